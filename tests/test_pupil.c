/* The exit pupils: the map from samples to pupil points (its exact density in the weight,
   continuous over the film), and the physics they must get right: every ray the lens passes
   lies in the sampled region, and the film irradiance of a uniform background matches an
   independent integral over every direction the lens passes. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "optics/irradiance.h"
#include "support.h"
#include "optics/trace_batch.h"

static const char *const LENSES[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm",
                                     "telephoto.250mm"};

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double unit(uint64_t *state)
{
    *state = mix64(*state + 0x9e3779b97f4a7c15ULL);
    return (double)(*state >> 11) * 0x1.0p-53;
}

/* ---- The map, on a pupil with hand-made shapes. */

static pupil hand_made(double z_mm)
{
    pupil pu;
    memset(&pu, 0, sizeof pu);
    pu.kind = PUPIL_STOP_IMAGE;
    pu.z_mm = z_mm;
    pu.radius_mm = 5.0;
    pu.node_spacing_mm = 0.5;
    pu.reach_mm = INFINITY;
    for (int j = 0; j <= PUPIL_NODES; j++) {   /* the axis's disk turning into an oval */
        pu.node[j].centre_mm = 0.1 * j - 0.003 * j * j;
        for (int i = 0; i <= PUPIL_KNOTS; i++) {
            const double c = 1.0 - 2.0 * i / PUPIL_KNOTS;
            pu.node[j].radius_mm[i] = 5.0 - 0.06 * j * c * c + 0.01 * j * c;
        }
    }
    return pu;
}

static void sample_point(const pupil *pu, vec3 p, double u, double v, double *x, double *y)
{
    double area;
    cr_assert(pupil_point(pu, p, u, v, x, y, &area));
}

/* The map's Jacobian, by central differences, is the inverse of the density the weight
   divides by, pi R(phi)^2, with R read off the interpolated shape at the sample's angle from
   the film point's direction; the weight is that times cos^4 / Z^2. Samples near the
   concentric map's diagonals, where it is only piecewise smooth, are left out. */
Test(pupil, the_weight_divides_by_the_exact_density)
{
    const double z_mm[] = {40.0, -15.0};
    uint64_t state = 1;
    for (int zi = 0; zi < 2; zi++) {
        const pupil pu = hand_made(z_mm[zi]);
        for (int n = 0; n < 2000; n++) {
            const double r = 24.0 * unit(&state), t = 2.0 * M_PI * unit(&state);
            const vec3 p = v3(r * cos(t), r * sin(t), 0.0);
            const double u = 0.02 + 0.96 * unit(&state), v = 0.02 + 0.96 * unit(&state);
            if (fabs(fabs(2 * u - 1) - fabs(2 * v - 1)) < 1e-3)
                continue;
            const double h = 1e-6;
            double x1, y1, x2, y2, x3, y3, x4, y4, x, y, inverse_density;
            sample_point(&pu, p, u + h, v, &x1, &y1);
            sample_point(&pu, p, u - h, v, &x2, &y2);
            sample_point(&pu, p, u, v + h, &x3, &y3);
            sample_point(&pu, p, u, v - h, &x4, &y4);
            cr_assert(pupil_point(&pu, p, u, v, &x, &y, &inverse_density));
            const double det = ((x1 - x2) * (y3 - y4) - (y1 - y2) * (x3 - x4)) / (4 * h * h);
            pupil_shape e;
            cr_assert(pupil_shape_at(&pu, r, &e));
            const double cx = e.centre_mm * cos(t), cy = e.centre_mm * sin(t);
            const double phi = atan2(y - cy, x - cx) - t;
            const double radius = pupil_shape_radius_mm(&e, cos(phi));
            cr_assert_float_eq(inverse_density, M_PI * radius * radius, 1e-9 * inverse_density);
            cr_assert_float_eq(det, inverse_density, 1e-5 * inverse_density,
                               "r %g: Jacobian %.9g, pi R^2 %.9g", r, det, inverse_density);
            const vec3 d = v3_normalize(v3_sub(v3(x, y, pu.z_mm), p));
            vec3 got_d;
            const double w = pupil_film_ray(&pu, p, u, v, &got_d);
            const double want = inverse_density * pow(fabs(d.z), 4) / (pu.z_mm * pu.z_mm);
            cr_assert_float_eq(w, want, 1e-12 * want);
            cr_assert(fabs(v3_dot(got_d, d)) > 1 - 1e-15, "the ray aims at the pupil point");
        }
    }
}

