/* POV-Ray's own options after "--" (issue 13): an animation gives one picture a frame, named
   as POV-Ray names its frames, each through that frame's camera, with the lens traced once;
   Declare= reaches the scene; image_width reads the film's width; options that would break
   the ray table are refused before any work. Pictures are 48x36 at 4 samples a pixel. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "image/image_io.h"
#include "povray/povargs.h"
#include "povray/scenecam.h"
#include "support.h"

#define DGAUSS LENS_DIR "dgauss.50mm.dat"
#define L2P(out, errtext, ...) run_lens2pov(out, errtext, __VA_ARGS__, (char *)NULL)
#define SIZE "--width", "48", "--height", "36", "--spp", "4"

/* Markers (emitting spheres, one colour each) and a camera that moves with the clock. */
#define ANIMATED_SCENE                                                                          \
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"                                    \
    "#macro Marker(P, C) sphere { P, 0.08 pigment { rgb C }\n"                                  \
    "    finish { ambient 0 emission 1 diffuse 0 } } #end\n"                                   \
    "Marker(<0, 0.5, 0>, <1, 0, 0>)\nMarker(<0.7, 0.5, 0.2>, <0, 1, 0>)\n"                     \
    "Marker(<-0.3, 1, 0.4>, <0, 0, 1>)\n"                                                      \
    "camera { location <clock - 0.5, 1, -4> look_at <clock - 0.5, 0.7, 0> angle 40\n"         \
    "  right x * image_width / image_height }\n"

/* A path kept in the caller's buffer (tmp_path's rotate). */
static const char *hold(char *buf, const char *dir, const char *name)
{
    snprintf(buf, 512, "%s/%s", dir, name);
    return buf;
}

/* Renders ANIMATED_SCENE's frames 1 to 3 with POV-Ray's own camera and through the lens with
   sampling; the lens is traced once (the map) and each frame's markers land where POV-Ray's
   do. */
static void frames_match_povray(const char *sampling, const char *map)
{
    const char *dir = test_tmpdir();
    char scene_buf[512], keep_buf[512];
    const char *scene = hold(scene_buf, dir, "scene.pov"), *keep = hold(keep_buf, dir, "keep");
    write_text(scene, ANIMATED_SCENE);
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "cd '%s' && povray +Iscene.pov +Oown.png +W48 +H36 +FN -A -D -V "
             "-GA +KFI1 +KFF3 >povray.log 2>&1", dir);
    cr_assert_eq(system_povray(cmd), 0, "%s", cmd);
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--angle", "scene",
                       "--sampling", sampling, "--jobs", "2", "-q", "--keep-temp", keep, "-o",
                       tmp_path(dir, "lens.png"), "--", "+KFI1", "+KFF3");
    cr_assert_eq(st, 0, "render failed: %s", errtext ? errtext : "");
    free(errtext);
    char listing[1024];
    cr_expect_eq(count_entries(dir, "lens", listing, sizeof listing), 3, "%s", listing);
    cr_expect_eq(count_entries(keep, map, NULL, 0), 1, "the lens was traced per frame");
    cr_expect_eq(count_entries(keep, "rays.t", NULL, 0) + count_entries(keep, "field.t", NULL, 0),
                 0, "a second table was traced");
    /* The one table's renders are every frame's: develop asks which, naming them. */
    char prefix[600];
    snprintf(prefix, sizeof prefix, "%s/%.*s", keep, (int)strlen(map) - 4, map);
    cr_expect_eq(L2P(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "again.png")), 2);
    cr_expect(errtext && strstr(errtext, "frames 1, 2, 3") && strstr(errtext, "lens2pov develop"),
              "%s", errtext ? errtext : "");
    free(errtext);
    for (int f = 1; f <= 3; f++) {
        char own[32], lens[32];
        snprintf(own, sizeof own, "own%d.png", f);
        snprintf(lens, sizeof lens, "lens%d.png", f);
        for (int c = 0; c < 3; c++) {
            const marker_centroid a = image_marker(tmp_path(dir, own), c),
                                  b = image_marker(tmp_path(dir, lens), c);
            cr_assert(a.found && b.found, "frame %d marker %d missing (POV-Ray %d, lens %d)", f,
                      c, a.found, b.found);
            cr_expect(fabs(a.x - b.x) < 1.0 && fabs(a.y - b.y) < 1.0,
                      "%s frame %d marker %d: POV-Ray (%.2f, %.2f), lens (%.2f, %.2f)", sampling,
                      f, c, a.x, a.y, b.x, b.y);
        }
    }
}

