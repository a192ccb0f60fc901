/* The ray table as lens2pov trace writes it: the include read back the way POV-Ray reads it,
   rays traced back through the lens, determinism, weights, focusing and crops. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "support.h"

static const char *const LENSES[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm"};
static const char *const PUPILS[] = {"stop", "rear", "stop-image"};

/* A small trace through lens with extra options; returns the CSV rows. */
static csv_ray *trace_csv(const char *dir, const char *lens_name, const char *pupil, size_t *n,
                          const char *extra1, const char *extra2)
{
    char lens_path[512];
    snprintf(lens_path, sizeof lens_path, LENS_DIR "%s.dat", lens_name);
    const char *prefix = tmp_path(dir, "r"), *csv = tmp_path(dir, "r.csv");
    char *errtext;
    int st = run_lens2pov(NULL, &errtext, "trace", lens_path, "--pupil", pupil, "--width", "16",
                          "--height", "12", "--spp", "4", "--look-at", "0,0,3", "--rays", csv,
                          "-o", prefix, "--quiet", extra1, extra2, NULL);
    cr_assert_eq(st, 0, "%s %s: %s", lens_name, pupil, errtext);
    free(errtext);
    return read_rays_csv(csv, n);
}

Test(emit, include_reproduces_the_traced_rays)
{
    const char *dir = test_tmpdir();
    for (int i = 0; i < 4; i++)
        for (int p = 0; p < 3; p++) {
            size_t n, m;
            csv_ray *rows = trace_csv(dir, LENSES[i], PUPILS[p], &n, NULL, NULL);
            pov_ray *rays = read_include_as_povray(tmp_path(dir, "r.inc"), &m);
            cr_assert_eq(m, n, "one face per ray");
            for (size_t k = 0; k < n; k++) {
                /* Default placement: location 0, looking along +z, metres. */
                const vec3 o = v3_scale(rows[k].o, 1e-3);
                const double dist = v3_length(v3_sub(rays[k].o, o));
                const double angle = acos(fmin(1.0, v3_dot(rays[k].d, rows[k].d)));
                cr_assert_lt(dist, 1e-6, "%s %s ray %zu: origin off by %g", LENSES[i], PUPILS[p], k, dist);
                cr_assert_lt(angle, 1e-6, "%s %s ray %zu: direction off by %g rad", LENSES[i], PUPILS[p], k, angle);
            }
            free(rows);
            free(rays);
        }
}

static void camera_for(const char *lens_name, const char *pupil, camera *c)
{
    camera_options o;
    camera_options_default(&o);
    o.look_at = v3(0, 0, 3);
    pupil_kind_parse(pupil, &o.pupil);
    test_camera(c, lens_name, &o);
}

Test(emit, rays_traced_back_land_on_their_film_points)
{
    const char *dir = test_tmpdir();
    for (int i = 0; i < 4; i++)
        for (int p = 0; p < 3; p++) {
            size_t n;
            csv_ray *rows = trace_csv(dir, LENSES[i], PUPILS[p], &n, NULL, NULL);
            camera c;
            camera_for(LENSES[i], PUPILS[p], &c);
            const double scale = c.film.diagonal_mm;
            for (size_t k = 0; k < n; k++) {
                /* Back it out of the lens, then reverse it toward the film. */
                ray r = {v3_madd(rows[k].o, rows[k].d, scale), v3_scale(rows[k].d, -1.0)};
                cr_assert_eq(trace_toward_film(&c.lens, 0, c.lens.count - 1, &r, NULL), TRACE_PASSED,
                             "%s %s ray %zu does not get back through", LENSES[i], PUPILS[p], k);
                const double t = -r.o.z / r.d.z;
                const double ex = r.o.x + t * r.d.x - rows[k].film_x, ey = r.o.y + t * r.d.y - rows[k].film_y;
                cr_assert_lt(hypot(ex, ey), 1e-9 * scale, "%s %s ray %zu lands %g mm off",
                             LENSES[i], PUPILS[p], k, hypot(ex, ey));
            }
            camera_free(&c);
            free(rows);
        }
}