/* The concentric map's inverse (field sampling places its own disk points): on the axis the
   hand-made region is the disk of 5 mm about it, so the sample pupil_square_of_disk gives for
   disk point (x, y) must land on (5 x, 5 y). Random points, and the centre, the axes and the
   diagonals, where the map changes branch. */
Test(pupil, the_inverse_concentric_map_returns_the_disk_point)
{
    const pupil pu = hand_made(40.0);
    const double h = sqrt(0.5);
    const double fixed[][2] = {{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}, {h, h}, {-h, h}, {h, -h},
                               {-h, -h}, {0.3, 0.3}, {1e-300, 0}, {0, -1e-300}};
    uint64_t state = 7;
    for (int n = 0; n < 10000; n++) {
        double x, y;
        if (n < 12) {
            x = fixed[n][0], y = fixed[n][1];
        } else {
            const double r = sqrt(unit(&state)), t = 2.0 * M_PI * unit(&state);
            x = r * cos(t), y = r * sin(t);
        }
        double u, v, px, py;
        pupil_square_of_disk(x, y, &u, &v);
        cr_assert(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0, "(%g, %g): (%g, %g)", x, y, u, v);
        cr_assert_float_eq(pupil_disk_radius(u, v), hypot(x, y), 1e-15);
        sample_point(&pu, v3(0.0, 0.0, 0.0), u, v, &px, &py);
        cr_assert(fabs(px - 5.0 * x) < 1e-13 && fabs(py - 5.0 * y) < 1e-13,
                  "(%.17g, %.17g) lands on (%.17g, %.17g)", x, y, px / 5.0, py / 5.0);
    }
}

/* A fixed sample moves continuously as the film point crosses the nodes and the axis: the
   next pupil field (one sample over the whole film) must have no seams. */
Test(pupil, a_sample_moves_continuously_with_the_film_point)
{
    const pupil pu = hand_made(40.0);
    const double us[] = {0.5, 0.9, 0.1, 0.73}, vs[] = {0.5, 0.2, 0.95, 0.31};
    const double step = 1e-3;
    for (int k = 0; k < 4; k++) {
        double px = 0, py = 0;
        for (int i = -8000; i <= 8000; i++) {
            const vec3 p = v3(0.6 * i * step, 0.8 * i * step, 0.0);
            double x, y;
            sample_point(&pu, p, us[k], vs[k], &x, &y);
            /* The shapes change by at most 0.5 mm per mm of film radius, the turn moves a
               point of a 12 mm region by at most 12 mm per radian: 50 mm per mm covers both. */
            if (i > -8000)
                cr_assert_lt(hypot(x - px, y - py), 50.0 * step, "sample %d jumps at film %g mm",
                             k, i * step);
            px = x;
            py = y;
        }
    }
}

/* The region holds every sample and nothing outside its rim. */
Test(pupil, the_region_holds_its_samples_and_nothing_beyond_its_rim)
{
    const pupil pu = hand_made(40.0);
    uint64_t state = 2;
    for (int n = 0; n < 5000; n++) {
        const double r = 24.0 * unit(&state), phi = 2.0 * M_PI * unit(&state);
        const vec3 p = v3(r * cos(phi), r * sin(phi), 0.0);
        double x, y, rx, ry;
        sample_point(&pu, p, 0.001 + 0.998 * unit(&state), 0.001 + 0.998 * unit(&state), &x, &y);
        cr_assert(pupil_contains(&pu, p, x, y), "film (%g, %g): a sample outside", p.x, p.y);
        /* The square's edge maps onto the disk's rim. */
        const double t = unit(&state), side = unit(&state);
        const double ru = side < 0.25 ? 0.0 : side < 0.5 ? 1.0 : t;
        const double rv = side < 0.5 ? t : side < 0.75 ? 0.0 : 1.0;
        double cx, cy;
        sample_point(&pu, p, ru, rv, &rx, &ry);
        sample_point(&pu, p, 0.5, 0.5, &cx, &cy);
        cr_assert_not(pupil_contains(&pu, p, cx + 1.001 * (rx - cx), cy + 1.001 * (ry - cy)));
        cr_assert(pupil_contains(&pu, p, cx + 0.999 * (rx - cx), cy + 0.999 * (ry - cy)));
    }
}

