/* render --sampling field through the real POV-Ray: refusals, and a field render agreeing with
   a pixel render of a scene with edges within the noise of two pixel renders. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "image/image_io.h"
#include "support.h"

#define L2P(out, errtext, ...) run_lens2pov(out, errtext, __VA_ARGS__, (char *)NULL)

/* Edges everywhere: a checker floor, a sphere against a sky gradient, one light. */
static const char *SCENE =
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
    "camera { location <0, 1, -4> look_at <0, 0.6, 0> }\n"
    "light_source { <-3, 5, -4> rgb 1 }\n"
    "sky_sphere { pigment { gradient y color_map { [0 rgb <0.6,0.7,0.9>] [1 rgb <0.1,0.2,0.6>] } } }\n"
    "plane { y, 0 pigment { checker rgb 0.9 rgb 0.1 scale 0.5 } finish { ambient 0.2 diffuse 0.8 } }\n"
    "sphere { <0.3, 0.8, 0.5>, 0.8 pigment { rgb <0.8, 0.2, 0.1> } finish { ambient 0.2 diffuse 0.8 } }\n";

/* The scene at 48 x 36 through the double-Gauss at f/2.8: with pixel or field sampling at 16
   spp, or "adaptive", field sampling with --adaptive at a mean of 32. */
static float *render(const char *dir, const char *name, const char *sampling, const char *seed)
{
    const char *scene = tmp_path(dir, "scene.pov");
    char out[4096];
    snprintf(out, sizeof out, "%s/%s.exr", dir, name);
    char *errtext = NULL;
    const bool adaptive = !strcmp(sampling, "adaptive");
    int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--width", "48",
                 "--height", "36", "--spp", adaptive ? "32" : "16", "--f-number", "2.8", "--seed",
                 seed, "--sampling", adaptive ? "field" : sampling, "--jobs", "2", "--quiet", "-o",
                 out, adaptive ? "--adaptive" : "--quiet");
    cr_assert_eq(st, 0, "render %s: %s", name, errtext ? errtext : "");
    free(errtext);
    int w, h;
    float *px;
    l2p_error err;
    cr_assert_eq(image_read_rgba(out, &w, &h, &px, &err), 0, "%s", err.text);
    cr_assert(w == 48 && h == 36);
    return px;
}

static double mean_abs_difference(const float *a, const float *b)
{
    double sum = 0;
    for (int i = 0; i < 48 * 36; i++)
        for (int c = 0; c < 3; c++)
            sum += fabs(a[4 * i + c] - b[4 * i + c]);
    return sum / (48 * 36 * 3);
}

static double mean(const float *a)
{
    double sum = 0;
    for (int i = 0; i < 48 * 36; i++)
        sum += a[4 * i] + a[4 * i + 1] + a[4 * i + 2];
    return sum / (48 * 36 * 3);
}

/* A render with `sampling` (render's) against a pixel render of the same film: within the noise
   between two pixel renders, and unbiased. */
static void expect_agrees_with_pixel_sampling(const char *sampling)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    float *p1 = render(dir, "pixel1", "pixel", "1"), *p2 = render(dir, "pixel2", "pixel", "2");
    float *f = render(dir, sampling, sampling, "3");
    double noise = mean_abs_difference(p1, p2), diff = mean_abs_difference(f, p1);
    cr_log_info("%s against pixel %.4f, pixel against pixel %.4f; means %.4f %.4f", sampling, diff,
                noise, mean(f), mean(p1));
    cr_expect(diff < 1.5 * noise + 2e-3, "%s %g, noise %g", sampling, diff, noise);
    cr_expect(fabs(mean(f) - mean(p1)) < 0.02 * mean(p1));
    free(p1), free(p2), free(f);
}

Test(field_render, agrees_with_pixel_sampling_within_the_noise)
{
    expect_agrees_with_pixel_sampling("field");
}

/* --adaptive (src/field/field_adaptive.c): a quarter of the samples over the whole picture,
   then the rest tile by tile where the error is, each pixel the mean of its tile's. */
