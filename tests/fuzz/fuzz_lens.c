/* libFuzzer target: the lens-file reader, and the optics behind it.

   Any bytes go to lens_parse. A refusal must be L2P_BAD_INPUT (or L2P_FAILED for memory) with
   a message that starts with the file's name and line ("fuzz.dat:N: "; only "no surfaces" and
   "no aperture stop", about the whole file, name no line). A lens that parses is then set up as a camera
   with the defaults on a tiny film and a few samples are traced: camera_setup may refuse it
   (L2P_BAD_INPUT only), and every ray that passes must be finite, with a unit direction, a
   positive finite weight, and a finite thick lens. Crashes, sanitizer reports and these checks
   (abort) are what the fuzzer finds. Built by tests/fuzz/run.sh. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "optics/lens.h"

#define NAME "fuzz.dat"

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_lens: %s: %s\n", what, detail);
    abort();
}

static void trace_a_few(const camera *c)
{
    /* The film's corners, edges and centre, four pupil samples each. */
    for (int j = 0; j <= 2; j++)
        for (int i = 0; i <= 2; i++)
            for (int k = 0; k < 4; k++) {
                const vec3 p = film_camera_from_raster(&c->film, i * 0.5 * c->film.width,
                                                       j * 0.5 * c->film.height);
                ray r;
                double w;
                if (!camera_trace(c, p, 0.125 + 0.25 * k, 0.875 - 0.25 * k, &r, &w))
                    continue;
                if (!v3_isfinite(r.o) || !v3_isfinite(r.d) || !(fabs(v3_length(r.d) - 1) < 1e-9))
                    fail("a ray that passes is not finite or not unit", "");
                if (!(w > 0) || !isfinite(w))
                    fail("a ray that passes has a bad weight", "");
            }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lens l;
    l2p_error err = {0, ""};
    int st = lens_parse((const char *)data, size, NAME, &l, &err);
    if (st) {
        if (st != L2P_BAD_INPUT && st != L2P_FAILED)
            fail("lens_parse status", err.text);
        if (strncmp(err.text, NAME ":", strlen(NAME) + 1) != 0 && st == L2P_BAD_INPUT)
            fail("a refusal that does not name the file", err.text);
        /* ... and the line, but for what the whole file lacks. */
        const char *after = err.text + strlen(NAME) + 1;
        if (st == L2P_BAD_INPUT && !(*after >= '1' && *after <= '9') &&
            strcmp(after, " no surfaces") && strcmp(after, " no aperture stop (a row with radius 0)"))
            fail("a refusal that does not name the line", err.text);
        return 0;
    }
    if (l.count < 2 || l.stop < 0 || l.stop >= l.count)
        fail("a lens without a stop or a surface", "");
    for (int i = 0; i < l.count; i++)
        if (!isfinite(l.surface[i].radius_mm) || !isfinite(l.surface[i].thickness_mm) ||
            !isfinite(l.surface[i].ior) || !(l.surface[i].aperture_diameter_mm > 0) ||
            !isfinite(l.surface[i].curvature_per_mm))
            fail("a surface that is not finite", "");
    camera_options o;
    camera_options_default(&o);
    o.width = 8;
    o.height = 6;
    o.spp = 1;
    camera c;
    st = camera_setup(&c, &l, &o, &err);
    if (st == L2P_OK) {
        if (!isfinite(c.lens.film_distance_mm) || !isfinite(c.pupil.z_mm) ||
            !isfinite(c.pupil.radius_mm) || !isfinite(c.weight_scale) ||
            !isfinite(c.thick.rear_focal_length_mm))
            fail("camera_setup succeeded with a non-finite camera", "");
        trace_a_few(&c);
    } else if (st != L2P_BAD_INPUT) {
        fail("camera_setup status", err.text);
    }
    camera_free(&c);
    return 0;
}