Test(pupil, beyond_the_reach_nothing_is_sampled)
{
    pupil pu = hand_made(40.0);
    pu.reach_mm = 3.0;
    vec3 d;
    cr_assert(pupil_reaches(&pu, v3(1.8, 2.4, 0)));
    cr_assert_gt(pupil_film_ray(&pu, v3(1.8, 2.4, 0), 0.3, 0.3, &d), 0.0);
    cr_assert_not(pupil_reaches(&pu, v3(1.8, 2.41, 0)));
    cr_assert_eq(pupil_film_ray(&pu, v3(1.8, 2.41, 0), 0.3, 0.3, &d), 0.0);
    cr_assert_eq(pupil_film_ray(&pu, v3(NAN, 0, 0), 0.3, 0.3, &d), 0.0);
}

/* ---- The physics, on the four lenses. */

/* The four lenses on a 35 mm film of 4:3 (64x48), focused at focus_m, stopped to f_number
   (NAN: the full opening), physical weights. */
static void setup_blades(camera *c, const char *name, double f_number, double focus_m,
                         pupil_kind kind, int blades)
{
    camera_options o;
    camera_options_default(&o);
    o.width = 64;
    o.height = 48;
    o.focus_distance_units = focus_m;
    o.f_number = f_number;
    o.pupil = kind;
    o.weighting = WEIGHTING_PHYSICAL;
    o.aperture_blades = blades;
    o.blade_rotation_deg = 11.0;
    test_camera(c, name, &o);
}

static void setup(camera *c, const char *name, double f_number, double focus_m, pupil_kind kind)
{
    setup_blades(c, name, f_number, focus_m, kind, 0);
}

/* Film points: the centre, mid-field, mid-edge and corner of the 64x48 film (raster to film
   as the contract gives it: (0.5 - rx / W) fw, (ry / H - 0.5) fh). */
static const double RASTER[][2] = {{32, 24}, {48, 36}, {63.5, 24}, {63.5, 47.5}};
enum { POINTS = 4 };

static vec3 film_point(const camera *c, int i)
{
    return v3((0.5 - RASTER[i][0] / 64.0) * c->film.width_mm,
              (RASTER[i][1] / 48.0 - 0.5) * c->film.height_mm, 0.0);
}

/* Which of the n directions (a[k], b[k], sqrt(1 - a^2 - b^2)) from p get through the lens. */
static void trace_directions(const lens *l, vec3 p, const double *a, const double *b, int n,
                             bool *passed)
{
    for (int done = 0; done < n; done += TRACE_BATCH_MAX) {
        const int m = n - done < TRACE_BATCH_MAX ? n - done : TRACE_BATCH_MAX;
        trace_batch s;
        for (int k = 0; k < m; k++) {
            const double q = a[done + k] * a[done + k] + b[done + k] * b[done + k];
            s.ox[k] = p.x; s.oy[k] = p.y; s.oz[k] = p.z;
            s.dx[k] = a[done + k]; s.dy[k] = b[done + k]; s.dz[k] = sqrt(fmax(0.0, 1.0 - q));
            s.status[k] = q < 1.0 ? TRACE_PASSED : TRACE_MISSED;
        }
        trace_batch_toward_scene(l, &s, m);
        for (int k = 0; k < m; k++)
            passed[done + k] = s.status[k] == TRACE_PASSED;
    }
}

/* Passing cells of an n x n grid of direction cosines over [x0, x0 + n h) x [y0, y0 + n h);
   their bounding box in *box (x0, x1, y0, y1) when box is given. */
static long count_cells(const lens *l, vec3 p, double x0, double y0, double h, int n, double *box)
{
    long count = 0;
    double a[TRACE_BATCH_MAX * 8], b[TRACE_BATCH_MAX * 8];
    bool passed[TRACE_BATCH_MAX * 8];
    const int chunk = TRACE_BATCH_MAX * 8;
    for (long start = 0; start < (long)n * n; start += chunk) {
        const int m = (long)n * n - start < chunk ? (int)((long)n * n - start) : chunk;
        for (int k = 0; k < m; k++) {
            a[k] = x0 + ((start + k) % n + 0.5) * h;
            b[k] = y0 + ((start + k) / n + 0.5) * h;
        }
        trace_directions(l, p, a, b, m, passed);
        for (int k = 0; k < m; k++) {
            if (!passed[k])
                continue;
            count++;
            if (box) {
                box[0] = fmin(box[0], a[k]);
                box[1] = fmax(box[1], a[k]);
                box[2] = fmin(box[2], b[k]);
                box[3] = fmax(box[3], b[k]);
            }
        }
    }
    return count;
}

