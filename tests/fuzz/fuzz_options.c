/* libFuzzer target: option parsing, and the camera the options make.

   The bytes are split at '\n' into words (a word may be empty or hold spaces), given to
   cli_parse after "lens2pov trace". A refusal must be L2P_BAD_INPUT with a message. Accepted
   options are then applied to a fixed lens (the bundled double Gauss) with camera_setup, which
   may refuse them (L2P_BAD_INPUT only); a camera it accepts traces a few samples of its crop,
   and every ray that passes must be finite in camera and in world space, with a positive
   finite weight. Built by tests/fuzz/run.sh. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "cli/cli.h"
#include "optics/lens.h"

static const char DGAUSS[] =
    "29.475 3.76 1.67 25.2\n84.83 0.12 1 25.2\n19.275 4.025 1.67 23\n40.77 3.275 1.699 23\n"
    "12.75 5.705 1 18\n0 4.5 0 17.1\n-14.495 1.18 1.603 17\n40.77 6.065 1.658 20\n"
    "-20.385 0.19 1 20\n437.065 3.22 1.717 20\n-39.73 0 1 20\n";

enum { MAX_WORDS = 64, MAX_BYTES = 4096 };

static void fail(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_options: %s: %s\n", what, detail);
    abort();
}

static void trace_a_few(const camera *c)
{
    const int xs[3] = {c->crop_x0, (c->crop_x0 + c->crop_x1) / 2, c->crop_x1 - 1};
    const int ys[3] = {c->crop_y0, (c->crop_y0 + c->crop_y1) / 2, c->crop_y1 - 1};
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < c->samples.spp && k < 4; k++) {
                const film_sample s = sample_pattern_get(&c->samples, xs[i], ys[j], k);
                if (!(s.offset_x >= 0 && s.offset_x < 1 && s.offset_y >= 0 && s.offset_y < 1 &&
                      s.pupil_u >= 0 && s.pupil_u < 1 && s.pupil_v >= 0 && s.pupil_v < 1))
                    fail("a sample outside its pixel or the unit square", "");
                const vec3 p = film_camera_from_raster(&c->film, xs[i] + s.offset_x,
                                                       ys[j] + s.offset_y);
                if (!v3_isfinite(p))
                    fail("a film point that is not finite", "");
                ray r;
                double w;
                if (!camera_trace(c, p, s.pupil_u, s.pupil_v, &r, &w))
                    continue;
                const vec3 wo = camera_world_from_camera_point(c, r.o);
                const vec3 wd = camera_world_from_camera_dir(c, r.d);
                if (!v3_isfinite(r.o) || !v3_isfinite(r.d) || !v3_isfinite(wo) ||
                    !v3_isfinite(wd) || !(w > 0) || !isfinite(w))
                    fail("a ray that passes is not finite", "");
            }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > MAX_BYTES)
        return 0;
    char text[MAX_BYTES + 1];
    memcpy(text, data, size);
    text[size] = '\0';
    char *argv[MAX_WORDS + 3];
    int argc = 0;
    argv[argc++] = "lens2pov";
    argv[argc++] = "trace";
    for (char *w = text; argc < MAX_WORDS + 2;) {
        argv[argc++] = w;
        char *nl = memchr(w, '\n', (size_t)(text + size - w));
        if (!nl)
            break;
        *nl = '\0';
        w = nl + 1;
    }
    argv[argc] = NULL;
    cli c;
    l2p_error err = {0, ""};
    int st = cli_parse(&c, argc, argv, 2, &err);
    if (st) {
        if (st != L2P_BAD_INPUT || !err.text[0])
            fail("cli_parse refused without L2P_BAD_INPUT and a message", err.text);
        return 0;
    }
    const camera_options *o = &c.cam;
    if (o->width <= 0 || o->height <= 0 || o->spp <= 0 || !(o->film_diagonal_mm > 0) ||
        !(o->unit_mm > 0) || !v3_isfinite(o->location) || !v3_isfinite(o->look_at) ||
        !v3_isfinite(o->sky) || (!isnan(o->film_distance_mm) && !isnan(o->focus_distance_units)))
        fail("cli_parse accepted an invalid value", "");
    lens l;
    if (lens_parse(DGAUSS, sizeof DGAUSS - 1, "dgauss.50mm.dat", &l, &err))
        fail("the fixed lens", err.text);
    camera cam;
    st = camera_setup(&cam, &l, o, &err);
    if (st == L2P_OK)
        trace_a_few(&cam);
    else if (st != L2P_BAD_INPUT)
        fail("camera_setup status", err.text);
    camera_free(&cam);
    return 0;
}
