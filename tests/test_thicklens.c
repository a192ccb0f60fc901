/* A single thick biconvex lens against its closed form (the thick-lens lensmaker's equation and
   the principal-plane offsets), and the emitted rays against its analytic conjugates. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "optics/lens.h"
#include "support.h"
#include "optics/thicklens.h"

/* R1 = 50, R2 = -50, t = 6, n = 1.5, then the stop 10 mm behind the lens. */
static const double R1 = 50, R2 = -50, T = 6, N = 1.5, GAP = 10;
static const char *const LENS_TEXT =
    "# one biconvex lens and a stop behind it\n"
    "50 6 1.5 30\n-50 10 1 30\n0 0 0 10\n";

/* Hecht, Optics, 6.2: 1/f = (n-1)[1/R1 - 1/R2 + (n-1)t/(n R1 R2)]; H1 lies
   -f(n-1)t/(n R2) behind the front vertex, H2 -f(n-1)t/(n R1) behind the rear vertex
   (positive toward the film). */
static double analytic_f(void) { return 1.0 / ((N - 1) * (1 / R1 - 1 / R2 + (N - 1) * T / (N * R1 * R2))); }

typedef struct analytic { double p1, p2, f; } analytic;

static analytic analytic_at(double film_distance)
{
    const double f = analytic_f();
    const double v2 = film_distance + GAP, v1 = v2 + T;
    analytic a = {v1 - (-f * (N - 1) * T / (N * R2)), v2 - (-f * (N - 1) * T / (N * R1)), f};
    return a;
}

/* Gaussian conjugate of a film point (air on both sides): 1/s + 1/s' = 1/f. */
static vec3 analytic_conjugate(analytic a, vec3 film)
{
    const double s_image = a.p2 - film.z, s_object = 1.0 / (1.0 / a.f - 1.0 / s_image);
    const double m = -s_object / s_image;
    return v3(film.x * m, film.y * m, a.p1 + s_object);
}

Test(thicklens, cardinal_points_match_the_closed_form)
{
    lens l;
    l2p_error err;
    cr_assert_eq(lens_parse(LENS_TEXT, strlen(LENS_TEXT), "bi.dat", &l, &err), 0, "%s", err.text);
    lens_set_film_distance(&l, 41.0);
    thick_lens t;
    cr_assert_eq(thick_lens_of(&l, 0, l.count - 1, &t, &err), 0, "%s", err.text);
    const analytic a = analytic_at(41.0);
    /* Probing at 1e-5 of the aperture leaves aberrations ~1e-10 relative. */
    cr_assert_float_eq(t.rear_focal_length_mm, a.f, 1e-8 * a.f);
    cr_assert_float_eq(t.front_focal_length_mm, a.f, 1e-8 * a.f);
    cr_assert_float_eq(t.p1_z_mm, a.p1, 1e-8 * a.f);
    cr_assert_float_eq(t.p2_z_mm, a.p2, 1e-8 * a.f);
    cr_assert_float_eq(t.f2_z_mm, a.p2 - a.f, 1e-8 * a.f);
    lens_free(&l);
}

Test(thicklens, conjugates_round_trip)
{
    thick_lens t = {10, 5, 60, -40, 50, 45};
    vec3 image, back;
    cr_assert(thick_image_from_real(&t, v3(3, -2, 1000), &image));
    cr_assert(thick_real_from_image(&t, image, &back));
    cr_assert_float_eq(back.x, 3, 1e-12);
    cr_assert_float_eq(back.y, -2, 1e-12);
    cr_assert_float_eq(back.z, 1000, 1e-9);
    cr_assert(!thick_real_from_image(&t, v3(1, 1, t.f2_z_mm), &back), "F2 images to infinity");
}

Test(thicklens, afocal_subsystem_is_refused)
{
    /* Two lenses of f = 100 mm spaced 200 mm apart (thin-lens approximation made thick: the
       spacing is fitted by the same code) form a telescope; a plane-parallel plate is afocal
       exactly. */
    const char *plate = "1e30 5 1.5 20\n0 1 0 10\n-1e30 0 1 20\n";
    lens l;
    l2p_error err;
    cr_assert_eq(lens_parse(plate, strlen(plate), "plate.dat", &l, &err), 0, "%s", err.text);
    thick_lens t;
    cr_assert_eq(thick_lens_of(&l, 0, l.count - 1, &t, &err), L2P_BAD_INPUT);
    cr_assert(strstr(err.text, "afocal") != NULL, "%s", err.text);
    lens_free(&l);
}