Test(field_render, adaptive_agrees_with_pixel_sampling_within_the_noise)
{
    expect_agrees_with_pixel_sampling("adaptive");
}

/* What --adaptive cannot take: pixel sampling and trace (refused, exit 2, nothing written);
   POV-Ray's animation options, whose frames would each need tiles of their own (refused);
   fewer than 16 samples or a lens with dispersion (rendered uniformly, with a note). */
Test(field_render, adaptive_refuses_what_it_cannot_render)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *scene = tmp_path(dir, "scene.pov"), *out = tmp_path(dir, "x.exr");
    static const struct { const char *extra[3], *message; } bad[] = {
        {{"--sampling", "pixel", NULL}, "--adaptive is for --sampling field"},
        {{"--", "+KFF3", NULL}, "--adaptive renders a still, but POV-Ray's options after -- make "
                                "an animation of 3 frames"}};
    for (int i = 0; i < 2; i++) {
        char *errtext = NULL;
        const int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--width",
                           "16", "--height", "12", "--spp", "16", "--adaptive", "-o", out,
                           bad[i].extra[0], bad[i].extra[1]);
        cr_expect_eq(st, 2, "%s: status %d", bad[i].extra[0], st);
        cr_expect(errtext && strstr(errtext, bad[i].message), "%s", errtext ? errtext : "");
        cr_expect(!file_exists(out));
        free(errtext);
    }
    char *errtext = NULL;
    cr_expect_eq(L2P(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--adaptive", "-o",
                     tmp_path(dir, "t.inc")), 2);
    cr_expect(errtext && strstr(errtext, "trace does not take --adaptive"), "%s", errtext ? errtext : "");
    free(errtext);
    static const struct { const char *lens, *spp, *blades, *why; } uniform[] = {
        {LENS_DIR "dgauss.50mm.dat", "8", "0", "it needs --spp 16 or more"},
        {LENS_DIR "takumar.50mm.dat", "16", "0", "the lens has dispersion"},
        {LENS_DIR "dgauss.50mm.dat", "16", "6", "the stop has blades"}};
    for (int i = 0; i < 3; i++) {
        errtext = NULL;
        const int st = L2P(NULL, &errtext, "render", scene, uniform[i].lens, "--width", "16",
                           "--height", "12", "--spp", uniform[i].spp, "--aperture-blades",
                           uniform[i].blades, "--adaptive", "-o", out);
        cr_expect_eq(st, 0, "%s: status %d: %s", uniform[i].lens, st, errtext ? errtext : "");
        cr_expect(errtext && strstr(errtext, uniform[i].why), "%s", errtext ? errtext : "");
        cr_expect(file_exists(out));
        remove(out);
        free(errtext);
    }
}

Test(field_render, refuses_a_tolerance_it_cannot_keep)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *scene = tmp_path(dir, "scene.pov");
    static const char *const bad[] = {"0", "-1", "1e-9"};
    for (int i = 0; i < 3; i++) {
        char *errtext = NULL;
        int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--width", "16",
                     "--height", "12", "--spp", "1", "--sampling", "field", "--field-tolerance", bad[i],
                     "--quiet", "-o", tmp_path(dir, "x.png"));
        cr_expect_eq(st, 2, "--field-tolerance %s: status %d", bad[i], st);
        cr_expect(errtext && strstr(errtext, "--sampling pixel"), "--field-tolerance %s: %s", bad[i],
                  errtext ? errtext : "");
        free(errtext);
    }
    char *errtext = NULL;
    cr_expect_eq(L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--sampling",
                     "rays", "-o", tmp_path(dir, "x.png")), 2);
    free(errtext);
    /* a tolerance that would change nothing: pixel sampling, asked for or trace's default */
    errtext = NULL;
    cr_expect_eq(L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--sampling", "pixel",
                     "--field-tolerance", "0.1", "-o", tmp_path(dir, "x.png")), 2);
    cr_expect(errtext && strstr(errtext, "--sampling field"), "%s", errtext ? errtext : "");
    free(errtext);
    errtext = NULL;
    cr_expect_eq(L2P(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--field-tolerance", "0.1", "-o",
                     tmp_path(dir, "t")), 2);
    free(errtext);
    cr_expect(!file_exists(tmp_path(dir, "x.png")) && !file_exists(tmp_path(dir, "t.map")));
}