Test(emit, same_seed_same_rays_other_seed_other_rays)
{
    const char *dir = test_tmpdir();
    size_t n1, n2, n3;
    char *a, *b, *c;
    csv_ray *r1 = trace_csv(dir, "dgauss.50mm", "stop-image", &n1, "--seed", "7");
    a = read_text(tmp_path(dir, "r.inc"), NULL);
    csv_ray *r2 = trace_csv(dir, "dgauss.50mm", "stop-image", &n2, "--seed", "7");
    b = read_text(tmp_path(dir, "r.inc"), NULL);
    csv_ray *r3 = trace_csv(dir, "dgauss.50mm", "stop-image", &n3, "--seed", "8");
    c = read_text(tmp_path(dir, "r.inc"), NULL);
    cr_assert_eq(n1, n2);
    cr_assert(memcmp(r1, r2, n1 * sizeof *r1) == 0, "same seed: identical rays");
    cr_assert_str_eq(a, b, "same seed: identical include");
    cr_assert(n1 != n3 || memcmp(r1, r3, n1 * sizeof *r1) != 0, "another seed: other samples");
    free(r1); free(r2); free(r3); free(a); free(b); free(c);
}

Test(emit, samples_are_stratified_in_the_pixel)
{
    const char *dir = test_tmpdir();
    size_t n;
    csv_ray *r = trace_csv(dir, "dgauss.50mm", "stop-image", &n, "--crop", "8,6,9,7");
    /* 4 spp: one sample in each quarter of the pixel (those the lens passes). */
    int seen[4] = {0, 0, 0, 0};
    for (size_t k = 0; k < n; k++) {
        const double fx = r[k].raster_x - 8, fy = r[k].raster_y - 6;
        cr_assert(fx >= 0 && fx < 1 && fy >= 0 && fy < 1, "sample inside the cropped pixel");
        seen[(fx >= 0.5) + 2 * (fy >= 0.5)]++;
    }
    for (int q = 0; q < 4; q++)
        cr_assert_leq(seen[q], 1, "quarter %d has %d samples", q, seen[q]);
    free(r);
}

Test(emit, crop_traces_exactly_the_samples_of_its_region)
{
    const char *dir = test_tmpdir();
    size_t n_all, n_crop;
    csv_ray *all = trace_csv(dir, "wide.22mm", "stop-image", &n_all, NULL, NULL);
    csv_ray *crop = trace_csv(dir, "wide.22mm", "stop-image", &n_crop, "--crop", "3,2,7,5");
    size_t k = 0;
    for (size_t i = 0; i < n_all; i++) {
        const int px = (int)all[i].raster_x, py = (int)all[i].raster_y;
        if (px < 3 || px >= 7 || py < 2 || py >= 5)
            continue;
        cr_assert_lt(k, n_crop);
        cr_assert(memcmp(&all[i], &crop[k], sizeof all[i]) == 0, "row %zu of the crop differs", k);
        k++;
    }
    cr_assert_eq(k, n_crop, "the crop holds its region's rays and nothing else");
    free(all);
    free(crop);
}

/* The film centre's mean weight, counting blocked samples as 0, is 1 when normalized; under
   AddressSanitizer on a 256 x 256 grid, with that grid's tolerance (FULL_OR_ASAN). */
enum { N = FULL_OR_ASAN(1000, 256) };
static const double TOLERANCE = FULL_OR_ASAN(0.004, 0.012);

Test(emit, normalized_weights_average_one_at_the_centre)
{
    for (int p = 0; p < 3; p++) {
        camera c;
        camera_for("dgauss.50mm", PUPILS[p], &c);
        double sum = 0;
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                ray r;
                double w;
                if (camera_trace(&c, v3(0, 0, 0), (i + 0.5) / N, (j + 0.5) / N, &r, &w))
                    sum += w;
            }
        /* An independent estimate: a 1000 x 1000 grid over the pupil, against the exact cone
           integral the camera normalizes with. The grid's error at the edge of the passing
           region is first order, about 0.1% here (0.6% at 256 x 256). */
        cr_assert_float_eq(sum / ((double)N * N), 1.0, TOLERANCE, "%s: %g", PUPILS[p],
                           sum / ((double)N * N));
        camera_free(&c);
    }
}

/* An independent check of focus: a real near-axial ray from the film centre crosses the axis
   in front of the lens at the focus distance. */