Test(animation, frames_named_as_povray_traced_once)
{
    frames_match_povray("pixel", "rays.map");
}

Test(animation, field_frames_named_as_povray_traced_once)
{
    frames_match_povray("field", "field.map");
}

/* The markers of POV-Ray's own pictures PREFIX_OWN<f>.png and the lens's PREFIX_LENS<f>.png
   (no frame number where f is 0) land on the same pixels. */
static void markers_match(const char *dir, const char *own_prefix, const char *lens_prefix, int f)
{
    char own[64], lens[64];
    snprintf(own, sizeof own, f ? "%s%d.png" : "%s.png", own_prefix, f);
    snprintf(lens, sizeof lens, f ? "%s%d.png" : "%s.png", lens_prefix, f);
    for (int c = 0; c < 3; c++) {
        const marker_centroid a = image_marker(tmp_path(dir, own), c),
                              b = image_marker(tmp_path(dir, lens), c);
        cr_assert(a.found && b.found, "%s marker %d missing (POV-Ray %d, lens %d)", lens, c,
                  a.found, b.found);
        cr_expect(fabs(a.x - b.x) < 1.0 && fabs(a.y - b.y) < 1.0,
                  "%s marker %d: POV-Ray (%.2f, %.2f), lens (%.2f, %.2f)", lens, c, a.x, a.y,
                  b.x, b.y);
    }
}

/* A povray.ini in the scene's folder that sets the clock, or makes an animation, with no
   options after "--": POV-Ray's own camera and the lens see the same frames, the red marker
   moving with the clock. Field sampling held the clock at 0 for the scene while taking the
   camera at the ini's clock, and made one picture of an animation. */
Test(animation, an_ini_that_sets_the_clock_or_frames_is_followed)
{
    const char *dir = test_tmpdir();
    char scene_buf[512];
    const char *scene = hold(scene_buf, dir, "scene.pov");
    write_text(scene, ANIMATED_SCENE "Marker(<2 * clock - 1, 0.9, 0>, <1, 0, 0>)\n");
    static const char *const inis[] = {"Clock=0.7\n", "Initial_Frame=1\nFinal_Frame=2\n"};
    for (int k = 0; k < 2; k++) {
        write_text(tmp_path(dir, "povray.ini"), inis[k]);
        char cmd[1024], own[24], lens[24];
        snprintf(own, sizeof own, "own%d_", k);
        snprintf(lens, sizeof lens, "lens%d_", k);
        snprintf(cmd, sizeof cmd, "cd '%s' && povray +Iscene.pov +O%s.png +W48 +H36 +FN -A -D "
                 "-V -GA >povray.log 2>&1", dir, own);
        cr_assert_eq(system_povray(cmd), 0, "%s", cmd);
        char out[600];
        snprintf(out, sizeof out, "%s/%s.png", dir, lens);
        char *errtext = NULL;
        const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--angle", "scene",
                           "--jobs", "2", "-q", "-o", out);
        cr_assert_eq(st, 0, "%s: %s", inis[k], errtext ? errtext : "");
        free(errtext);
        for (int f = k; f <= 2 * k; f++)
            markers_match(dir, own, lens, f);
    }
}

/* A dolly (the camera moving toward its look-at point) changes the focus, and each frame is
   traced again; with --focus-distance the focus is the same for every frame, and one table
   serves them all. */