/* render's default sampling is field; a film too small for the fields (the fisheye at 16x12:
   its image circle's edge needs more faces than the sub-image has pixels) is rendered with
   pixel sampling, with a note, and gives pixel sampling's picture. Asked for by name, field
   sampling refuses it. */
Test(field_render, default_falls_back_to_pixel_sampling_on_a_tiny_film)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *scene = tmp_path(dir, "scene.pov");
#define TINY LENS_DIR "fisheye-dx.10.5mm.dat", "--width", "16", "--height", "12", "--spp", "4"
    char *errtext = NULL;
    cr_assert_eq(L2P(NULL, &errtext, "render", scene, TINY, "--sampling", "field", "-o",
                     tmp_path(dir, "field.exr")), 2);
    cr_expect(errtext && strstr(errtext, "faces for 192 pixels"), "%s", errtext ? errtext : "");
    free(errtext);
    errtext = NULL;
    cr_assert_eq(L2P(NULL, &errtext, "render", scene, TINY, "-o", tmp_path(dir, "default.exr")), 0,
                 "%s", errtext ? errtext : "");
    cr_expect(errtext && strstr(errtext, "note: rendering with --sampling pixel"), "%s",
              errtext ? errtext : "");
    free(errtext);
    run_lens2pov_ok("pixel", "render", scene, TINY, "--sampling", "pixel", "-q", "-o",
                    tmp_path(dir, "pixel.exr"), NULL);
#undef TINY
    int w, h, w2, h2;
    float *a, *b;
    l2p_error err;
    cr_assert_eq(image_read_rgba(tmp_path(dir, "default.exr"), &w, &h, &a, &err), 0, "%s", err.text);
    cr_assert_eq(image_read_rgba(tmp_path(dir, "pixel.exr"), &w2, &h2, &b, &err), 0, "%s", err.text);
    cr_assert(w == 16 && h == 12 && w2 == 16 && h2 == 12);
    cr_expect_arr_eq(a, b, sizeof(float) * 4 * 16 * 12, "the fallback is not pixel sampling");
    cr_expect(!file_exists(tmp_path(dir, "field.exr")));
    free(a), free(b);
}

/* A render none of whose pixels the lens passes (a crop beyond the fisheye's image circle)
   still gets a mesh POV-Ray accepts, which gives no pixel a ray: the picture is black. Before,
   its empty mesh stopped POV-Ray ("No vertices in triangle mesh"). */
Test(field_render, a_render_the_lens_blocks_everywhere_is_black)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char *errtext = NULL;
    int st = L2P(NULL, &errtext, "render", tmp_path(dir, "scene.pov"), LENS_DIR "fisheye.10mm.dat",
                 "--width", "96", "--height", "72", "--crop", "0,0,5,5", "--spp", "4", "--jobs", "2",
                 "--sampling", "field", "--quiet", "-o", tmp_path(dir, "corner.exr"));
    cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
    free(errtext);
    int w, h;
    float *px;
    l2p_error err;
    cr_assert_eq(image_read_rgba(tmp_path(dir, "corner.exr"), &w, &h, &px, &err), 0, "%s", err.text);
    cr_assert(w == 5 && h == 5);
    for (int i = 0; i < 5 * 5 * 4; i++)
        cr_expect(px[i] == 0.0f || (i % 4 == 3), "pixel %d channel %d: %g", i / 4, i % 4, px[i]);
    free(px);
}

