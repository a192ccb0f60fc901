/* A large render keeps, for each sub-image, only where its pixels pass (src/field/fieldpass.c)
   and makes the weights again when it develops: they must be the weights the sub-image was
   built with, bit for bit, on every pupil, with dispersion, stopped down, cropped, and on a
   film larger than the fisheye's image circle; and the runs must be few, as the faces are. */
#include <criterion/criterion.h>
#include <stdlib.h>
#include <string.h>
#include "field/field_render.h"
#include "field/fieldpass.h"
#include "field/fieldpixels.h"
#include "field/strata.h"
#include "field/subimage.h"
#include "support.h"

typedef struct pass_case {
    const char *lens;
    double f_number;           /* 0: full aperture */
    pupil_kind pupil;
    trace_kind trace;
    bool dispersion, crop;
} pass_case;

static const pass_case CASES[] = {
    {"dgauss.50mm", 0, PUPIL_STOP_IMAGE, TRACE_KIND_FULL, false, false},
    {"dgauss.50mm", 8, PUPIL_STOP_IMAGE, TRACE_KIND_FULL, false, false},
    {"dgauss.50mm", 0, PUPIL_REAR, TRACE_KIND_FULL, false, false},
    {"dgauss.50mm", 0, PUPIL_STOP_IMAGE, TRACE_KIND_THICK, false, false},
    {"fisheye.10mm", 0, PUPIL_STOP_IMAGE, TRACE_KIND_FULL, false, false},
    {"wide.22mm", 0, PUPIL_STOP_IMAGE, TRACE_KIND_FULL, false, true},
    {"telephoto.250mm", 5.6, PUPIL_REAR, TRACE_KIND_FULL, false, false},
    {"cooke-triplet.50mm", 0, PUPIL_STOP_IMAGE, TRACE_KIND_FULL, true, false},
};

static void check_case(const pass_case *p)
{
    camera_options o;
    camera_options_default(&o);
    o.width = 160, o.height = 120, o.spp = 8, o.seed = 3;
    o.location = v3(0, 1, -4), o.look_at = v3(0, 1, 0);
    o.pupil = p->pupil, o.trace = p->trace;
    o.dispersion = p->dispersion ? DISPERSION_ON : DISPERSION_OFF;
    if (p->f_number > 0)
        o.f_number = p->f_number;
    if (p->crop)
        o.crop_x0 = 100, o.crop_y0 = 70, o.crop_x1 = 160, o.crop_y1 = 120;
    camera c;
    test_camera(&c, p->lens, &o);
    field_tolerance t;
    field_tolerance_of(&c, FIELD_DEFAULT_TOLERANCE_PX, &t);
    field_strata strata;
    field_strata_count(&c, c.samples.spp, &strata);
    const int w = c.crop_x1 - c.crop_x0, h = c.crop_y1 - c.crop_y0;
    const long long pixels = (long long)w * h;
    float *built = malloc(sizeof *built * (size_t)pixels);
    float *again = malloc(sizeof *again * (size_t)pixels);
    cr_assert(built && again);
    long long blocked = 0;
    for (int k = 0; k < o.spp; k++) {
        film_sample s = field_shared_sample(&c, k, NULL);
        const double scale = field_strata_place(&strata, &s);
        field_mesh m;
        field_stats st;
        l2p_error err;
        field_mesh_init(&m, field_render_size(w), field_render_size(h));
        cr_assert_eq(field_build_subimage(&c, s, scale, &t, FIELD_COARSEST_CELL, &m, built, &st,
                                          &err), L2P_OK, "%s", err.text);
        field_pass pass;
        float *given = built;
        cr_assert_eq(field_pass_of(&given, pixels, s, scale, false, &pass, &err), L2P_OK);
        cr_assert(given == built && !pass.weights, "the weights are not taken");
        memset(again, 0xff, sizeof *again * (size_t)pixels);   /* NaN: each must be written */
        cr_assert_eq(field_pass_weights(&c, &pass, again, &err), L2P_OK);
        long long differ = 0, passing = 0;
        for (long long i = 0; i < pixels; i++) {
            differ += memcmp(&built[i], &again[i], sizeof *built) != 0;
            passing += built[i] > 0;
        }
        cr_expect_eq(differ, 0, "%s f/%g sub-image %d: %lld of %lld weights differ", p->lens,
                     c.f_number, k, differ, pixels);
        cr_expect_eq(passing, st.passed, "%s sub-image %d", p->lens, k);
        /* A row crosses the edge of the region a pupil point sees through a few times at
           most, so the runs grow with the rows, not with the pixels. Near the fisheye's image
           circle some samples pass and are blocked by turns, in thin rings (docs/fields.md,
           "Memory and disk"): four runs a row. */
        cr_expect_leq(pass.run_count, 4 * h, "%s sub-image %d: %lld runs for %d rows", p->lens,
                      k, pass.run_count, h);
        blocked += pixels - passing;
        field_pass_free(&pass);
        field_mesh_free(&m);
    }
    cr_log_info("%s f/%g: %lld of %lld pixels blocked", p->lens, c.f_number, blocked,
                pixels * o.spp);
    if (!strcmp(p->lens, "fisheye.10mm"))
        cr_expect_gt(blocked, 0, "the fisheye's image circle lies inside the film");
    free(built), free(again);
    camera_free(&c);
}

Test(field_pass, weights_made_again_are_the_built_ones)
{
    for (size_t i = 0; i < sizeof CASES / sizeof *CASES; i++)
        check_case(&CASES[i]);
}