Test(emit, focus_puts_the_film_centre_conjugate_at_the_focus_distance)
{
    const double distances_m[] = {0.8, 2.0, 10.0, 1000.0};
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            char path[512];
            snprintf(path, sizeof path, LENS_DIR "%s.dat", LENSES[i]);
            lens l;
            l2p_error err;
            cr_assert_eq(lens_read(path, &l, &err), 0);
            camera_options o;
            camera_options_default(&o);
            o.focus_distance_units = distances_m[j];
            camera c;
            int st = camera_setup(&c, &l, &o, &err);
            if (st) {   /* only the telephoto cannot focus at 0.8 m */
                cr_assert(i == 3 && j == 0, "%s at %g m: %s", LENSES[i], distances_m[j], err.text);
                cr_assert(strstr(err.text, "closest") != NULL, "%s", err.text);
                camera_free(&c);
                continue;
            }
            const double h = 1e-6 * c.lens.surface[c.lens.count - 1].aperture_diameter_mm;
            ray r = {v3(0, 0, 0), v3_normalize(v3(0, h / c.lens.film_distance_mm, 1))};
            cr_assert_eq(trace_toward_scene(&c.lens, 0, c.lens.count - 1, &r, NULL), TRACE_PASSED);
            const double z = r.o.z - r.o.y * r.d.z / r.d.y;
            /* Far focus is ill-conditioned: a film shift delta moves the conjugate by
               delta D^2 / f^2. Allow 1e-6 relative, or a picometre on the film side. */
            const double D = distances_m[j] * 1000.0, f = c.thick.rear_focal_length_mm;
            cr_assert_float_eq(z, D, 1e-6 * D + 1e-9 * D * D / (f * f),
                               "%s at %g m: conjugate at %.9g mm", LENSES[i], distances_m[j], z);
            camera_free(&c);
        }
}

Test(emit, blocked_rays_are_left_out)
{
    const char *dir = test_tmpdir();
    size_t n;
    csv_ray *r = trace_csv(dir, "wide.22mm", "rear", &n, NULL, NULL);
    cr_assert_lt(n, 16 * 12 * 4, "the rear-element pupil wastes rays on this lens");
    cr_assert_gt(n, 0);
    size_t m;
    pov_ray *rays = read_include_as_povray(tmp_path(dir, "r.inc"), &m);
    cr_assert_eq(m, n, "and none of them reaches POV-Ray");
    free(r);
    free(rays);
}

/* The number in "vertex_vectors { N," of an include. */
static long vertices_in(const char *path)
{
    char *text = read_text(path, NULL);
    cr_assert_not_null(text, "%s", path);
    const char *at = strstr(text, "vertex_vectors {");
    cr_assert_not_null(at, "%s", path);
    const long n = atol(at + strlen("vertex_vectors {"));
    free(text);
    return n;
}

/* Neighbouring rays share triangle edges (four vertices for two faces). The double-Gauss
   table must use far fewer than three vertices a face, and when a chunk boundary falls
   between the two faces of an edge, the second chunk gets the edge's vertices again: every
   chunk stands alone, and every face still carries its ray. */
Test(emit, shared_edges_survive_chunk_boundaries)
{
    const char *dir = test_tmpdir();
    size_t n;
    csv_ray *rows = trace_csv(dir, "dgauss.50mm", "stop-image", &n, NULL, NULL);
    const long whole = vertices_in(tmp_path(dir, "r.inc"));
    cr_assert_lt(whole, (long)(2.3 * (double)n), "%ld vertices for %zu faces", whole, n);
    const char *prefix = tmp_path(dir, "c");
    /* 0.02 MB: about 100 faces a chunk. */
    run_lens2pov_ok("trace", "trace", LENS_DIR "dgauss.50mm.dat", "--pupil",
                          "stop-image", "--width", "16", "--height", "12", "--spp", "4",
                          "--look-at", "0,0,3", "--memory-mb", "0.02", "-o", prefix, "--quiet",
                          NULL);
    size_t done = 0;
    long vertices = 0;
    int chunks = 0;
    for (;; chunks++) {
        char path[600];
        snprintf(path, sizeof path, "%s.c%03d.inc", prefix, chunks);
        FILE *f = fopen(path, "r");
        if (!f)
            break;
        fclose(f);
        vertices += vertices_in(path);
        size_t m;
        pov_ray *rays = read_include_as_povray(path, &m);
        cr_assert_leq(done + m, n, "more faces than rays");
        for (size_t k = 0; k < m; k++, done++) {
            const vec3 o = v3_scale(rows[done].o, 1e-3);
            cr_assert_lt(v3_length(v3_sub(rays[k].o, o)), 1e-6, "chunk %d face %zu: origin",
                         chunks, k);
            cr_assert_lt(acos(fmin(1.0, v3_dot(rays[k].d, rows[done].d))), 1e-6,
                         "chunk %d face %zu: direction", chunks, k);
        }
        free(rays);
    }
    cr_assert_gt(chunks, 4, "%d chunks", chunks);
    cr_assert_eq(done, n, "every ray in some chunk");
    /* Each split edge is written twice: two vertices more than the one-chunk table. */
    cr_assert_gt(vertices, whole, "no chunk boundary split a shared edge: the case is untested");
    cr_assert_leq(vertices - whole, 2L * (chunks - 1));
    cr_assert_eq((vertices - whole) % 2, 0);
    free(rows);
}