Test(animation, a_fixed_focus_traces_a_dolly_once)
{
    const char *dir = test_tmpdir();
    char scene_buf[512], keep_buf[512];
    const char *scene = hold(scene_buf, dir, "dolly.pov");
    write_text(scene, "#version 3.7;\nsphere { 0, 0.5 pigment { rgb 1 } }\n"
                      "camera { location <0, 0, -4 + clock> look_at 0 angle 30 }\n");
    static const char *const focus[][2] = {{"--seed", "0"}, {"--focus-distance", "3"}};
    for (int k = 0; k < 2; k++) {
        char keep_name[16];
        snprintf(keep_name, sizeof keep_name, "keep%d", k);
        const char *keep = hold(keep_buf, dir, keep_name);
        char *errtext = NULL;
        const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--sampling", "pixel",
                           focus[k][0], focus[k][1], "-q", "--keep-temp", keep, "-o",
                           tmp_path(dir, "d.png"), "--", "+KFI1", "+KFF3");
        cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
        free(errtext);
        const int maps = (file_exists(tmp_path(keep, "rays.map")) ? 1 : 0) +
                         (file_exists(tmp_path(keep, "rays.t1.map")) ? 1 : 0) +
                         (file_exists(tmp_path(keep, "rays.t2.map")) ? 1 : 0);
        cr_expect_eq(maps, k ? 1 : 3, "%s: %d tables", focus[k][0], maps);
    }
}

/* A frame the lens cannot see is refused when its table is set up, after the frames before
   it: the message names the frame, and says where an angle came from. */
Test(animation, a_frame_the_lens_cannot_see_is_named)
{
    const char *dir = test_tmpdir();
    char scene_buf[512];
    const char *scene = hold(scene_buf, dir, "zoom.pov");
    write_text(scene, "#version 3.7;\nsphere { 0, 0.5 pigment { rgb 1 } }\n"
                      "camera { location <0, 0, -4> look_at 0 angle 20 + 60 * clock }\n");
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--sampling", "pixel",
                       "--angle", "scene", "-q", "-o", tmp_path(dir, "z.png"), "--", "+KFI1",
                       "+KFF2");
    cr_expect_eq(st, 2);
    cr_expect(errtext && strstr(errtext, "lens2pov: frame 2: ") &&
              strstr(errtext, "the scene camera's angle 80"), "%s", errtext ? errtext : "");
    free(errtext);
    cr_expect(file_exists(tmp_path(dir, "z1.png")), "frame 1 was not kept");
}

/* Without --keep-temp a field animation's renders go from the work folder once their frame is
   developed. Four samples of a 48x36 film make one render a frame at --jobs 1, so a POV-Ray run
   (a stand-in that counts the pictures under TMPDIR, then runs POV-Ray) sees at most the
   frame before's; kept, the fourth frame's would see three. */
Test(animation, a_field_animations_pictures_go_frame_by_frame)
{
    const char *dir = test_tmpdir();
    char scene_buf[512], tmp_buf[512], script_buf[512], text[1024];
    const char *scene = hold(scene_buf, dir, "scene.pov"), *tmp = hold(tmp_buf, dir, "tmp"),
               *script = hold(script_buf, dir, "countpov");
    write_text(scene, ANIMATED_SCENE);
    cr_assert_eq(mkdir(tmp, 0755), 0);
    snprintf(text, sizeof text, "#!/bin/sh\nfind '%s' -name '*.exr' | wc -l >> '%s/counts'\n"
             "exec povray \"$@\"\n", tmp, dir);
    write_text(script, text);
    cr_assert_eq(chmod(script, 0755), 0);
    setenv("LENS2POV_POVRAY", script, 1);
    setenv("TMPDIR", tmp, 1);
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--sampling", "field",
                       "--jobs", "1", "-q", "-o", tmp_path(dir, "f.png"), "--", "+KFI1", "+KFF4");
    unsetenv("LENS2POV_POVRAY");
    unsetenv("TMPDIR");
    cr_assert_eq(st, 0, "render failed: %s", errtext ? errtext : "");
    free(errtext);
    for (int f = 1; f <= 4; f++) {
        char name[32];
        snprintf(name, sizeof name, "f%d.png", f);
        cr_expect(file_exists(tmp_path(dir, name)), "no %s", name);
    }
    char *counts = read_text(tmp_path(dir, "counts"), NULL);
    cr_assert_not_null(counts, "POV-Ray never ran");
    int runs = 0, most = 0;
    for (char *p = counts, *end; *p; p = end, runs++) {
        const long n = strtol(p, &end, 10);
        cr_assert(end != p, "counts: %s", counts);
        most = n > most ? (int)n : most;
        while (*end == '\n' || *end == ' ')
            end++;
    }
    free(counts);
    cr_expect_geq(runs, 4, "%d POV-Ray runs for four frames", runs);
    cr_expect_leq(most, 1, "a POV-Ray run saw %d pictures in the work folder", most);
}