/* The two renders' pictures, both w x h, are the same bit for bit. */
static void expect_same_pictures(char out[2][1024], int w, int h)
{
    int pw[2], ph[2];
    float *px[2];
    l2p_error err;
    for (int j = 0; j < 2; j++)
        cr_assert_eq(image_read_rgba(out[j], &pw[j], &ph[j], &px[j], &err), 0, "%s", err.text);
    cr_assert(pw[0] == w && ph[0] == h && pw[1] == w && ph[1] == h);
    cr_expect(memcmp(px[0], px[1], sizeof(float) * 4 * (size_t)w * h) == 0, "the two packings differ");
    free(px[0]), free(px[1]);
}

/* How sub-images are packed into renders (here: one render of 4 with one job, two of 2 with
   two) changes no pixel: every UV is a short binary fraction, so every pixel gets the same
   face weights, hence the same ray, in any render. A crop is the crop's size. */
Test(field_render, packing_changes_no_pixel)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char scene[1024], out[2][1024];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    for (int j = 0; j < 2; j++) {
        snprintf(out[j], sizeof out[j], "%s/jobs%d.exr", dir, j + 1);
        char *errtext = NULL;
        int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "fisheye.10mm.dat", "--width", "64",
                     "--height", "48", "--crop", "8,4,58,40", "--spp", "4", "--sampling", "field",
                     "--jobs", j ? "2" : "1", "--quiet", "-o", out[j]);
        cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
        free(errtext);
    }
    expect_same_pictures(out, 50, 36);
}

/* The same of --adaptive, whose second round packs pieces of the picture on shelves: with one
   job, one render a round; with two, more renders than jobs in the second round, so that a
   POV-Ray run renders several as its frames, each with the rows and columns of the run's
   first. The tiles' counts come from the first round's picture, which packing does not
   change, so neither does it change a pixel of the whole. */
Test(field_render, packing_changes_no_pixel_of_an_adaptive_render)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *scene = tmp_path(dir, "scene.pov");
    char out[2][1024], work[2][1024];
    for (int j = 0; j < 2; j++) {
        snprintf(out[j], sizeof out[j], "%s/jobs%d.exr", dir, j + 1);
        snprintf(work[j], sizeof work[j], "%s/work%d", dir, j + 1);
        char *errtext = NULL;
        int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "fisheye.10mm.dat",
                     "--width", "96", "--height", "72", "--spp", "32", "--adaptive", "--jobs",
                     j ? "2" : "1", "--keep-temp", work[j], "--quiet", "-o", out[j]);
        cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
        free(errtext);
    }
    char listing[4096];
    const int inis = count_entries(work[1], "field.f", listing, sizeof listing) / 3;   /* inc, ini, exr */
    cr_assert_geq(inis, 5, "two jobs: 2 renders in the first round and more than 2 in the second "
                  "wanted, found %d: %s", inis, listing);
    expect_same_pictures(out, 96, 72);
}

/* A still's POV-Ray options with --adaptive: every render of both rounds is a POV-Ray run of
   its own (a stand-in notes each run's arguments), each run is given the options, and the
   picture is, bit for bit, the one rendered without them when they change nothing in it (a
   Declare= the scene does not read): the runs are developed as the animation loop's frames
   are. */
