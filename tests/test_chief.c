/* The chief ray and the field angle it defines (optics/chief.h, camera/fieldangle.h): checked
   against a trace in long double, the paraxial focal length, and the lens's own rays, and as
   what --angle and info's field of view do not depend on. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/fieldangle.h"
#include "optics/chief.h"
#include "precision_trace.h"
#include "support.h"

static const char *const LENSES[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm",
                                     "telephoto.250mm", "petzval.50mm", "retrofocus.28mm"};
enum { LENS_COUNT = sizeof LENSES / sizeof LENSES[0] };

static void setup(camera *c, const char *name, double focus_m, double f_number)
{
    camera_options o;
    camera_options_default(&o);
    o.width = 64;
    o.height = 48;
    o.focus_distance_units = focus_m;
    o.f_number = f_number;
    test_camera(c, name, &o);
}

/* The chief ray, traced back from in front of the lens in long double through the opened
   lens, crosses the stop's plane at the axis and lands on its film point: from the axis to the
   film's corner (or the image circle). */
Test(chief, the_chief_ray_crosses_the_stop_at_its_centre)
{
    for (int i = 0; i < LENS_COUNT; i++) {
        camera c;
        setup(&c, LENSES[i], 3.0, NAN);
        chief_lens ch;
        cr_assert_eq(chief_lens_open(&ch, &c.lens), 0);
        const double corner = fmin(0.5 * c.film.diagonal_mm, c.pupil.reach_mm);
        for (int k = 0; k <= 10; k++) {
            const double r = corner * k / 10.0;
            ray y;
            cr_assert(chief_ray(&ch, r, &y), "%s: no chief ray at %g mm", LENSES[i], r);
            /* from 10 mm in front of the lens, back along the ray */
            const vec3 o = v3_madd(y.o, y.d, 10.0);
            ld_ray back = {{o.x, o.y, o.z}, {-y.d.x, -y.d.y, -y.d.z}};
            cr_assert_eq(precision_trace_range(&ch.open, 0, ch.open.stop, false, &back, NULL),
                         TRACE_PASSED);
            const long double z_stop = ch.open.surface[ch.open.stop].vertex_z_mm;
            const long double at = back.o.x + (z_stop - back.o.z) / back.d.z * back.d.x;
            cr_expect(fabsl(at) < 1e-9L, "%s, r %g: crosses the stop %Lg mm off the axis",
                      LENSES[i], r, at);
            cr_assert_eq(precision_trace_range(&ch.open, ch.open.stop + 1, ch.open.count - 1, false,
                                               &back, NULL), TRACE_PASSED);
            const long double x = back.o.x - back.o.z / back.d.z * back.d.x;
            cr_expect(fabsl(x - r) < 1e-9L && fabsl(back.o.y) < 1e-12L,
                      "%s: the chief ray of %g mm comes back to %Lg mm", LENSES[i], r, x);
        }
        chief_lens_close(&ch);
        camera_free(&c);
    }
}

/* Focused at infinity, the film is the rear focal plane: near the axis every lens maps field
   angle to image height as h = f tan(theta), f the effective focal length, whatever its pupils
   and distortion (Smith, Modern Optical Engineering, sec. 2.3). */
Test(chief, near_the_axis_the_field_angle_is_the_focal_lengths)
{
    for (int i = 0; i < LENS_COUNT; i++) {
        char path[512], *out = NULL;
        snprintf(path, sizeof path, LENS_DIR "%s.dat", LENSES[i]);
        cr_assert_eq(run_lens2pov(&out, NULL, "info", path, "--json", NULL), 0);
        const double efl = json_number(out, "efl_mm");
        free(out);
        camera c;
        setup(&c, LENSES[i], INFINITY, NAN);
        chief_lens ch;
        cr_assert_eq(chief_lens_open(&ch, &c.lens), 0);
        const double h = 1e-4;
        double theta;
        cr_assert(chief_angle(&ch, h, &theta));
        cr_expect(fabs(efl * tan(theta) / h - 1.0) < 1e-5, "%s: f tan(theta) = %.9g mm for %g mm "
                  "(f %g mm)", LENSES[i], efl * tan(theta), h, efl);
        chief_lens_close(&ch);
        camera_free(&c);
    }
}

/* info's field of view is the lens's at its focus: the same whichever pupil is sampled and at
   any opening, down to a pinhole (which once shrank it to the few degrees the pupil's fit found
   rays at). */