/* A table placed by a frame's transform gives the picture a table traced in place gives. In
   pixel sampling the animation's table is in three chunks (each rendered for every frame),
   the single frame's in one; in field sampling the two meshes are the same, moved by the
   placement or by the camera's own matrix. */
static void placed_matches_single(const char *sampling, const char *memory_mb)
{
    const char *dir = test_tmpdir();
    char scene_buf[512];
    const char *scene = hold(scene_buf, dir, "scene.pov");
    write_text(scene, ANIMATED_SCENE);
    cr_assert_eq(L2P(NULL, NULL, "render", scene, DGAUSS, SIZE, "--sampling", sampling, "--jobs",
                     "2", "--memory-mb", memory_mb, "-q", "-o", tmp_path(dir, "anim.png"), "--",
                     "+KFI0", "+KFF2"), 0);
    cr_assert_eq(L2P(NULL, NULL, "render", scene, DGAUSS, SIZE, "--sampling", sampling, "--jobs",
                     "1", "-q", "-o", tmp_path(dir, "single.png"), "--", "+K1"), 0);
    cr_assert(file_exists(tmp_path(dir, "anim2.png")) && file_exists(tmp_path(dir, "single.png")));
    int w, h, w2, h2;
    float *a, *b;
    l2p_error err;
    cr_assert_eq(image_read_rgba(tmp_path(dir, "anim2.png"), &w, &h, &a, &err), 0, "%s", err.text);
    cr_assert_eq(image_read_rgba(tmp_path(dir, "single.png"), &w2, &h2, &b, &err), 0, "%s", err.text);
    cr_assert(w == w2 && h == h2);
    double worst = 0;
    for (size_t i = 0; i < (size_t)w * (size_t)h * 4; i++)
        worst = fmax(worst, fabs(a[i] - b[i]));
    cr_expect(worst <= 1.0 / 255.0, "%s: the placed table differs by %g", sampling, worst);
    free(a);
    free(b);
}

Test(animation, placed_table_matches_a_single_frame)
{
    placed_matches_single("pixel", "0.5");
}

Test(animation, placed_field_matches_a_single_frame)
{
    placed_matches_single("field", "1000");
}

/* Declare= reaches the scene, and image_width and image_height read the film's size. */
static void declare_reaches(const char *sampling)
{
    const char *dir = test_tmpdir();
    char scene_buf[512], keep_buf[512];
    const char *scene = hold(scene_buf, dir, "scene.pov"), *keep = hold(keep_buf, dir, "keep");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                      "#debug concat(\"seen: \", str(Shade, 0, 2), \" \", str(image_width, 0, 0),"
                      " \" \", str(image_height, 0, 0), \"\\n\")\n"
                      "background { rgb Shade }\n");
    cr_assert_eq(L2P(NULL, NULL, "render", scene, DGAUSS, SIZE, "--sampling", sampling,
                     "--jobs", "1", "-q",
                     "--location", "0,0,0", "--look-at", "0,0,1", "--keep-temp", keep, "-o",
                     tmp_path(dir, "out.exr"), "--", "Declare=Shade=0.25"), 0);
    size_t n;
    char *log = read_text(tmp_path(keep, "povray.c000.log"), &n);
    cr_assert_not_null(log);
    cr_expect(strstr(log, "seen: 0.25 48 36"), "%s", log);
    free(log);
    int w, h;
    float *p;
    l2p_error err;
    cr_assert_eq(image_read_rgba(tmp_path(dir, "out.exr"), &w, &h, &p, &err), 0, "%s", err.text);
    const float *centre = p + 4 * ((size_t)(h / 2) * (size_t)w + (size_t)(w / 2));
    cr_expect(fabs(centre[0] - 0.25) < 0.02, "centre %g", centre[0]);
    free(p);
}

Test(animation, declare_and_image_size_reach_the_scene)
{
    declare_reaches("pixel");
}

Test(animation, declare_and_image_size_reach_a_field_render)
{
    declare_reaches("field");
}