/* Distance from point p to the line o + t d (d unit). */
static double line_distance(vec3 o, vec3 d, vec3 p)
{
    const vec3 w = v3_sub(p, o);
    return v3_length(v3_sub(w, v3_scale(d, v3_dot(w, d))));
}

static const char *write_lens(const char *dir)
{
    static char path[512];
    snprintf(path, sizeof path, "%s", tmp_path(dir, "bi.dat"));
    write_text(path, LENS_TEXT);
    return path;
}

Test(thicklens, emitted_thick_rays_pass_through_the_analytic_conjugate)
{
    const char *dir = test_tmpdir();
    const char *lens_path = write_lens(dir), *prefix = tmp_path(dir, "t"), *csv = tmp_path(dir, "t.csv");
    run_lens2pov_ok("trace", "trace", lens_path, "--trace", "thick", "--film-distance", "41",
                          "--width", "12", "--height", "8", "--spp", "4", "--film-diagonal", "8",
                          "--rays", csv, "-o", prefix, "--quiet", NULL);
    size_t n_csv, n_pov;
    csv_ray *rows = read_rays_csv(csv, &n_csv);
    pov_ray *rays = read_include_as_povray(tmp_path(dir, "t.inc"), &n_pov);
    cr_assert_eq(n_csv, 12 * 8 * 4, "thick tracing blocks nothing");
    cr_assert_eq(n_pov, n_csv);
    const analytic a = analytic_at(41.0);
    double worst = 0;
    for (size_t i = 0; i < n_pov; i++) {
        /* Default placement: world = camera / 1000 (metres), looking along +z. */
        const vec3 target = v3_scale(analytic_conjugate(a, v3(rows[i].film_x, rows[i].film_y, 0)), 1e-3);
        const double range = v3_length(v3_sub(target, rays[i].o));
        const double miss = line_distance(rays[i].o, rays[i].d, target) / range;
        worst = fmax(worst, miss);
    }
    /* float32 vertices give directions good to ~1e-7 rad: 1e-6 of the range is ten times that. */
    cr_assert_lt(worst, 1e-6, "worst miss %g of the range", worst);
    free(rows);
    free(rays);
}

/* Mean axial distance between where full-simulation rays of a near-axial film point come
   closest to the axis and the analytic conjugate: spherical aberration, ~ aperture^2. */
static double longitudinal_error(const char *dir, const char *lens_path, const char *aperture)
{
    const char *prefix = tmp_path(dir, "f"), *csv = tmp_path(dir, "f.csv");
    run_lens2pov_ok("trace", "trace", lens_path, "--film-distance", "41",
                          "--width", "1", "--height", "1", "--spp", "256", "--film-diagonal", "1e-4",
                          "--aperture-diameter", aperture, "--rays", csv, "-o", prefix, "--quiet", NULL);
    size_t n;
    csv_ray *rows = read_rays_csv(csv, &n);
    /* The pupil disk covers the passing bundle with a margin: nearly all get through. */
    cr_assert(n > 230 && n <= 256, "%zu of 256 rays pass", n);
    const analytic a = analytic_at(41.0);
    double sum = 0;
    for (size_t i = 0; i < n; i++) {
        const vec3 target = analytic_conjugate(a, v3(rows[i].film_x, rows[i].film_y, 0));
        const vec3 o = rows[i].o, d = rows[i].d;
        const double dxy = d.x * d.x + d.y * d.y;
        const double t = -((o.x - target.x) * d.x + (o.y - target.y) * d.y) / dxy;
        sum += fabs(o.z + t * d.z - target.z);
    }
    free(rows);
    return sum / (double)n;
}

Test(thicklens, full_rays_approach_the_conjugate_like_the_aperture_squared)
{
    const char *dir = test_tmpdir();
    const char *lens_path = write_lens(dir);
    const char *apertures[] = {"2", "1", "0.5", "0.25"};
    double e[4];
    for (int i = 0; i < 4; i++)
        e[i] = longitudinal_error(dir, lens_path, apertures[i]);
    for (int i = 0; i < 3; i++) {
        const double slope = log(e[i] / e[i + 1]) / log(2.0);
        cr_assert(slope > 1.9 && slope < 2.1, "error %g -> %g: slope %g, expected 2", e[i], e[i + 1], slope);
        cr_log_info("aperture halved: longitudinal error %g -> %g mm, slope %.4f", e[i], e[i + 1], slope);
    }
}
