/* Stops far smaller than the pupil fit's node spacing can follow by interpolation: the light a
   tiny stop passes is a sliver of the pupil plane about the chief ray's crossing, and the
   sampled region must hold it, however small, and not much more. The reference is computed
   here alone: the chief direction by Newton's method on where the ray meets the stop's plane,
   and the passing set of direction cosines as the preimage of the stop's disk under that map,
   of area pi rho^2 / |det J| (J the map's Jacobian, exact as rho -> 0). */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "optics/trace.h"
#include "support.h"

/* Where the ray from film point p with direction cosines (a, b) meets the stop's plane, after
   the surfaces between film and stop; false when it does not get there. */
static bool stop_point(const lens *l, vec3 p, double a, double b, double *x, double *y)
{
    ray r = {p, v3(a, b, sqrt(1.0 - a * a - b * b))};
    if (l->stop < l->count - 1 &&
        trace_toward_scene(l, l->stop + 1, l->count - 1, &r, NULL) != TRACE_PASSED)
        return false;
    const double t = (l->surface[l->stop].vertex_z_mm - r.o.z) / r.d.z;
    *x = r.o.x + t * r.d.x;
    *y = r.o.y + t * r.d.y;
    return r.d.z > 0.0 && isfinite(*x) && isfinite(*y);
}

/* The map's Jacobian at (a, b) by central differences. */
static bool jacobian(const lens *l, vec3 p, double a, double b, double j[4])
{
    const double h = 1e-6;
    double x1, y1, x2, y2, x3, y3, x4, y4;
    if (!stop_point(l, p, a + h, b, &x1, &y1) || !stop_point(l, p, a - h, b, &x2, &y2) ||
        !stop_point(l, p, a, b + h, &x3, &y3) || !stop_point(l, p, a, b - h, &x4, &y4))
        return false;
    j[0] = (x1 - x2) / (2 * h), j[1] = (x3 - x4) / (2 * h);
    j[2] = (y1 - y2) / (2 * h), j[3] = (y3 - y4) / (2 * h);
    return true;
}

/* The chief direction of p: Newton's method from the direction toward the stop's centre
   seen straight, each step halved until the ray gets to the stop. l: rims opened wide. */
static bool chief_direction(const lens *l, vec3 p, double *a, double *b)
{
    const vec3 d = v3_normalize(v3(-p.x, -p.y, l->surface[l->stop].vertex_z_mm));
    double x, y, j[4];
    *a = d.x;
    *b = d.y;
    if (!stop_point(l, p, *a, *b, &x, &y))
        return false;
    for (int k = 0; k < 100; k++) {
        if (hypot(x, y) < 1e-12)
            return true;
        if (!jacobian(l, p, *a, *b, j))
            return false;
        const double det = j[0] * j[3] - j[1] * j[2];
        double da = -(j[3] * x - j[1] * y) / det, db = -(-j[2] * x + j[0] * y) / det;
        for (int h = 0; h < 40 && !stop_point(l, p, *a + da, *b + db, &x, &y); h++)
            da *= 0.5, db *= 0.5;
        *a += da;
        *b += db;
        if (!stop_point(l, p, *a, *b, &x, &y))
            return false;
    }
    return false;
}

/* l with every rim opened wide: where a ray meets the stop's plane does not depend on them. */
static void open_rims(lens *l)
{
    for (int i = 0; i < l->count; i++)
        l->surface[i].aperture_diameter_mm = 1e9;
    l->stop_diameter_mm = 1e9;
}

/* Whether the whole lens passes the ray from p with direction cosines (a, b). */
static bool passes(const lens *l, vec3 p, double a, double b)
{
    ray r = {p, v3(a, b, sqrt(1.0 - a * a - b * b))};
    return trace_toward_scene(l, 0, l->count - 1, &r, NULL) == TRACE_PASSED;
}

/* The film irradiance of a uniform background of radiance 1 through a stop of radius rho:
   the area of the passing set of direction cosines (d(omega) cos(theta) = da db), 0 where
   the chief ray is blocked. NAN where a rim comes near the sliver (rays 30 times its size from
   the chief one differ in passing): there neither is the answer, and the fit, which follows
   the rims there, samples more than the sliver (the image circle's edge is tested in
   test_pupil.c). */
