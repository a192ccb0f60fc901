/* The scene's own camera (issue 13): with no --location, --look-at or --sky, render and
   trace --scene place the lens where the scene's last camera statement puts POV-Ray's camera,
   as POV-Ray evaluates it; --angle scene takes its horizontal angle. Markers (small emitting
   spheres, one colour each) must land where POV-Ray's own camera puts them. Pictures are
   64x48 at 4 samples a pixel. */
#include <criterion/criterion.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <signal.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "image/image_io.h"
#include "povray/scenecam.h"
#include "scene_markers.h"
#include "support.h"

Test(scene_camera, declared_vectors_expression_and_angle)
{
    expect_markers_as_povray(MARKERS_HEAD CAMERA("x"));
}

Test(scene_camera, mirrored_right_mirrors_the_picture)
{
    expect_markers_as_povray(MARKERS_HEAD CAMERA("-x"));
}

/* Transforms after look_at, an earlier camera that the last one replaces, and a camera in an
   #if branch that does not run. */
Test(scene_camera, transforms_and_the_last_camera)
{
    expect_markers_as_povray(MARKERS_HEAD
                             "camera { location <5, 5, 5> look_at 0 angle 80 }\n"
                             "#if (clock > 1) camera { location <9, 9, 9> look_at 0 } #end\n"
                             "camera { location Lift(Eye) - Target look_at 0 angle 40\n"
                             "  rotate <0, 5, 0> translate Target }\n");
}




/* Conditionals, #debug and #warning inside the camera block are followed as POV-Ray follows
   them (focal blur switched by a quality setting is a common use). */
Test(scene_camera, conditionals_inside_the_camera_block)
{
    expect_markers_as_povray(MARKERS_HEAD
                             "#declare Quality = 2;\n"
                             "camera {\n  #if (image_width < 10) orthographic #end\n"
                             "  location <5, 5, 5>\n"
                             "#if (image_width > 10) location Lift(Eye) #else location 9 #end\n"
                             "  look_at Target\n#ifdef (Undeclared) angle 80 #end\n"
                             "#switch (Quality)\n#case (1) angle 80 #break\n"
                             "#range (2, 3) angle 40 aperture 0.1 #debug \"fine\\n\" #break\n"
                             "#end #warning \"kept\"\n"
                             "  right x * image_width / image_height\n}\n");
}

/* A '#' alone before the block's '}' (Debian's scenes/language/image_size.pov has one):
   POV-Ray passes over it, and so does the scene camera's reader. */
Test(scene_camera, a_lone_hash_before_the_blocks_end_is_passed_over)
{
    expect_markers_as_povray(MARKERS_HEAD
                             "camera {\n  location Lift(Eye)\n  look_at Target\n  angle 40\n"
                             "  right x * image_width / image_height #\n}\n");
}


/* The probe's POV-Ray run, failing with "Timed out waiting for worker thread startup" (a
   loaded machine), is started again as a render's runs are: a stand-in that fails so on its
   first start only gives the scene's camera on the second, with a warning. */
Test(scene_camera, a_probe_that_times_out_starting_is_run_again)
{
    const char *dir = test_tmpdir();
    char scene[512], script[512], starts[512], prefix[512];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(script, sizeof script, "%s/slowpov", dir);
    snprintf(starts, sizeof starts, "%s/starts", dir);
    snprintf(prefix, sizeof prefix, "%s/t", dir);
    write_text(scene, MARKERS_HEAD CAMERA("x"));
    char text[2048];
    snprintf(text, sizeof text, "#!/bin/sh\necho x >> '%s'\nif [ $(wc -l < '%s') -lt 2 ]; then\n"
             "  echo 'Timed out waiting for worker thread startup' >&2; exit 1\nfi\n"
             "exec povray \"$@\"\n", starts, starts);
    write_text(script, text);
    chmod(script, 0755);
    setenv("LENS2POV_POVRAY", script, 1);
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "trace", DGAUSS, "--scene", scene, SIZE, "--spp", "1",
                       "-o", prefix);
    unsetenv("LENS2POV_POVRAY");
    cr_expect_eq(st, 0, "exit %d: %s", st, errtext);
    cr_expect(errtext && strstr(errtext, "timed out starting its threads"), "%s", errtext);
    char *count = read_text(starts, NULL);
    cr_expect(count && !strcmp(count, "x\nx\n"), "starts: %s", count ? count : "none");
    free(count);
    free(errtext);
}