/* The film irradiance from a uniform background of radiance 1, independently of the pupils:
   E = integral of cos(theta) over the passing directions = the area of the passing set in
   the plane of direction cosines (a, b) (d(omega) cos(theta) = da db). A coarse grid finds the
   set, a fine one (n x n over its bounding box, grown by two coarse cells) measures it, and
   a grid of half the density gives the error estimate *error. */
static double irradiance(const lens *l, vec3 p, int n, double *error)
{
    const int steps = FULL_OR_ASAN(1024, 512);
    const double coarse = 2.0 / steps;
    double box[4] = {1, -1, 1, -1};
    if (count_cells(l, p, -1.0, -1.0, coarse, steps, box) == 0) {
        *error = 0.0;
        return 0.0;
    }
    const double x0 = box[0] - 2.5 * coarse, y0 = box[2] - 2.5 * coarse;
    const double side = fmax(box[1] - box[0], box[3] - box[2]) + 5.0 * coarse;
    const double fine = (double)count_cells(l, p, x0, y0, side / n, n, NULL) * (side / n) * (side / n);
    const double half = (double)count_cells(l, p, x0, y0, side / (n / 2), n / 2, NULL) *
                        (side / (n / 2)) * (side / (n / 2));
    *error = fabs(fine - half);
    return fine;
}

/* lens2pov's estimate with N jittered stratified samples, and its standard error as if the
   samples were independent (stratification only lowers it). */
static double estimate(const camera *c, vec3 p, int side, double *std_error)
{
    uint64_t state = 99;
    double sum = 0.0, sum2 = 0.0;
    for (int j = 0; j < side; j++)
        for (int i = 0; i < side; i++) {
            ray r;
            double w;
            const double u = (i + unit(&state)) / side, v = (j + unit(&state)) / side;
            if (!camera_trace(c, p, u, v, &r, &w))
                continue;
            sum += w;
            sum2 += w * w;
        }
    const double n = (double)side * side, mean = sum / n;
    *std_error = sqrt(fmax(0.0, sum2 / n - mean * mean) / n);
    return mean;
}

/* The four lenses at full aperture, f/8, f/16 and f/64 (the telephoto opens to f/5.6, the
   fisheye to f/4; f/64 stands for the small stops), at the centre, mid-field, mid-edge and
   corner; beyond the fisheye's image circle both are 0. The tolerance: four standard errors
   of the 128 x 128 samples (0.1-0.5%), plus twice the grid's own error (its change from half
   the density), plus 2e-4 of the value for the rest of the grid's discretization. (Under
   AddressSanitizer, 64 x 64 samples and a grid of half the density: FULL_OR_ASAN.) */
enum { SIDE = FULL_OR_ASAN(128, 64), GRID = FULL_OR_ASAN(512, 256) };

Test(pupil, irradiance_matches_an_independent_integral_over_the_lens)
{
    const double f_numbers[] = {NAN, 8.0, 16.0, 64.0};
    for (int li = 0; li < 4; li++)
        for (int fi = 0; fi < 4; fi++) {
            camera c;
            setup(&c, LENSES[li], f_numbers[fi], 10.0, PUPIL_STOP_IMAGE);
            for (int i = 0; i < POINTS; i++) {
                const vec3 p = film_point(&c, i);
                double se, grid_error;
                const double got = estimate(&c, p, SIDE, &se);
                const double want = irradiance(&c.lens, p, GRID, &grid_error);
                const double tolerance = 4.0 * se + 2.0 * grid_error + 2e-4 * want;
                cr_assert(fabs(got - want) <= tolerance,
                          "%s f/%g, film (%.2f, %.2f): lens2pov %.6g, the lens passes %.6g "
                          "(%+.3f%%, tolerance %.3f%%)", LENSES[li], f_numbers[fi], p.x, p.y,
                          got, want, 100.0 * (got / want - 1.0), 100.0 * tolerance / want);
            }
            camera_free(&c);
        }
}