Test(field_render, adaptive_passes_a_stills_povray_options_to_every_render)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char scene[1024], work[1024], script[1024], text[2048], out[2][1024];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(work, sizeof work, "%s/work", dir);
    snprintf(script, sizeof script, "%s/argspov", dir);
    snprintf(text, sizeof text, "#!/bin/sh\necho \"$*\" >> '%s/runs'\nexec povray \"$@\"\n", dir);
    write_text(script, text);
    chmod(script, 0755);
    for (int j = 0; j < 2; j++) {
        snprintf(out[j], sizeof out[j], "%s/options%d.exr", dir, j);
        char *errtext = NULL;
        if (j)
            setenv("LENS2POV_POVRAY", script, 1);
        int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--width", "96",
                     "--height", "72", "--spp", "32", "--adaptive", "--jobs", "2", "--quiet",
                     "--keep-temp", j ? work : tmp_path(dir, "plain"), "-o", out[j],
                     j ? "--" : NULL, "Declare=Lens2povUnread=1");
        unsetenv("LENS2POV_POVRAY");
        cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
        free(errtext);
    }
    char listing[8192];
    const int renders = count_entries(work, "field.f", listing, sizeof listing) / 3;   /* inc, ini, exr */
    const int second = count_entries(work, "povray.r2.", NULL, 0) / 2;   /* wrapper, log */
    cr_assert_geq(second, 2, "the second round's runs: %d (%s)", second, listing);
    char *runs = read_text(tmp_path(dir, "runs"), NULL);
    cr_assert_not_null(runs);
    int lines = 0, with = 0;   /* the renders' runs, not the probe of the scene's camera */
    for (char *line = strtok(runs, "\n"); line; line = strtok(NULL, "\n"))
        if (strstr(line, "/field.f")) {
            lines++;
            with += strstr(line, "Declare=Lens2povUnread=1") != NULL;
        }
    free(runs);
    cr_expect_eq(lines, renders, "a POV-Ray run a render: %d runs, %d renders", lines, renders);
    cr_expect_eq(with, lines, "%d of %d runs had the option", with, lines);
    expect_same_pictures(out, 96, 72);
}

/* The weights, a float a pixel and sub-image, never reach the disk unless the work folder is
   kept: while POV-Ray runs (a stand-in lists the work folder first), it holds no field map.
   The picture is the same, bit for bit, whether render keeps the weights in memory or makes
   them again where the pixels pass (LENS2POV_FIELD_WEIGHTS_MB=0, as beyond
   FIELD_WEIGHTS_KEPT_MB); kept, the folder's map holds every weight, and develop makes from
   it and the kept renders the same picture again. */
Test(field_render, the_weights_stay_off_the_disk_unless_the_work_folder_is_kept)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char scene[1024], tmp[1024], keep[1024], script[1024], text[2048], out[3][1024], again[1024];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(tmp, sizeof tmp, "%s/tmp", dir);
    snprintf(keep, sizeof keep, "%s/keep", dir);
    snprintf(script, sizeof script, "%s/listpov", dir);
    snprintf(again, sizeof again, "%s/again.exr", dir);
    cr_assert_eq(mkdir(tmp, 0755), 0);
    snprintf(text, sizeof text, "#!/bin/sh\nfind '%s' -name '*.map*' >> '%s/maps'\n"
             "echo run >> '%s/runs'\nexec povray \"$@\"\n", tmp, dir, dir);
    write_text(script, text);
    cr_assert_eq(chmod(script, 0755), 0);
    setenv("LENS2POV_POVRAY", script, 1);
    setenv("TMPDIR", tmp, 1);
    for (int kept = 0; kept < 3; kept++) {
        snprintf(out[kept], sizeof out[kept], "%s/%s.exr", dir,
                 kept == 2 ? "remade" : kept ? "kept" : "gone");
        if (kept == 2)
            setenv("LENS2POV_FIELD_WEIGHTS_MB", "0", 1);
        remove(tmp_path(dir, "maps"));
        remove(tmp_path(dir, "runs"));
        char *errtext = NULL;
        const int st = kept ? L2P(NULL, &errtext, "render", scene, LENS_DIR "fisheye.10mm.dat",
                                  "--width", "48", "--height", "36", "--spp", "16", "--sampling",
                                  "field", "--jobs", "1", "--quiet", "--keep-temp", keep, "-o",
                                  out[kept])
                            : L2P(NULL, &errtext, "render", scene, LENS_DIR "fisheye.10mm.dat",
                                  "--width", "48", "--height", "36", "--spp", "16", "--sampling",
                                  "field", "--jobs", "1", "--quiet", "-o", out[kept]);
        cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
        free(errtext);
        if (kept != 1) {
            char *maps = read_text(tmp_path(dir, "maps"), NULL);
            cr_assert(file_exists(tmp_path(dir, "runs")), "POV-Ray never ran (run %d)", kept);
            cr_expect(!maps || !*maps, "the work folder held a map: %s", maps);
            free(maps);
        }
    }
    unsetenv("LENS2POV_POVRAY");
    unsetenv("TMPDIR");
    unsetenv("LENS2POV_FIELD_WEIGHTS_MB");
    struct stat sb;
    char map[1100];
    snprintf(map, sizeof map, "%s/field.map", keep);
    cr_assert_eq(stat(map, &sb), 0, "no %s", map);
    cr_expect_geq(sb.st_size, 16 * 48 * 36 * 4, "%s: %lld bytes", map, (long long)sb.st_size);
    char prefix[1100];
    snprintf(prefix, sizeof prefix, "%s/field", keep);
    char *errtext = NULL;
    cr_assert_eq(L2P(NULL, &errtext, "develop", prefix, "-o", again), 0, "%s",
                 errtext ? errtext : "");
    free(errtext);
    float *px[4];
    int w, h;
    l2p_error err;
    const char *pictures[4] = {out[0], out[1], again, out[2]};
    for (int i = 0; i < 4; i++) {
        cr_assert_eq(image_read_rgba(pictures[i], &w, &h, &px[i], &err), 0, "%s", err.text);
        cr_assert(w == 48 && h == 36);
    }
    cr_expect(memcmp(px[0], px[1], sizeof(float) * 4 * 48 * 36) == 0,
              "kept or not, the pictures differ");
    cr_expect(memcmp(px[1], px[2], sizeof(float) * 4 * 48 * 36) == 0,
              "develop of the kept folder differs from render's picture");
    cr_expect(memcmp(px[0], px[3], sizeof(float) * 4 * 48 * 36) == 0,
              "weights made again or kept, the pictures differ");
    cr_expect_gt(mean(px[0]), 0.05, "the picture is black");
    for (int i = 0; i < 4; i++)
        free(px[i]);
}