/* A camera normal { } perturbs POV-Ray's rays, which no lens does: it is left out with a
   warning naming the scene, whether the camera is read by POV-Ray (an expression) or as plain
   numbers; a normal in a branch POV-Ray does not take, or none, gives no warning. */
Test(scene_camera, a_camera_normal_is_left_out_with_a_warning)
{
    const char *dir = test_tmpdir();
    static const char *const cameras[] = {
        "camera { location <0, 1, -5> look_at <0, 1, 0> normal { bumps 0.5 scale 0.1 } }\n",
        "camera { location <0, 1, -5> + 0 look_at <0, 1, 0> normal { bumps 0.5 scale 0.1 } }\n",
        "camera { location <0, 1, -5> + 0 look_at <0, 1, 0>\n"
        "#if (image_width < 2) normal { bumps 0.5 } #end }\n",
        "camera { location <0, 1, -5> look_at <0, 1, 0> }\n"};
    for (int k = 0; k < 4; k++) {
        char scene[512], prefix[512], text[512];
        snprintf(scene, sizeof scene, "%s/scene%d.pov", dir, k);
        snprintf(prefix, sizeof prefix, "%s/t%d", dir, k);
        snprintf(text, sizeof text, "#version 3.7;\n%s", cameras[k]);
        write_text(scene, text);
        char *errtext = NULL;
        const int st = L2P(NULL, &errtext, "trace", DGAUSS, "--scene", scene, SIZE, "--spp",
                           "1", "-q", "-o", prefix);
        cr_expect_eq(st, 0, "camera %d: exit %d: %s", k, st, errtext);
        char warning[700];
        snprintf(warning, sizeof warning, "lens2pov: warning: %s: the camera's normal { } is left "
                 "out", scene);
        cr_expect_eq(errtext && strstr(errtext, warning) != NULL, k < 2, "camera %d: %s", k,
                     errtext ? errtext : "");
        free(errtext);
    }
}



/* A camera in a file the scene includes from its folder, nested two deep (the inner one
   named without its ".inc", which POV-Ray appends), after a camera of the scene's own: it is
   the last to run, so it is the camera, its expressions evaluated where its file stands. A
   standard include is not copied; comments that look like a camera or an #include do not
   count. */
Test(scene_camera, a_camera_in_an_included_file_is_the_camera)
{
    const char *dir = test_tmpdir();
    char outer[512], inner[512];
    snprintf(outer, sizeof outer, "%s/outer.inc", dir);
    snprintf(inner, sizeof inner, "%s/inner.inc", dir);
    write_text(inner, "// camera { location 0 }\n\n" CAMERA("x"));
    write_text(outer, "/* #include \"nothing.inc\" */\n#include \"inner\"\n");
    expect_markers_in(dir, MARKERS_HEAD "camera { location <5, 5, 5> look_at 0 angle 80 }\n"
                           "#include \"colors.inc\"\n#include \"outer.inc\"\n", NULL);
}

/* Included files are found on POV-Ray's library path as POV-Ray finds them: a folder of the
   user's given as +L after "--", and the standard includes, where screen.inc sets the camera
   in a macro (without look_at: the lens focuses at the direction's length, within a pixel of
   blur here). */
Test(scene_camera, cameras_on_the_library_path)
{
    const char *dir = test_tmpdir();
    char library[512], inc[600];
    snprintf(library, sizeof library, "%s/lib", dir);
    snprintf(inc, sizeof inc, "%s/cam.inc", library);
    cr_assert_eq(mkdir(library, 0777), 0);
    write_text(inc, CAMERA("x"));
    expect_markers_in(dir, MARKERS_HEAD "#include \"cam.inc\"\n", library);
    expect_markers_as_povray(MARKERS_HEAD "#include \"screen.inc\"\n"
                             "Set_Camera(Lift(Eye), Target, 40)\n");
}


/* Explicit placement wins: trace --scene with --location and --look-at writes what trace
   without the scene writes. */