static double tiny_irradiance(const lens *l, vec3 p, double rho)
{
    double a, b, j[4];
    lens open;
    cr_assert_eq(lens_copy(&open, l), 0);
    open_rims(&open);
    cr_assert(chief_direction(&open, p, &a, &b), "%s: no chief ray from (%g, %g)", l->path, p.x, p.y);
    cr_assert(jacobian(&open, p, a, b, j));
    lens_free(&open);
    const double det = fabs(j[0] * j[3] - j[1] * j[2]);
    /* the sliver's longest semi-axis is rho / s, s the smaller singular value of J */
    const double q = j[0] * j[0] + j[1] * j[1] + j[2] * j[2] + j[3] * j[3];
    const double s2 = 0.5 * (q - sqrt(fmax(0.0, q * q - 4.0 * det * det)));
    const double reach = 30.0 * rho / sqrt(s2);
    lens rims;   /* the stop opened to its full diameter, the rims kept */
    cr_assert_eq(lens_copy(&rims, l), 0);
    rims.stop_diameter_mm = rims.surface[rims.stop].aperture_diameter_mm;
    const bool chief = passes(&rims, p, a, b);
    bool clear = true;
    for (int k = 0; k < 8; k++)
        clear &= passes(&rims, p, a + reach * cos(k * M_PI / 4), b + reach * sin(k * M_PI / 4)) == chief;
    lens_free(&rims);
    if (!clear)
        return NAN;
    return chief ? M_PI * rho * rho / det : 0.0;
}

/* A uniform number in [0, 1) from a 64-bit LCG (Knuth's MMIX constants), for jitter. */
static double jitter(uint64_t *state)
{
    *state = *state * 6364136223846793005u + 1442695040888963407u;
    return (double)(*state >> 11) * 0x1p-53;
}

static const char *const LENSES[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm",
                                     "telephoto.250mm", "petzval.50mm"};

/* Stops of 1e-3, 1e-5 and 1e-7 mm on five lenses, without dispersion: at film points across
   the diagonal, the estimate with 32 x 32 jittered samples matches the reference within 1%,
   and at least half of the samples pass (before the chief ray was tabulated, none did off
   the axis at 1e-7 mm). The sampled region holds the sliver with a margin of 0.4% in
   radius, so only the outer ring of strata (124 of 1024) can miss: about 6% of them do,
   which scatters the estimate by about 0.3%; the reference's own error, of order rho over
   the lens's radii, is far below that. */
Test(tiny_stop, the_light_of_a_tiny_stop_is_found_and_measured)
{
    const double diameters_mm[] = {1e-3, 1e-5, 1e-7};
    int compared = 0;   /* film points where the lens passes the sliver whole */
    for (int li = 0; li < 5; li++)
        for (int di = 0; di < 3; di++) {
            camera_options o;
            camera_options_default(&o);
            o.width = 64;
            o.height = 48;
            o.focus_distance_units = 10.0;
            o.aperture_diameter_mm = diameters_mm[di];
            o.weighting = WEIGHTING_PHYSICAL;
            o.dispersion = DISPERSION_OFF;
            camera c;
            test_camera(&c, LENSES[li], &o);
            for (int i = 0; i <= 8; i++) {
                const vec3 p = v3(0.5 * c.film.width_mm * i / 8.5, 0.5 * c.film.height_mm * i / 8.5, 0);
                const double want = tiny_irradiance(&c.lens, p, 0.5 * diameters_mm[di]);
                if (isnan(want))
                    continue;
                compared += want > 0.0;
                enum { SIDE = 32 };
                double sum = 0.0;
                int passed = 0;
                uint64_t state = 7;
                for (int s = 0; s < SIDE * SIDE; s++) {
                    ray r;
                    double w;
                    const double u = (s % SIDE + jitter(&state)) / SIDE;
                    const double v = (s / SIDE + jitter(&state)) / SIDE;
                    if (camera_trace(&c, p, u, v, &r, &w))
                        sum += w, passed++;
                }
                const double got = sum / (SIDE * SIDE);
                cr_expect(fabs(got - want) <= 0.01 * want, "%s, stop %g mm, film (%.2f, %.2f): "
                          "%.6g against %.6g", LENSES[li], diameters_mm[di], p.x, p.y, got, want);
                cr_expect(want == 0.0 || passed >= SIDE * SIDE / 2, "%s, stop %g mm, film (%.2f, "
                          "%.2f): %d of %d samples pass", LENSES[li], diameters_mm[di], p.x, p.y,
                          passed, SIDE * SIDE);
            }
            camera_free(&c);
        }
    /* 135 points in all; the fisheye's and the Petzval's outer ones lie beyond their reach */
    cr_expect_geq(compared, 100, "only %d film points compared", compared);
}