/* A sub-image that passes nowhere has no runs, and its weights are all 0; one that passes
   everywhere is one run; weights kept are given back as they are. */
Test(field_pass, no_pixel_every_pixel_and_weights_kept)
{
    float none[12] = {0}, all[12], again[12];
    for (int i = 0; i < 12; i++)
        all[i] = 1;
    field_pass p;
    l2p_error err;
    float *given = none;
    cr_assert_eq(field_pass_of(&given, 12, (film_sample){0}, 1.0, false, &p, &err), L2P_OK);
    cr_expect_eq(p.run_count, 0);
    camera_options o;
    camera_options_default(&o);
    o.width = 4, o.height = 3, o.spp = 1;
    camera c;
    test_camera(&c, "dgauss.50mm", &o);
    memset(again, 0xff, sizeof again);
    cr_assert_eq(field_pass_weights(&c, &p, again, &err), L2P_OK);
    for (int i = 0; i < 12; i++)
        cr_expect_eq(again[i], 0.0f, "pixel %d", i);
    field_pass_free(&p);
    given = all;
    cr_assert_eq(field_pass_of(&given, 12, (film_sample){0}, 1.0, false, &p, &err), L2P_OK);
    cr_expect_eq(p.run_count, 1);
    cr_expect(p.runs[0] == 0 && p.runs[1] == 12, "[%lld, %lld)", p.runs[0], p.runs[1]);
    field_pass_free(&p);
    float *kept = malloc(sizeof all);
    cr_assert_not_null(kept);
    for (int i = 0; i < 12; i++)
        kept[i] = (float)i;   /* not what the camera would give: given back as kept */
    given = kept;
    cr_assert_eq(field_pass_of(&given, 12, (film_sample){0}, 1.0, true, &p, &err), L2P_OK);
    cr_expect(!given && p.weights == kept && p.run_count == 0);
    cr_assert_eq(field_pass_weights(&c, &p, again, &err), L2P_OK);
    for (int i = 0; i < 12; i++)
        cr_expect_eq(again[i], (float)i, "pixel %d", i);
    field_pass_free(&p);   /* frees kept */
    camera_free(&c);
}

/* A sub-image whose passing pixels come one in two (a checkerboard) would take more memory as
   runs than as floats: its weights are kept as they are. */
Test(field_pass, runs_that_would_outweigh_the_floats_are_not_kept)
{
    float *w = malloc(sizeof *w * 64);
    cr_assert_not_null(w);
    for (int i = 0; i < 64; i++)
        w[i] = (float)((i + i / 8) % 2);
    float *given = w;
    field_pass p;
    l2p_error err;
    cr_assert_eq(field_pass_of(&given, 64, (film_sample){0}, 1.0, false, &p, &err), L2P_OK);
    cr_expect(!given && p.weights == w && p.run_count == 0, "32 runs in 64 pixels were kept");
    field_pass_free(&p);
}

#include "field/field_files.h"

/* What field_files_make keeps for develop: the floats within the bound, the runs beyond it
   (render), nothing for trace; the map in memory gives the same weights either way. */
Test(field_pass, render_keeps_floats_within_the_bound_and_runs_beyond)
{
    camera_options o;
    camera_options_default(&o);
    o.width = 64, o.height = 48, o.spp = 4, o.seed = 1;
    o.location = v3(0, 1, -4), o.look_at = v3(0, 1, 0);
    camera c;
    test_camera(&c, "fisheye.10mm", &o);
    const char *dir = test_tmpdir();
    const double bounds[2] = {0.0, 1e9};
    field_files f[3];
    l2p_error err;
    for (int i = 0; i < 3; i++) {
        const field_files_request q = {.prefix = tmp_path(dir, i == 0 ? "a" : i == 1 ? "b" : "c"),
                                       .jobs = 1, .tolerance_px = FIELD_DEFAULT_TOLERANCE_PX,
                                       .frame_s = FIELD_FRAME_S, .map_file = i == 2,
                                       .weights_kept_bytes = i < 2 ? bounds[i] : 0.0,
                                       .develops = i < 2};
        cr_assert_eq(field_files_make(&c, &q, &f[i], &err), L2P_OK, "%s", err.text);
    }
    cr_expect(f[2].pass == NULL && f[2].table.weights_of == NULL, "trace keeps weights");
    const size_t pixels = 64 * 48;
    float *w[2] = {malloc(sizeof(float) * pixels), malloc(sizeof(float) * pixels)};
    cr_assert(w[0] && w[1]);
    long long runs = 0;
    for (int k = 0; k < o.spp; k++) {
        cr_expect(!f[0].pass[k].weights, "sub-image %d: floats kept at a bound of 0", k);
        cr_expect_not_null(f[1].pass[k].weights, "sub-image %d: floats not kept", k);
        runs += f[0].pass[k].run_count;
        for (int i = 0; i < 2; i++)
            cr_assert_eq(field_map_weights(&f[i].table, k, w[i], &err), L2P_OK, "%s", err.text);
        cr_expect(memcmp(w[0], w[1], sizeof(float) * pixels) == 0, "sub-image %d differs", k);
    }
    cr_expect_gt(runs, 0, "the fisheye's image circle gives runs");
    free(w[0]), free(w[1]);
    for (int i = 0; i < 3; i++)
        field_files_free(&f[i]);
    camera_free(&c);
}