Test(scene_camera, explicit_placement_overrides_the_scene)
{
    const char *dir = test_tmpdir();
    char scene[512], a[512], b[512], ainc[520], binc[520];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(a, sizeof a, "%s/a", dir);
    snprintf(b, sizeof b, "%s/b", dir);
    snprintf(ainc, sizeof ainc, "%s.inc", a);
    snprintf(binc, sizeof binc, "%s.inc", b);
    write_text(scene, MARKERS_HEAD CAMERA("x"));
    cr_assert_eq(L2P(NULL, NULL, "trace", DGAUSS, SIZE, "--spp", "1", "--scene", scene,
                     "--location", "0,1,-3", "--look-at", "0,0.5,0", "-q", "-o", a), 0);
    cr_assert_eq(L2P(NULL, NULL, "trace", DGAUSS, SIZE, "--spp", "1", "--location", "0,1,-3",
                     "--look-at", "0,0.5,0", "-q", "-o", b), 0);
    size_t na, nb;
    char *ta = read_text(ainc, &na), *tb = read_text(binc, &nb);
    cr_assert(ta && tb);
    cr_expect(na == nb && !memcmp(ta, tb, na), "the scene's camera changed an explicit placement");
    free(ta);
    free(tb);
}

/* --angle DEG: the traced horizontal field of view is DEG; an angle out of reach is refused. */
Test(scene_camera, angle_sets_the_traced_field_of_view)
{
    char *out = NULL;
    cr_assert_eq(L2P(&out, NULL, "info", DGAUSS, "--angle", "40", "--focus-distance", "inf", "--json"), 0);
    const char *p = out ? strstr(out, "\"hfov_deg\":") : NULL;
    cr_assert_not_null(p, "%s", out ? out : "");
    cr_expect(fabs(strtod(p + 11, NULL) - 40.0) < 1e-6, "%s", p);
    free(out);
    char *errtext = NULL;
    cr_expect_eq(L2P(NULL, &errtext, "info", LENS_DIR "telephoto.250mm.dat", "--angle", "60", "--focus-distance", "inf"), 2);
    cr_expect(errtext && strstr(errtext, "--angle"), "%s", errtext ? errtext : "");
    free(errtext);
}

/* The copy keeps every line where it was, so POV-Ray's messages name the scene's lines. */
Test(scene_camera, rewrite_keeps_lines)
{
    const char *text = "#declare A = camera { location 1 }\n"
                       "camera {\n location <0, 1, -3> // a } comment\n"
                       " look_at /* nested /* } */ */ 0\n}\nsphere { 0, 1 }\n\"camera {\"\n";
    char *copy = scene_camera_rewrite(text, strlen(text));
    cr_assert_not_null(copy);
    int a = 0, b = 0;
    for (const char *p = text; *p; p++)
        a += *p == '\n';
    for (const char *p = copy; *p; p++)
        b += *p == '\n';
    cr_expect_eq(a, b, "%s", copy);
    cr_expect(strstr(copy, "#declare A = camera { location 1 }"), "%s", copy);
    cr_expect(strstr(copy, "sphere { 0, 1 }\n\"camera {\""), "%s", copy);
    cr_expect(strstr(copy, "lens2pov-look_at"), "%s", copy);
    free(copy);
}

/* POV-Ray wraps its console at 80 columns; the messages are joined again. */
Test(scene_camera, wrapped_messages)
{
    const char *log = "noise\n\nlens2pov-camera 0 7|\n\nlens2pov-version 3.700|\n"
                      "\nlens2pov-location 1.00000000000000000 2.000000000000000\n"
                      "00 -3.00000000000000000|\n\nlens2pov-look_at 1.0 2.0 0.0|\n"
                      "\nlens2pov-end|\n";
    scene_camera sc;
    l2p_error err;
    const char *scene = "s.pov";
    const scene_files files = {&scene, 1};
    cr_assert_eq(scene_camera_from_log(log, strlen(log), &files, &sc, &err), 0, "%s", err.text);
    cr_expect(sc.found && sc.line == 7);
    cr_expect(fabs(sc.location.y - 2.0) < 1e-15 && fabs(sc.location.z + 3.0) < 1e-15);
    cr_expect(fabs(sc.forward.z - 1.0) < 1e-15 && fabs(sc.focus_distance - 3.0) < 1e-12);
    cr_expect(fabs(sc.hfov_deg - 2.0 * atan(0.665) * 180.0 / M_PI) < 1e-9);
}

