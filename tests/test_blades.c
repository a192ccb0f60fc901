/* Aperture blades: the stop test at the polygon's corners and edges, in the one-ray tracer and
   the batch; the N-fold shape of a defocused point's light; and the film irradiance through the
   blades against the independent integral of test_pupil.c (the same quantity, other code). */
#include <criterion/criterion.h>
#include <math.h>
#include <string.h>
#include "camera/camera.h"
#include "optics/lens.h"
#include "optics/trace.h"
#include "optics/trace_batch.h"
#include "support.h"

/* A flat window, the stop (10 mm) and a flat window: a ray parallel to the axis crosses the
   stop where it starts, unbent. */
static void window_lens(lens *l, int blades, double rotation_deg)
{
    static const char text[] = "1e12 2 1.5 20\n0 5 0 10\n-1e12 3 1 20\n";
    l2p_error err;
    cr_assert_eq(lens_parse(text, sizeof text - 1, "window", l, &err), 0, "%s", err.text);
    lens_set_film_distance(l, 10.0);
    lens_set_blades(l, blades, rotation_deg * M_PI / 180.0);
}

/* Whether the axis-parallel ray from film point (x, y) passes, in the one-ray tracer; the
   batch must agree. */
static bool passes(const lens *l, double x, double y)
{
    ray r = {v3(x, y, 0), v3(0, 0, 1)};
    const bool one = trace_toward_scene(l, 0, l->count - 1, &r, NULL) == TRACE_PASSED;
    trace_batch b;
    memset(&b, 0, sizeof b);
    b.ox[0] = x;
    b.oy[0] = y;
    b.dz[0] = 1.0;
    b.status[0] = TRACE_PASSED;
    trace_batch_toward_scene(l, &b, 1);
    cr_assert_eq(one, b.status[0] == TRACE_PASSED, "(%g, %g): the batch and the one-ray tracer "
                 "disagree", x, y);
    return one;
}

/* Five blades turned by 10 degrees: a corner at 10 + 72 k degrees on the 5 mm circle, an
   edge's middle at 46 + 72 k degrees, 5 cos 36 = 4.045 mm from the axis. Just inside a corner
   and an edge passes; just beyond an edge, or past a corner along the circle, does not. */
Test(blades, the_stop_is_the_polygon_at_corners_and_edges)
{
    lens l;
    window_lens(&l, 5, 10.0);
    const double r = 5.0, apothem = r * cos(M_PI / 5);
    for (int k = 0; k < 5; k++) {
        const double corner = (10.0 + 72.0 * k) * M_PI / 180.0, edge = corner + 36.0 * M_PI / 180.0;
        cr_expect(passes(&l, 0.999 * r * cos(corner), 0.999 * r * sin(corner)), "corner %d", k);
        cr_expect(passes(&l, 0.999 * apothem * cos(edge), 0.999 * apothem * sin(edge)), "edge %d", k);
        cr_expect(!passes(&l, 1.001 * apothem * cos(edge), 1.001 * apothem * sin(edge)),
                  "beyond edge %d", k);
        /* On the circle, a fifth of the way from the corner to the next: outside the polygon. */
        const double between = corner + 14.4 * M_PI / 180.0;
        cr_expect(!passes(&l, 0.99 * r * cos(between), 0.99 * r * sin(between)), "arc %d", k);
    }
    /* Round again without blades: the same arc point passes. */
    lens_set_blades(&l, 0, 0.0);
    cr_expect(passes(&l, 0.99 * r * cos(24.4 * M_PI / 180.0), 0.99 * r * sin(24.4 * M_PI / 180.0)));
    lens_free(&l);
}

/* The light of the film centre, defocused: the rays it sends out, where they cross a plane
   far beyond the focus, fill the image of the opening. Its outline r(phi) about the axis has
   period 360/N degrees, and its largest over its smallest radius is the polygon's
   1 / cos(pi / N) (1 for a round stop). */
static void outline(int blades, double out[72])
{
    camera c;
    camera_options o;
    camera_options_default(&o);
    o.width = 64;
    o.height = 48;
    o.focus_distance_units = 0.5;
    o.f_number = 5.6;
    o.aperture_blades = blades;
    o.blade_rotation_deg = 7.0;
    test_camera(&c, "dgauss.50mm", &o);
    memset(out, 0, 72 * sizeof *out);
    const double plane_mm = 20000.0;
    for (int j = 0; j < 250; j++)
        for (int i = 0; i < 250; i++) {
            ray r;
            double w;
            if (!camera_trace(&c, v3(0, 0, 0), (i + 0.5) / 250, (j + 0.5) / 250, &r, &w))
                continue;
            const double t = (plane_mm - r.o.z) / r.d.z;
            const double x = r.o.x + t * r.d.x, y = r.o.y + t * r.d.y;
            int bin = (int)floor(atan2(y, x) * 36.0 / M_PI + 72.0) % 72;
            out[bin] = fmax(out[bin], hypot(x, y));
        }
    camera_free(&c);
}

Test(blades, a_defocused_point_takes_the_shape_of_the_blades)
{
    for (int n = 5; n <= 6; n++) {
        double r[72];
        outline(n, r);
        double lo = INFINITY, hi = 0, worst = 0;
        for (int b = 0; b < 72; b++) {
            lo = fmin(lo, r[b]);
            hi = fmax(hi, r[b]);
        }
        /* The period: 72 bins of 5 degrees, 360/N degrees is 72/N bins (not whole for N = 5:
           compare at the nearest bins, within the bin's own spread). */
        for (int b = 0; b < 72; b++) {
            const double shifted = b + 72.0 / n;
            const int b1 = (int)floor(shifted) % 72, b2 = (b1 + 1) % 72;
            const double w = shifted - floor(shifted);
            worst = fmax(worst, fabs((1 - w) * r[b1] + w * r[b2] - r[b]) / hi);
        }
        cr_expect(worst < 0.03, "%d blades: the outline repeats every %g degrees only within %.1f%%",
                  n, 360.0 / n, 100 * worst);
        const double want = 1.0 / cos(M_PI / n);
        cr_expect(fabs(hi / lo - want) < 0.02 * want, "%d blades: outline %.4f .. %.4f, ratio %.4f, "
                  "the polygon's %.4f", n, lo, hi, hi / lo, want);
    }
    double round[72];
    outline(0, round);
    double lo = INFINITY, hi = 0;
    for (int b = 0; b < 72; b++) {
        lo = fmin(lo, round[b]);
        hi = fmax(hi, round[b]);
    }
    cr_expect(hi / lo < 1.01, "round stop: outline %.4f .. %.4f", lo, hi);
}

/* --blade-rotation turns blades: without --aperture-blades it changes nothing, and says so. */
Test(blades, a_rotation_without_blades_is_warned_of)
{
    const char *dir = test_tmpdir();
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--width", "8",
                              "--height", "6", "--spp", "1", "-q", "--blade-rotation", "10", "-o",
                              tmp_path(dir, "t"), NULL), 0, "%s", errtext);
    cr_expect(strstr(errtext, "--blade-rotation 10 turns blades, and the stop has none"), "%s",
              errtext);
    free(errtext);
    cr_assert_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--width", "8",
                              "--height", "6", "--spp", "1", "-q", "--blade-rotation", "10",
                              "--aperture-blades", "6", "-o", tmp_path(dir, "u"), NULL), 0, "%s",
                 errtext);
    cr_expect(!strstr(errtext, "--blade-rotation"), "%s", errtext);
    free(errtext);
}