/* Refused before any work, naming "--" and the option; nothing written. */
Test(animation, table_breaking_options_are_refused)
{
    const char *dir = test_tmpdir();
    char scene_buf[512];
    const char *scene = hold(scene_buf, dir, "scene.pov");
    write_text(scene, ANIMATED_SCENE);
    const char *bad[] = {"+W100", "-h50", "+A0.3", "Antialias=On", "+FN", "+Oother.png",
                         "Output_File_Type=N", "+SR0.5", "End_Column=10", "width=5"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char *errtext = NULL;
        const clock_t t0 = clock();
        const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "-q", "-o",
                           tmp_path(dir, "out.png"), "--", "+KFI1", "+KFF3", bad[i]);
        cr_expect_eq(st, 2, "%s: exit %d", bad[i], st);
        cr_expect(errtext && strstr(errtext, "--") && strstr(errtext, bad[i]), "%s: %s", bad[i],
                  errtext ? errtext : "");
        cr_expect((double)(clock() - t0) / CLOCKS_PER_SEC < 1.0);
        free(errtext);
    }
    cr_expect_eq(count_entries(dir, "out", NULL, 0), 0, "an output was written");
}

/* A value POV-Ray cannot read: POV-Ray's own message, exit 2, nothing written. */
Test(animation, bad_value_gives_povrays_message)
{
    const char *dir = test_tmpdir();
    char scene_buf[512];
    const char *scene = hold(scene_buf, dir, "scene.pov");
    write_text(scene, ANIMATED_SCENE);
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "-q", "-o",
                       tmp_path(dir, "out.png"), "--", "+KFIx");
    cr_expect_eq(st, 2);
    cr_expect(errtext && strstr(errtext, "+KFIx") && strstr(errtext, "Problem with option"),
              "%s", errtext ? errtext : "");
    free(errtext);
    cr_expect_eq(count_entries(dir, "out", NULL, 0), 0, "an output was written");
}

/* POV-Ray's naming rule: the frame number padded to the final frame's digits, before the
   extension. */
Test(animation, frame_names)
{
    char *a = povargs_frame_name("dir.x/out.png", 3, povargs_frame_digits(10));
    char *b = povargs_frame_name("out", 7, povargs_frame_digits(9));
    char *c = povargs_frame_name("a.b/c.exr", 12, povargs_frame_digits(100));
    cr_expect_str_eq(a, "dir.x/out03.png");
    cr_expect_str_eq(b, "out7");
    cr_expect_str_eq(c, "a.b/c012.exr");
    free(a);
    free(b);
    free(c);
}

/* Frames from POV-Ray's output: one camera each, between "lens2pov-frame" messages. */
Test(animation, frames_from_log)
{
    const char *log = "lens2pov-frame 1 3 0.00000000000000000|\n"
                      "lens2pov-camera 0 5|\nlens2pov-version 3.700|\n"
                      "lens2pov-location 0 1 -4|\nlens2pov-end|\n"
                      "lens2pov-frame 2 3 0.5|\n"
                      "lens2pov-camera 0 5|\nlens2pov-version 3.700|\n"
                      "lens2pov-location 2 1 -4|\nlens2pov-end|\n";
    scene_frames f;
    l2p_error err;
    const char *scene = "s.pov";
    const scene_files files = {&scene, 1};
    cr_assert_eq(scene_frames_from_log(log, strlen(log), &files, &f, &err), 0, "%s", err.text);
    cr_assert_eq(f.count, 2);
    cr_expect(f.animated && f.final_frame == 3);
    cr_expect(f.frame[0].number == 1 && f.frame[1].number == 2 && f.frame[1].clock == 0.5);
    cr_expect(f.frame[0].cam.location.x == 0 && f.frame[1].cam.location.x == 2);
    scene_frames_free(&f);
}

/* A focus that follows look_at from frame to frame needs a field (render's default sampling)
   a frame. The kept folder holds each field's POV-Ray logs, and develop makes each frame again
   from its field's renders, which POV-Ray numbered by frame, byte for byte. */