/* With --trace thick the light comes through the exit pupil, the stop's image, and nothing else
   stops it: the mean weight of the thick camera's samples is the disk's projected solid angle
   (irradiance_through_disk, which plot --what vignetting --trace thick draws), whichever pupil
   samples it. The rear pupil's larger disk passed everything it sampled, as if at full
   opening: at f/8 the double-Gauss's centre came out 17 times too bright. */
Test(pupil, thick_irradiance_is_the_exit_pupils_disk)
{
    const double f_numbers[] = {NAN, 8.0};
    for (int li = 0; li < 2; li++)
        for (int fi = 0; fi < 4; fi++) {
            camera_options o;
            camera_options_default(&o);
            o.width = 64, o.height = 48, o.focus_distance_units = 10.0, o.f_number = f_numbers[fi % 2];
            o.weighting = WEIGHTING_PHYSICAL, o.trace = TRACE_KIND_THICK;
            o.pupil = fi < 2 ? PUPIL_STOP_IMAGE : PUPIL_REAR;
            camera c;
            test_camera(&c, LENSES[li], &o);
            double z, radius;
            l2p_error err;
            cr_assert_eq(pupil_stop_image(&c.lens, true, &z, &radius, &err), L2P_OK);
            for (int i = 0; i < POINTS; i++) {
                const vec3 p = film_point(&c, i);
                double se;
                const double got = estimate(&c, p, SIDE, &se);
                const double want = irradiance_through_disk(v3_length(p), z, radius);
                cr_assert(fabs(got - want) <= 4.0 * se + 1e-4 * want, "%s f/%g, %s pupil, film "
                          "(%.2f, %.2f): %.6g, the disk %.6g", LENSES[li], f_numbers[fi % 2],
                          pupil_kind_name(o.pupil), p.x, p.y, got, want);
            }
            camera_free(&c);
        }
}

/* The same through blades (5 and 6, turned by 11 degrees), on the double-Gauss and the wide
   angle at full opening and f/8: the fitted pupil covers the polygon's rays, the weights stay
   unbiased. The independent integral traces the same blades (the kernel's stop test). */
Test(pupil, irradiance_through_blades_matches_an_independent_integral)
{
    static const char *const lenses[] = {"dgauss.50mm", "wide.22mm"};
    const double f_numbers[] = {NAN, 8.0};
    for (int li = 0; li < 2; li++)
        for (int fi = 0; fi < 2; fi++)
            for (int blades = 5; blades <= 6; blades++) {
                camera c;
                setup_blades(&c, lenses[li], f_numbers[fi], 10.0, PUPIL_STOP_IMAGE, blades);
                for (int i = 0; i < POINTS; i++) {
                    const vec3 p = film_point(&c, i);
                    double se, grid_error;
                    const double got = estimate(&c, p, SIDE, &se);
                    const double want = irradiance(&c.lens, p, GRID, &grid_error);
                    const double tolerance = 4.0 * se + 2.0 * grid_error + 2e-4 * want;
                    cr_assert(fabs(got - want) <= tolerance,
                              "%s f/%g, %d blades, film (%.2f, %.2f): lens2pov %.6g, the lens "
                              "passes %.6g (%+.3f%%, tolerance %.3f%%)", lenses[li],
                              f_numbers[fi], blades, p.x, p.y, got, want,
                              100.0 * (got / want - 1.0), 100.0 * tolerance / want);
                }
                camera_free(&c);
            }
}

/* A dense grid over the rear element, and beyond its rim: every ray from the film point through
   a grid point that the lens passes crosses the pupil plane inside the region sampled for that
   film point (none for a film point beyond the lens's reach). Film points: centre, mid-field,
   edge, corner (beyond the fisheye's image circle), and four points on the diagonal that fall
   between the pupil's nodes; stops: full, a quarter of the opening, 1/16; focus 10 m and 2 m
   (the telephoto's closest is farther: 4 m). */