/* A focal point puts focal blur's plane at its distance from the location, measured before
   the transforms, as POV-Ray's Parse_Camera does; it wins over look_at. */
Test(scene_camera, the_focal_point_is_in_focus)
{
    const char *scene = "s.pov";
    const scene_files files = {&scene, 1};
    static const struct {
        const char *items;
        double focus;
    } cases[] = {
        /* new syntax: after look_at, before the transforms (the scale leaves it as it is) */
        {"lens2pov-version 3.700|\n\nlens2pov-location 0 2 -3|\n\nlens2pov-focal_point 1 2 1|\n"
         "\nlens2pov-look_at 0 2 0|\n\nlens2pov-t0 0 0 0|\n\nlens2pov-t1 2 0 0|\n"
         "\nlens2pov-t2 0 2 0|\n\nlens2pov-t3 0 0 2|\n", 4.123105625617661},
        /* old syntax: at the item, from the location then in effect */
        {"lens2pov-version 3.100|\n\nlens2pov-location 0 0 -5|\n\nlens2pov-focal_point 0 0 0|\n"
         "\nlens2pov-location 0 0 -6|\n", 5.0},
        /* a focal point at the location: POV-Ray's 1 */
        {"lens2pov-version 3.700|\n\nlens2pov-location 0 0 -5|\n\nlens2pov-focal_point 0 0 -5|\n"
         "\nlens2pov-look_at 0 0 0|\n", 1.0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        char log[1024];
        snprintf(log, sizeof log, "\nlens2pov-camera 0 3|\n\n%s\nlens2pov-end|\n", cases[k].items);
        scene_camera sc;
        l2p_error err;
        cr_assert_eq(scene_camera_from_log(log, strlen(log), &files, &sc, &err), 0, "%zu: %s", k, err.text);
        cr_expect(fabs(sc.focus_distance - cases[k].focus) < 1e-12, "case %zu: focus %.17g, not %.17g",
                  k, sc.focus_distance, cases[k].focus);
    }
}

/* The focal point as POV-Ray evaluates it in a scene: an expression of declared vectors. */
Test(scene_camera, the_scenes_focal_point_is_evaluated)
{
    const char *dir = test_tmpdir();
    char scene[512];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    write_text(scene, MARKERS_HEAD "camera { location Lift(Eye) look_at Target angle 40\n"
                                   "  aperture 0.2 blur_samples 4 focal_point Target + <1, 0, 2> }\n");
    scene_camera sc;
    l2p_error err;
    cr_assert_eq(scene_camera_read(scene, 64, 48, &sc, &err), L2P_OK, "%s", err.text);
    /* Lift(Eye) = <1, 2.5, -4>, the focal point <1.2, 0.5, 2> */
    const double expected = sqrt(0.2 * 0.2 + 2.0 * 2.0 + 6.0 * 6.0);
    cr_expect(fabs(sc.focus_distance - expected) < 1e-12, "focus %.17g, not %.17g", sc.focus_distance,
              expected);
}

/* The probe is not waited for once the scene is parsed (what POV-Ray still does, a pixel and
   its winding down, takes about 0.4 s): a stand-in that notes its pid, runs POV-Ray and then
   writes "ended" is gone, without having written it, when scene_camera_read returns the
   scene's camera. With POV-Ray options of the user's (an animation's frames), or a povray.ini
   that makes POV-Ray animate, it is waited for. A scene that fails to parse still fails with
   POV-Ray's message. */
Test(scene_camera, the_probe_ends_with_the_parse)
{
    const char *dir = test_tmpdir();
    char scene[512], fake[512], pid_path[512], ended[512], text[2200];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(fake, sizeof fake, "%s/probepov", dir);
    snprintf(pid_path, sizeof pid_path, "%s/pid", dir);
    snprintf(ended, sizeof ended, "%s/ended", dir);
    snprintf(text, sizeof text, "#!/bin/sh\necho $$ > '%s'\npovray \"$@\"; st=$?\n"
             "echo end >> '%s'\nexit $st\n", pid_path, ended);
    write_text(fake, text);
    chmod(fake, 0755);
    /* declared vectors: POV-Ray has to evaluate them */
    write_text(scene, MARKERS_HEAD "camera { location Eye look_at Eye + z }\n");
    setenv("LENS2POV_POVRAY", fake, 1);
    scene_camera sc;
    l2p_error err = {0};
    cr_assert_eq(scene_camera_read(scene, 64, 48, &sc, &err), L2P_OK, "%s", err.text);
    cr_expect(sc.found && fabs(sc.location.x - 1) < 1e-12 && fabs(sc.location.y - 1.5) < 1e-12 &&
                  fabs(sc.location.z + 4) < 1e-12 && fabs(sc.forward.z - 1) < 1e-12,
              "camera at <%g, %g, %g> looking <%g, %g, %g>", sc.location.x, sc.location.y,
              sc.location.z, sc.forward.x, sc.forward.y, sc.forward.z);
    FILE *f = fopen(pid_path, "r");
    cr_assert_not_null(f, "the stand-in never ran");
    int pid = 0;
    cr_expect_eq(fscanf(f, "%d", &pid), 1);
    fclose(f);
    cr_expect(pid > 0 && kill(pid, 0) != 0 && errno == ESRCH, "stand-in %d still there", pid);
    cr_expect_neq(access(ended, F_OK), 0, "the probe was waited for after the parse");

    /* with options of the user's, the probe runs to its end */
    scene_frames frames;
    char *const args[] = {"+KFF2"};
    cr_assert_eq(scene_frames_read(scene, 64, 48, args, 1, &frames, &err), L2P_OK, "%s", err.text);
    cr_expect_eq(frames.count, 2);
    scene_frames_free(&frames);
    cr_expect_eq(access(ended, F_OK), 0, "the probe with the user's options was not waited for");

    /* an ini that makes POV-Ray animate: every frame is read, the probe runs to its end */
    char ini[600];
    snprintf(ini, sizeof ini, "%s/povray.ini", dir);
    write_text(ini, "Initial_Frame=1\nFinal_Frame=3\n");
    unlink(ended);
    cr_assert_eq(scene_frames_read(scene, 64, 48, NULL, 0, &frames, &err), L2P_OK, "%s", err.text);
    cr_expect_eq(frames.count, 3);
    scene_frames_free(&frames);
    cr_expect_eq(access(ended, F_OK), 0, "an animation's probe was not waited for");
    unlink(ini);

    /* a parse error is POV-Ray's, with the scene's line */
    write_text(scene, MARKERS_HEAD "camera { location Eye look_at Eye + z }\nsphere {\n");
    cr_expect_neq(scene_camera_read(scene, 64, 48, &sc, &err), L2P_OK);
    cr_expect(strstr(err.text, scene) != NULL, "%s", err.text);
    unsetenv("LENS2POV_POVRAY");
}

/* Cameras written as literals, each read without POV-Ray (a POV-Ray that cannot run stands in)
   and, the same scene beside an empty povray.ini (which could have set the version), by the
   probe: the same camera to the last bit. An #include of the scene's does not matter. */
Test(scene_camera, a_literal_camera_is_read_as_povray_reads_it)
{
    static const char *const cameras[] = {
        "#version 3.7;\ncamera { location <1, 1.5, -4> look_at <0.2, 0.5, 0> angle 40 }\n",
        "#version 3.7;\n#include \"defs.inc\"\ncamera {\n  perspective // a comment\n"
        "  location <0.000001234567, 2, -5> direction <0, 0, 1.5> right <-1.6, 0, 0>\n"
        "  up y sky <0.1, 1, 0> /* and another */ look_at <1.234567890123456e-10, 2, 0> }\n",
        "#version 3.5;\n#macro M() sphere { 0, 1 } #end\ncamera { location 3 }\n"
        "camera { location < -0 , 1 , - 3.25e0 > look_at <-0, 0, -0> angle 65.5 focal_point 0 }\n",
    };
    const char *dir = test_tmpdir();
    /* no ini of the user's (HOME, POVINI) may keep the scenes from being read as literals */
    char *home = getenv("HOME") ? strdup(getenv("HOME")) : NULL;
    setenv("HOME", dir, 1);
    unsetenv("POVINI");
    char alone[512], probed[512], ini[600], scene[600];
    snprintf(alone, sizeof alone, "%s/alone", dir);
    snprintf(probed, sizeof probed, "%s/probed", dir);
    mkdir(alone, 0755);
    mkdir(probed, 0755);
    snprintf(ini, sizeof ini, "%s/povray.ini", probed);
    write_text(ini, "");
    for (int d = 0; d < 2; d++) {
        snprintf(scene, sizeof scene, "%s/defs.inc", d ? probed : alone);
        write_text(scene, "#declare Unused = 1;\n");
    }
    for (size_t k = 0; k < sizeof cameras / sizeof *cameras; k++) {
        char *log = scene_camera_literal_log(cameras[k], strlen(cameras[k]));
        cr_expect_not_null(log, "camera %zu is not taken as literal", k);
        free(log);
        scene_camera a, b;
        l2p_error err = {0};
        snprintf(scene, sizeof scene, "%s/scene.pov", alone);
        write_text(scene, cameras[k]);
        setenv("LENS2POV_POVRAY", "/nonexistent/povray", 1);
        cr_assert_eq(scene_camera_read(scene, 64, 48, &a, &err), L2P_OK, "%zu: %s", k, err.text);
        unsetenv("LENS2POV_POVRAY");
        snprintf(scene, sizeof scene, "%s/scene.pov", probed);
        write_text(scene, cameras[k]);
        cr_assert_eq(scene_camera_read(scene, 64, 48, &b, &err), L2P_OK, "%zu: %s", k, err.text);
        cr_expect(a.found && b.found && a.line == b.line && a.mirrored == b.mirrored &&
                      !memcmp(&a.location, &b.location, sizeof a.location) &&
                      !memcmp(&a.forward, &b.forward, sizeof a.forward) &&
                      !memcmp(&a.up, &b.up, sizeof a.up) &&
                      a.focus_distance == b.focus_distance && a.hfov_deg == b.hfov_deg,
                  "camera %zu: <%.17g %.17g %.17g> %.17g deg against POV-Ray's <%.17g %.17g %.17g> "
                  "%.17g deg", k, a.location.x, a.location.y, a.location.z, a.hfov_deg,
                  b.location.x, b.location.y, b.location.z, b.hfov_deg);
    }
    if (home)
        setenv("HOME", home, 1);
    free(home);
}

/* What POV-Ray has to evaluate, or whose rules it has to choose, is not read as a literal. */
Test(scene_camera, other_cameras_are_left_to_povray)
{
    static const char *const cameras[] = {
        "camera { location <0, 1, -4> }\n",                                   /* no #version */
        "#version 3.1;\ncamera { location <0, 1, -4> }\n",                    /* old rules */
        "#version 3.8;\ncamera { location <0, 1, -4> }\n",                    /* not 3.7's */
        "#declare V = 3.7;\n#version V;\ncamera { location <0, 1, -4> }\n",
        "#version 3.7;\n#if (clock > 0) camera { location <0, 1, -4> } #end\n",
        "#version 3.7;\n#macro C() camera { location <0, 1, -4> } #end C()\n",
        "#version 3.7;\n#if (1) #version 3.1; #end camera { location <0, 1, -4> }\n",
        "#version 3.7;\n#declare Eye = <0, 1, -4>;\ncamera { location Eye }\n",
        "#version 3.7;\ncamera { location <0, 1, -4> * 2 }\n",
        "#version 3.7;\ncamera { location <0, 1> }\n",
        "#version 3.7;\ncamera { location <0, 1, -4> rotate 30 * y }\n",
        "#version 3.7;\ncamera { orthographic location <0, 1, -4> }\n",
        "#version 3.7;\n#declare C = camera { location 1 }\ncamera { C }\n",
        "#version 3.7;\ncamera { location <0, 1, -4> angle 2e9 }\n",
        "#version 3.7;\nsphere { 0, 1 }\n",                                  /* no camera */
    };
    for (size_t k = 0; k < sizeof cameras / sizeof *cameras; k++) {
        char *log = scene_camera_literal_log(cameras[k], strlen(cameras[k]));
        cr_expect_null(log, "taken as literal: %s", cameras[k]);
        free(log);
    }
}

/* A povray.ini that turns POV-Ray's console off (All_Console=Off, as -GA does) silenced the
   probe, and the lens took POV-Ray's default camera, with exit 0: lens2pov's own options turn
   the console on again after the user's. */
Test(scene_camera, an_ini_that_turns_the_console_off_still_gives_the_camera)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "povray.ini"), "All_Console=Off\n");
    expect_markers_in(dir, MARKERS_HEAD CAMERA("x"), NULL);
}