Test(animation, changing_focus_traces_again)
{
    const char *dir = test_tmpdir();
    char scene_buf[512], keep_buf[512];
    const char *scene = hold(scene_buf, dir, "scene.pov"), *keep = hold(keep_buf, dir, "keep");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                      "camera { location <0, 1, -4> look_at <0, 1, clock * 3> }\n"
                      "sphere { <0, 1, 0>, 0.5 pigment { rgb 1 } finish { emission 1 } }\n");
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--jobs", "1", "-q",
                       "--keep-temp", keep, "-o", tmp_path(dir, "f.png"), "--", "+KFI1",
                       "+KFF2");
    cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
    free(errtext);
    cr_expect_eq(count_entries(keep, "field.map", NULL, 0), 1);
    cr_expect_eq(count_entries(keep, "field.t1.map", NULL, 0), 1);
    cr_expect(file_exists(tmp_path(dir, "f1.png")) && file_exists(tmp_path(dir, "f2.png")));
    char listing[1024];
    cr_expect_eq(count_entries(keep, "povray.t1.", listing, sizeof listing), 2, "%s", listing);
    cr_expect_eq(count_entries(keep, "povray.c", listing, sizeof listing), 2, "%s", listing);
    const char *table[2] = {"field", "field.t1"};
    for (int f = 0; f < 2; f++) {
        char prefix[600], again[600], frame[32];
        snprintf(prefix, sizeof prefix, "%s/%s", keep, table[f]);
        snprintf(again, sizeof again, "%s/again%d.png", dir, f + 1);
        snprintf(frame, sizeof frame, "f%d.png", f + 1);
        cr_assert_eq(L2P(NULL, &errtext, "develop", prefix, "-o", again), 0, "%s", errtext);
        free(errtext);
        size_t na = 0, nb = 0;
        char *a = read_text(again, &na), *b = read_text(tmp_path(dir, frame), &nb);
        cr_expect(a && b && na == nb && !memcmp(a, b, na), "frame %d developed again differs", f + 1);
        free(a), free(b);
    }
}

/* Renders a scene of dir from its folder sub, given "--" ini (an .ini of sub, whose text is
   ini_text) and +L. : both relative to the current folder, while POV-Ray runs in the scene's.
   Returns the folder. */
static const char *render_from_sub(const char *ini_text, const char *ini)
{
    const char *dir = test_tmpdir();
    char scene_buf[512], sub[512], cwd[512], exe[1024];
    const char *scene = hold(scene_buf, dir, "scene.pov");
    hold(sub, dir, "sub");
    cr_assert_eq(mkdir(sub, 0777), 0);
    write_text(tmp_path(sub, "a.ini"), ini_text);
    write_text(tmp_path(sub, "lib.inc"), "#declare Shade = 0.5;\n");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n#include \"lib.inc\"\n"
                      "camera { location <clock, 1, -4> look_at <clock, 1, 0> }\n"
                      "background { rgb Shade }\n");
    /* Each test runs in a process of its own: the folder can change. */
    cr_assert_not_null(getcwd(cwd, sizeof cwd));
    const char *given = getenv("LENS2POV");
    snprintf(exe, sizeof exe, "%s", given && *given ? given : "build/lens2pov");
    if (exe[0] != '/')
        snprintf(exe, sizeof exe, "%s/%s", cwd, given && *given ? given : "build/lens2pov");
    setenv("LENS2POV", exe, 1);
    cr_assert_eq(chdir(sub), 0);
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--jobs", "1", "-q",
                       "-o", tmp_path(dir, "r.png"), "--", ini, "+L.");
    cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
    free(errtext);
    return dir;
}

/* An .ini with the animation in it, and +L. */
Test(animation, ini_and_library_path_relative_to_here)
{
    const char *dir = render_from_sub("Initial_Frame=1\nFinal_Frame=2\n", "a.ini");
    cr_expect(file_exists(tmp_path(dir, "r1.png")) && file_exists(tmp_path(dir, "r2.png")));
}

/* A section of an .ini (POV-Ray's FILE.ini[Section]): the section named, not the others. */
Test(animation, an_ini_section_relative_to_here)
{
    const char *dir = render_from_sub("[Still]\nDeclare=Unused=1\n[Two]\nInitial_Frame=1\n"
                                      "Final_Frame=2\n", "a.ini[Two]");
    cr_expect(file_exists(tmp_path(dir, "r1.png")) && file_exists(tmp_path(dir, "r2.png")));
    cr_expect(!file_exists(tmp_path(dir, "r.png")));
}