Test(pupil, every_passing_ray_lies_in_the_sampled_region)
{
    const double openings[] = {1.0, 0.25, 1.0 / 16};
    enum { N = FULL_OR_ASAN(300, 120) };
    for (int li = 0; li < 4; li++)
        for (int oi = 0; oi < 3; oi++)
            for (int fi = 0; fi < 2; fi++)
                for (int kind = PUPIL_REAR; kind <= PUPIL_STOP_IMAGE; kind++) {
                    char path[512];
                    snprintf(path, sizeof path, LENS_DIR "%s.dat", LENSES[li]);
                    lens l;
                    l2p_error err;
                    cr_assert_eq(lens_read(path, &l, &err), 0);
                    camera_options o;
                    camera_options_default(&o);
                    o.width = 64;
                    o.height = 48;
                    o.focus_distance_units = fi ? (li == 3 ? 4.0 : 2.0) : 10.0;
                    o.aperture_diameter_mm = openings[oi] * l.surface[l.stop].aperture_diameter_mm;
                    o.pupil = (pupil_kind)kind;
                    o.weighting = WEIGHTING_PHYSICAL;
                    camera c;
                    cr_assert_eq(camera_setup(&c, &l, &o, &err), 0, "%s", err.text);
                    const lens_surface *rear = &c.lens.surface[c.lens.count - 1];
                    const double reach = 0.75 * rear->aperture_diameter_mm, z = rear->vertex_z_mm;
                    for (int i = 0; i < POINTS + 4; i++) {   /* and between the nodes */
                        const double along[4] = {0.13, 0.37, 0.61, 0.87};
                        const vec3 p = i < POINTS ? film_point(&c, i)
                                                  : v3_scale(film_point(&c, 3), along[i - POINTS]);
                        long passing = 0, outside = 0;
                        for (int j = 0; j < N; j++)
                            for (int k = 0; k < N; k++) {
                                const vec3 q = v3(-reach + (k + 0.5) * 2 * reach / N,
                                                  -reach + (j + 0.5) * 2 * reach / N, z);
                                ray r = {p, v3_normalize(v3_sub(q, p))};
                                if (trace_toward_scene(&c.lens, 0, c.lens.count - 1, &r, NULL) != TRACE_PASSED)
                                    continue;
                                passing++;
                                const double t = c.pupil.z_mm / (q.z - p.z);
                                outside += !pupil_contains(&c.pupil, p, p.x + t * (q.x - p.x),
                                                           p.y + t * (q.y - p.y));
                            }
                        cr_assert_eq(outside, 0, "%s, %s pupil, stop x%g, focus %g m, film (%.2f, "
                                     "%.2f): %ld of %ld passing rays outside the sampled region",
                                     LENSES[li], pupil_kind_name(c.pupil.kind), openings[oi],
                                     o.focus_distance_units, p.x, p.y, outside, passing);
                    }
                    camera_free(&c);
                }
}

/* Beyond the fisheye's image circle no sample is produced: trace counts fewer samples than
   pixels times spp, and the corners' pixels get no ray. */
Test(pupil, film_points_no_ray_can_reach_produce_no_samples)
{
    const char *dir = test_tmpdir();
    char *errtext;
    int st = run_lens2pov(NULL, &errtext, "trace", LENS_DIR "fisheye.10mm.dat", "--width", "16",
                          "--height", "12", "--spp", "4", "--look-at", "0,0,3", "-o",
                          tmp_path(dir, "f"), "--rays", tmp_path(dir, "f.csv"), NULL);
    cr_assert_eq(st, 0, "%s", errtext);
    long passed = 0, samples = 0;
    const char *line = strstr(errtext, " rays pass the lens");
    cr_assert_not_null(line, "%s", errtext);
    while (line > errtext && line[-1] != '\n')
        line--;
    cr_assert_eq(sscanf(line, "lens2pov: %ld of %ld", &passed, &samples), 2, "%s", errtext);
    free(errtext);
    cr_assert(samples < 16 * 12 * 4 && samples > passed / 2, "%ld samples", samples);
    size_t n;
    csv_ray *rows = read_rays_csv(tmp_path(dir, "f.csv"), &n);
    cr_assert_eq((long)n, passed);
    for (size_t i = 0; i < n; i++)
        cr_assert_lt(hypot(rows[i].film_x, rows[i].film_y), 14.0);
    free(rows);
}