/* --f-number is compared at the precision the refusal prints the widest (4 digits): typing back
   the printed f/2.03 for the double-Gauss's 2.0301... opens the stop fully; a hundredth faster
   is refused, naming the widest as printed. The widest is taken from the camera at full
   opening, independently of the refusal's arithmetic. */
Test(emit, the_widest_f_number_as_printed_opens_the_stop_fully)
{
    camera full;
    camera_for("dgauss.50mm", "stop-image", &full);
    char printed[32];
    snprintf(printed, sizeof printed, "%.4g", full.f_number);
    const double stop_mm = full.lens.surface[full.lens.stop].aperture_diameter_mm;
    cr_assert(strtod(printed, NULL) < full.f_number, "the printed widest %s rounds down %.9g",
              printed, full.f_number);
    camera_free(&full);
    const double asked[] = {strtod(printed, NULL), strtod(printed, NULL) - 0.01};
    for (int k = 0; k < 2; k++) {
        lens l;
        l2p_error err;
        cr_assert_eq(lens_read(LENS_DIR "dgauss.50mm.dat", &l, &err), 0);
        camera_options o;
        camera_options_default(&o);
        o.look_at = v3(0, 0, 3);
        o.f_number = asked[k];
        camera c;
        const int st = camera_setup(&c, &l, &o, &err);
        if (k == 0) {
            cr_assert_eq(st, 0, "f/%g: %s", asked[k], err.text);
            cr_assert_eq(c.lens.stop_diameter_mm, stop_mm, "f/%g opens the stop fully", asked[k]);
        } else {
            cr_assert_eq(st, L2P_BAD_INPUT, "f/%g", asked[k]);
            cr_assert(strstr(err.text, printed) != NULL, "%s", err.text);
        }
        camera_free(&c);
    }
}

/* An aperture a hair wider than the stop is refused with both numbers as given, so that the
   message does not read "17.1 is not in (0, 17.1]". */
Test(emit, an_aperture_a_hair_too_wide_is_refused_in_full_digits)
{
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "info", LENS_DIR "dgauss.50mm.dat", "--aperture-diameter",
                              "17.1000001", NULL), 2);
    cr_assert(strstr(errtext, "17.1000001 mm is not in (0, 17.1]"), "%s", errtext);
    free(errtext);
}

/* A film distance shorter than the rear focal distance images a virtual object behind the film:
   trace warns that nothing is sharp, and says nothing for a film beyond the focal plane. The
   focal plane from info (back focal distance), not from the warning's arithmetic. */
Test(emit, a_film_distance_that_focuses_behind_the_film_is_warned_about)
{
    char *out = NULL, *errtext = NULL;
    cr_assert_eq(run_lens2pov(&out, &errtext, "info", LENS_DIR "dgauss.50mm.dat", "--json", NULL), 0);
    double bfd = NAN;
    const char *at = strstr(out, "\"bfd_mm\":");
    cr_assert(at && sscanf(at, "\"bfd_mm\": %lf", &bfd) == 1, "%s", out);
    free(out);
    free(errtext);
    const char *dir = test_tmpdir();
    const double distances[] = {0.5 * bfd, 1.05 * bfd};
    for (int k = 0; k < 2; k++) {
        char d[32];
        snprintf(d, sizeof d, "%.6f", distances[k]);
        const int st = run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--width",
                                    "4", "--height", "3", "--spp", "1", "--film-distance", d,
                                    "-o", tmp_path(dir, "f"), "--quiet", NULL);
        cr_assert_eq(st, 0, "%s", errtext);
        const bool warned = strstr(errtext, "warning: --film-distance") != NULL;
        cr_assert_eq(warned, k == 0, "film distance %s mm (bfd %g): %s", d, bfd, errtext);
        free(errtext);
    }
}