/* A camera in a file whose #include names it by an expression is not seen (only names
   written as strings are followed): the default camera is taken, and a warning names the
   line. */
Test(scene_camera, an_include_of_a_computed_name_is_warned_of)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "cam.inc"), "camera { location <0, 1, -4> look_at 0 }\n");
    const char *scene = tmp_path(dir, "computed.pov");
    write_text(scene, "#version 3.7;\nbackground { rgb 1 }\n#declare Name = \"cam.inc\";\n"
                      "#include Name\n");
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, "--width", "16", "--height", "12",
                       "--spp", "1", "-q", "-o", tmp_path(dir, "c.png"));
    cr_expect_eq(st, 0, "%s", errtext ? errtext : "");
    cr_expect(errtext && strstr(errtext, "computed.pov:4: this #include names its file by an "
                                         "expression"), "%s", errtext ? errtext : "");
    free(errtext);
}

/* trace --scene takes POV-Ray's options after -- for reading the camera: a camera in a file
   on a library path (+L) is found, and the table is the one --location and --look-at give
   (byte for byte); without the path POV-Ray's error names the scene's line; options that make
   an animation are refused, since trace writes one camera. */
Test(scene_camera, trace_takes_povray_options_for_the_scene)
{
    const char *dir = test_tmpdir();
    char lib[1024], scene[1100], plus_l[1100], prefix[1100];
    snprintf(lib, sizeof lib, "%s/lib", dir);
    cr_assert_eq(mkdir(lib, 0700), 0);
    write_text(tmp_path(lib, "cam.inc"), "camera { location <1, 2, -6> look_at <0, 1, 0> }\n");
    snprintf(scene, sizeof scene, "%s/s.pov", dir);
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1 }\n#include \"cam.inc\"\n"
                      "background { rgb 1 }\n");
    snprintf(plus_l, sizeof plus_l, "+L%s", lib);
    snprintf(prefix, sizeof prefix, "%s/a", dir);
    run_lens2pov_ok("trace with +L", "trace", LENS_DIR "dgauss.50mm.dat", "--scene", scene,
                    "--width", "16", "--height", "12", "--spp", "1", "-q", "-o", prefix, "--",
                    plus_l, NULL);
    snprintf(prefix, sizeof prefix, "%s/b", dir);
    run_lens2pov_ok("trace placed", "trace", LENS_DIR "dgauss.50mm.dat", "--location", "1,2,-6",
                    "--look-at", "0,1,0", "--width", "16", "--height", "12", "--spp", "1", "-q",
                    "-o", prefix, NULL);
    size_t na, nb;
    char *a = read_text(tmp_path(dir, "a.inc"), &na), *b = read_text(tmp_path(dir, "b.inc"), &nb);
    cr_expect(na == nb && memcmp(a, b, na) == 0, "the tables differ");
    free(a), free(b);
    char *errtext = NULL, want[1200];
    snprintf(prefix, sizeof prefix, "%s/c", dir);
    cr_expect_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--scene",
                              scene, "-q", "-o", prefix, NULL), 2, "%s", errtext);
    snprintf(want, sizeof want, "%s:3: Cannot find file 'cam.inc'", scene);
    cr_expect(strstr(errtext, want), "%s", errtext);
    free(errtext);
    cr_expect_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--scene",
                              scene, "-q", "-o", prefix, "--", plus_l, "+KFI1", "+KFF3", NULL), 2,
                 "%s", errtext);
    cr_expect(strstr(errtext, "make 3 frames; trace writes one camera"), "%s", errtext);
    free(errtext);
    cr_expect_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "-q", "-o",
                              prefix, "--", plus_l, NULL), 2, "%s", errtext);
    cr_expect(strstr(errtext, "only render, and trace --scene"), "%s", errtext);
    free(errtext);
}