/* The share of "N of M rays pass" in trace's report. */
static double reported_share(const char *errtext)
{
    long long passed, all;
    const char *at = strstr(errtext, " rays pass the lens");
    cr_assert(at, "%s", errtext);
    while (at > errtext && at[-1] != '\n')
        at--;
    cr_assert_eq(sscanf(at, "lens2pov: %lld of %lld", &passed, &all), 2, "%s", at);
    return (double)passed / (double)all;
}

/* Through a glass lens with dispersion, a stop of 0.5 um passes its light at a place in the
   pupil that moves with the wavelength by far more than its size: a small share of the
   samples passes, and before any work the user is told so, with the share the trace then
   reports (the probe's within a factor of two of it), and what would help; at 10 nm none
   pass, and the picture is said to be black. At f/16 nothing is said. */
Test(tiny_stop, a_stop_that_few_samples_pass_is_warned_of)
{
    const char *dir = test_tmpdir(), *lens = LENS_DIR "petzval.50mm.dat";
    char *out, *errtext;
    cr_assert_eq(run_lens2pov(&out, &errtext, "trace", lens, "--width", "64", "--height", "48",
                              "--aperture-diameter", "0.0005", "--sampling", "pixel", "-o",
                              tmp_path(dir, "few"), NULL), 0, "%s", errtext);
    double probe;
    const char *w = strstr(errtext, "warning: only ");
    cr_assert(w && sscanf(w, "warning: only %lf%%", &probe) == 1, "%s", errtext);
    const double share = reported_share(errtext);
    cr_expect(share > 0.0 && probe / 100.0 > 0.5 * share && probe / 100.0 < 2.0 * share,
              "probe %g%% against %g%%", probe, 100.0 * share);
    cr_expect(strstr(errtext, "--dispersion off"), "%s", errtext);
    free(out), free(errtext);
    cr_assert_eq(run_lens2pov(&out, &errtext, "trace", lens, "--width", "64", "--height", "48",
                              "--aperture-diameter", "0.00001", "--sampling", "pixel", "-o",
                              tmp_path(dir, "none"), NULL), 0, "%s", errtext);
    cr_expect(strstr(errtext, "the picture will be black"), "%s", errtext);
    cr_expect_eq(reported_share(errtext), 0.0);
    free(out), free(errtext);
    cr_assert_eq(run_lens2pov(&out, &errtext, "trace", lens, "--width", "64", "--height", "48",
                              "--f-number", "16", "--sampling", "pixel", "-o",
                              tmp_path(dir, "f16"), NULL), 0, "%s", errtext);
    cr_expect(!strstr(errtext, "get through the lens"), "%s", errtext);
    free(out), free(errtext);
    /* so small that its f-number overflows and the lens reaches no film point: still said, and
       no inf or nan printed */
    cr_assert_eq(run_lens2pov(&out, &errtext, "trace", lens, "--width", "8", "--height", "6",
                              "--aperture-diameter", "1e-307", "--weighting", "physical",
                              "--dispersion", "off", "-o", tmp_path(dir, "zero"), NULL), 0, "%s",
                 errtext);
    cr_expect(strstr(errtext, "the picture will be black") &&
              strstr(errtext, "would blur every point over the whole film") &&
              !strstr(errtext, "inf ") && !strstr(errtext, "nan"), "%s", errtext);
    free(out), free(errtext);
    remove_tree(dir);
}