Test(chief, the_field_of_view_does_not_depend_on_the_pupil_or_the_stop)
{
    const char *const variants[][4] = {
        {NULL}, {"--pupil", "rear", NULL}, {"--pupil", "stop", NULL}, {"--f-number", "22", NULL},
        {"--aperture-diameter", "0.01", NULL}, {"--aperture-diameter", "0.001", NULL}};
    const char *const keys[] = {"hfov_deg", "vfov_deg", "dfov_deg"};
    double first[3] = {0};
    for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
        char *out = NULL;
        char *args[16] = {"info", LENS_DIR "wide.22mm.dat", "--focus-distance", "1", "--json"};
        int n = 5;
        for (int k = 0; k < 3 && variants[v][k]; k++)
            args[n++] = (char *)variants[v][k];
        args[n] = NULL;
        cr_assert_eq(run_lens2pov_argv(&out, NULL, args), 0);
        for (int k = 0; k < 3; k++) {
            const double deg = json_number(out, keys[k]);
            if (v == 0)
                first[k] = deg;
            cr_expect(fabs(deg - first[k]) < 1e-9, "%s %s: %s %.12g against %.12g",
                      variants[v][0] ? variants[v][0] : "", variants[v][0] ? variants[v][1] : "",
                      keys[k], deg, first[k]);
        }
        free(out);
    }
    cr_expect(first[2] > first[0] && first[0] > first[1], "diagonal %g, horizontal %g, vertical %g",
              first[2], first[0], first[1]);
}

/* --angle up to the image circle: the film grows with the angle asked and the field comes out
   as asked; past the circle it is refused. The Petzval's field angle, measured on films of
   other sizes, once went up and down and sent --angle 29 to a film four times too wide. */
Test(chief, angle_grows_the_film_up_to_the_image_circle)
{
    const char *lens = LENS_DIR "petzval.50mm.dat";
    double last_diagonal = 0.0, circle = NAN;
    const char *const angles[] = {"26", "28", "30", "32", "34"};
    for (int i = 0; i < 5; i++) {
        char *out = NULL;
        cr_assert_eq(run_lens2pov(&out, NULL, "info", lens, "--focus-distance", "3", "--angle",
                                  angles[i], "--json", NULL), 0, "--angle %s", angles[i]);
        cr_expect(fabs(json_number(out, "hfov_deg") - atof(angles[i])) < 1e-6, "--angle %s: %s",
                  angles[i], out);
        const double diagonal = json_number(out, "film_diagonal_mm");
        cr_expect(diagonal > last_diagonal, "--angle %s: film diagonal %g after %g", angles[i],
                  diagonal, last_diagonal);
        last_diagonal = diagonal;
        free(out);
    }
    char *out = NULL;
    cr_assert_eq(run_lens2pov(&out, NULL, "info", lens, "--focus-distance", "3", "--film-diagonal",
                              "100", "--json", NULL), 0);
    circle = json_number(out, "image_circle_mm");
    const double most = json_number(out, "hfov_deg");
    free(out);
    cr_expect(last_diagonal * 0.8 < circle, "34 deg on a film of %g mm, the circle %g mm",
              last_diagonal, circle);
    char above[32], *errtext = NULL;
    snprintf(above, sizeof above, "%.6f", most + 0.01);
    cr_expect_eq(run_lens2pov(NULL, &errtext, "info", lens, "--focus-distance", "3", "--angle",
                              above, NULL), 2, "--angle %s (at most %g)", above, most);
    cr_expect(errtext && strstr(errtext, "sees at most"), "%s", errtext ? errtext : "");
    free(errtext);
}

/* A pinhole's image circle is where its chief ray, traced through the real lens with its rims,
   stops getting through: the pupil's fit finds a region far smaller than its scan's step there
   too (it once lost it on a large film, and with it most of the picture). */
Test(chief, a_pinhole_keeps_its_image_circle)
{
    camera_options o;
    camera_options_default(&o);
    o.width = 64;
    o.height = 48;
    o.film_diagonal_mm = 400.0;
    o.focus_distance_units = 1.0;
    o.aperture_diameter_mm = 0.001;
    camera c;
    test_camera(&c, "wide.22mm", &o);
    const double reach = c.pupil.reach_mm;
    cr_assert(reach > 15.0 && reach < 200.0, "reach %g mm", reach);
    chief_lens ch;
    cr_assert_eq(chief_lens_open(&ch, &c.lens), 0);
    const double at[2] = {0.98 * reach, 1.02 * reach};
    for (int k = 0; k < 2; k++) {
        double slope;
        cr_assert(chief_slope(&ch, at[k], &slope));
        ray y = {v3(at[k], 0, 0), v3_normalize(v3(slope, 0, 1))};
        const bool passed = trace_toward_scene(&c.lens, 0, c.lens.count - 1, &y, NULL) == TRACE_PASSED;
        cr_expect_eq(passed, k == 0, "the chief ray at %g mm %s (reach %g mm)", at[k],
                     passed ? "passes" : "is blocked", reach);
    }
    chief_lens_close(&ch);
    camera_free(&c);
}