/* LENS2POV_FIELD_WEIGHTS_MB that is not a number of MB, 0 or more, is refused, naming it. */
Test(field_render, a_bad_weights_bound_in_the_environment_is_refused)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *bad[] = {"", "abc", "-1", "12MB", "nan"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        setenv("LENS2POV_FIELD_WEIGHTS_MB", bad[i], 1);
        char *errtext = NULL;
        const int st = L2P(NULL, &errtext, "render", tmp_path(dir, "scene.pov"),
                           LENS_DIR "dgauss.50mm.dat", "--width", "48", "--height", "36", "--spp",
                           "4", "--sampling", "field", "--quiet", "-o", tmp_path(dir, "x.png"));
        unsetenv("LENS2POV_FIELD_WEIGHTS_MB");
        cr_expect_eq(st, 2, "'%s': exit %d", bad[i], st);
        cr_expect(errtext && strstr(errtext, "LENS2POV_FIELD_WEIGHTS_MB"), "'%s': %s", bad[i],
                  errtext ? errtext : "(nothing)");
        cr_expect(!file_exists(tmp_path(dir, "x.png")), "'%s': a picture was written", bad[i]);
        free(errtext);
    }
}

/* --memory-mb splits pixel sampling's ray tables; a field render is bounded already, and a
   user who asks for a bound there is told that it changes nothing. */
Test(field_render, memory_mb_is_said_to_change_nothing)
{
    const char *dir = test_tmpdir(), *scene = tmp_path(dir, "s.pov");
    write_text(scene, SCENE);
    char *errtext = NULL;
    cr_assert_eq(L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--width", "32",
                     "--height", "24", "--spp", "4", "--sampling", "field", "--memory-mb", "100",
                     "-q", "-o", tmp_path(dir, "a.png")), 0, "%s", errtext);
    cr_expect(strstr(errtext, "--memory-mb splits the ray tables of --sampling pixel"), "%s",
              errtext);
    free(errtext);
}