Test(pupil, the_stop_pupil_says_its_pictures_are_biased)
{
    const char *dir = test_tmpdir();
    char *errtext;
    int st = run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--width", "4",
                          "--height", "3", "--spp", "1", "--pupil", "stop", "-o",
                          tmp_path(dir, "s"), "--quiet", NULL);
    cr_assert_eq(st, 0, "%s", errtext);
    cr_assert(strstr(errtext, "warning: --pupil stop") != NULL, "%s", errtext);
    free(errtext);
    /* thick tracing's exit pupil is not the stop's disk either */
    st = run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--width", "4",
                      "--height", "3", "--spp", "1", "--pupil", "stop", "--trace", "thick", "-o",
                      tmp_path(dir, "t"), "--quiet", NULL);
    cr_assert_eq(st, 0, "%s", errtext);
    cr_expect(strstr(errtext, "warning: --pupil stop") != NULL, "%s", errtext);
    free(errtext);
    /* info, the diagram and the plot make no picture: their figures do not use the pupil */
    st = run_lens2pov(NULL, &errtext, "info", LENS_DIR "dgauss.50mm.dat", "--pupil", "stop", NULL);
    cr_assert_eq(st, 0, "%s", errtext);
    cr_expect_str_empty(errtext);
    free(errtext);
    st = run_lens2pov(NULL, &errtext, "diagram", LENS_DIR "dgauss.50mm.dat", "--pupil", "stop",
                      "-o", tmp_path(dir, "d.svg"), NULL);
    cr_assert_eq(st, 0, "%s", errtext);
    cr_expect_str_empty(errtext);
    free(errtext);
}

/* The fisheye's reach is where its image circle ends: a dense grid of directions finds rays
   that pass half a percent inside it, and none 0.1% beyond it. */
Test(pupil, the_reach_is_where_the_image_circle_ends)
{
    const double f_numbers[] = {NAN, 8.0};
    for (int fi = 0; fi < 2; fi++) {
        camera c;
        setup(&c, "fisheye.10mm", f_numbers[fi], 10.0, PUPIL_STOP_IMAGE);
        const double reach = c.pupil.reach_mm;
        cr_assert(reach > 5.0 && reach < 17.5, "f/%g: reach %g mm", f_numbers[fi], reach);
        const long inside = count_cells(&c.lens, v3(0.995 * reach, 0, 0), -1.0, -1.0, 1.0 / 1024, 2048, NULL);
        const long beyond = count_cells(&c.lens, v3(1.001 * reach, 0, 0), -1.0, -1.0, 1.0 / 1024, 2048, NULL);
        cr_assert_gt(inside, 0, "f/%g: nothing passes inside the reach, %g mm", f_numbers[fi], reach);
        cr_assert_eq(beyond, 0, "f/%g: %ld directions pass beyond the reach, %g mm", f_numbers[fi],
                     beyond, reach);
        camera_free(&c);
    }
}

/* info on a film larger than the fisheye's image circle: the field of view is the circle's,
   the same horizontally and diagonally, never "nan", and the circle's diameter is printed. */
Test(pupil, info_gives_the_fisheyes_field_at_its_image_circle)
{
    char *out = NULL, *errtext = NULL;
    int st = run_lens2pov(&out, &errtext, "info", LENS_DIR "fisheye.10mm.dat", "--width", "320",
                          "--height", "240", "--json", NULL);
    cr_assert_eq(st, 0, "%s", errtext);
    double h = NAN, d = NAN, circle = NAN;
    const char *at = strstr(out, "\"hfov_deg\":");
    if (at)
        sscanf(at, "\"hfov_deg\": %lf", &h);
    if ((at = strstr(out, "\"dfov_deg\":")))
        sscanf(at, "\"dfov_deg\": %lf", &d);
    if ((at = strstr(out, "\"image_circle_mm\":")))
        sscanf(at, "\"image_circle_mm\": %lf", &circle);
    cr_assert(h > 140 && h < 180, "hfov %g\n%s", h, out);
    cr_assert_float_eq(d, h, 1e-6, "dfov %g, hfov %g", d, h);
    cr_assert(circle > 20 && circle < 35, "image circle %g mm", circle);
    free(out);
    free(errtext);
    st = run_lens2pov(&out, &errtext, "info", LENS_DIR "fisheye.10mm.dat", "--width", "320",
                      "--height", "240", NULL);
    cr_assert_eq(st, 0);
    cr_assert_null(strstr(out, "nan"), "%s", out);
    free(out);
    free(errtext);
}
