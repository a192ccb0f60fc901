/* render --sampling field renders each job's renders as the frames of one POV-Ray animation
   (povray_render_sequences): the frames are the pictures separate processes make, --jobs
   processes are started, and an error in a later frame fails the render with its message.
   Through the real POV-Ray, with a script in front of it that counts its starts. */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "image/image_io.h"
#include "support.h"

/* Edges everywhere, its camera placed on the command line (no scene-camera run). */
static const char *SCENE =
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
    "light_source { <-3, 5, -4> rgb 1 }\n"
    "sky_sphere { pigment { gradient y color_map { [0 rgb <0.6,0.7,0.9>] [1 rgb <0.1,0.2,0.6>] } } }\n"
    "plane { y, 0 pigment { checker rgb 0.9 rgb 0.1 scale 0.5 } finish { ambient 0.2 diffuse 0.8 } }\n"
    "sphere { <0.3, 0.8, 0.5>, 0.8 pigment { rgb <0.8, 0.2, 0.1> } finish { ambient 0.2 diffuse 0.8 } }\n";

/* dir/countpov: notes each start in dir/starts and runs POV-Ray; lens2pov runs it. */
static void count_povray_starts(const char *dir)
{
    char script[1200], text[2600];
    snprintf(script, sizeof script, "%s/countpov", dir);
    /* a start that timed out starting its threads (the runner starts it again) is not one;
       a start is noted first, since a process whose pictures are in is killed */
    snprintf(text, sizeof text, "#!/bin/sh\necho start >> '%s/starts'\n"
             "povray \"$@\" 2>\"$0.err.$$\"; st=$?\ncat \"$0.err.$$\" >&2\n"
             "grep -q 'Timed out waiting for worker thread startup' \"$0.err.$$\" && "
             "echo retry >> '%s/starts'\nrm -f \"$0.err.$$\"\nexit $st\n", dir, dir);
    write_text(script, text);
    chmod(script, 0755);
    setenv("LENS2POV_POVRAY", script, 1);
}

static int povray_starts(const char *dir)
{
    char *text = read_text(tmp_path(dir, "starts"), NULL);
    int n = 0;
    for (const char *p = text; p && (p = strstr(p, "start")) != NULL; p++)
        n++;
    for (const char *p = text; p && (p = strstr(p, "retry")) != NULL; p++)
        n--;
    free(text);
    return n;
}

/* The fisheye at 160x120, 16 spp, a tolerance of 0.03 pixel: its sub-images take about 2900
   faces each, so the renders are several whatever --jobs. */
static int field_render(const char *dir, const char *jobs, const char *work)
{
    char *errtext = NULL;
    const char *scene = tmp_path(dir, "scene.pov"), *out = tmp_path(dir, "out.exr");
    const int st = run_lens2pov(NULL, &errtext, "render", scene, LENS_DIR "fisheye.10mm.dat",
                                "--width", "160", "--height", "120", "--spp", "16", "--location",
                                "0,1,-4", "--look-at", "0,0.6,0", "--sampling", "field",
                                "--field-tolerance", "0.03", "--jobs", jobs, "--keep-temp", work,
                                "--quiet", "-o", out, (char *)NULL);
    if (st)
        cr_log_info("render: %s", errtext ? errtext : "");
    free(errtext);
    return st;
}

/* Render r of work again, alone in a POV-Ray process of its own as render ran one before
   sequences (the wrapper declares the film's size, includes the scene, then the camera);
   its picture and the sequence's must be the same floats. */
static void expect_same_alone(const char *dir, const char *work, int r)
{
    char wrapper[1200], text[4000], cmd[8000], path[1200];
    snprintf(wrapper, sizeof wrapper, "%s/alone.pov", dir);
    snprintf(text, sizeof text,
             "#declare image_width = 160;\n#declare image_height = 120;\n"
             "#include \"%s/scene.pov\"\n#include \"%s/field.f%03d.inc\"\n", dir, work, r);
    write_text(wrapper, text);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray '%s/field.f%03d.ini' +I'%s' +O'%s/alone.exr' -D -P -C -UA -A "
             "-V -GS -GR +FE Display_Gamma=sRGB >'%s/alone.log' 2>&1", dir, work, r, wrapper, dir,
             dir);
    cr_assert_eq(system_povray(cmd), 0, "POV-Ray alone on render %d failed (%s/alone.log)", r, dir);
    int w[2], h[2];
    float *px[2];
    l2p_error err;
    snprintf(path, sizeof path, "%s/field.f%03d.exr", work, r);
    cr_assert_eq(image_read_rgba(path, &w[0], &h[0], &px[0], &err), 0, "%s", err.text);
    cr_assert_eq(image_read_rgba(tmp_path(dir, "alone.exr"), &w[1], &h[1], &px[1], &err), 0, "%s",
                 err.text);
    cr_assert(w[0] == w[1] && h[0] == h[1], "render %d: %dx%d against %dx%d", r, w[0], h[0], w[1],
              h[1]);
    cr_expect(memcmp(px[0], px[1], sizeof(float) * 4 * (size_t)w[0] * h[0]) == 0,
              "render %d: the frame differs from POV-Ray's picture alone", r);
    free(px[0]), free(px[1]);
}

static int count_renders(const char *work)
{
    int n = 0;
    char path[1200];
    for (;; n++) {
        snprintf(path, sizeof path, "%s/field.f%03d.inc", work, n);
        if (!file_exists(path))
            return n;
    }
}

/* --jobs 2: two POV-Ray processes for the several renders, each frame the very picture a
   process of its own makes of that render, and the workspace keeps one wrapper and one log a
   process, no frame file. */
Test(field_loop, each_frame_is_what_a_process_of_its_own_renders)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char work[1100];
    snprintf(work, sizeof work, "%s/work", dir);
    count_povray_starts(dir);
    cr_assert_eq(field_render(dir, "2", work), 0);
    unsetenv("LENS2POV_POVRAY");
    const int renders = count_renders(work);
    cr_log_info("%d renders", renders);
    cr_assert_geq(renders, 3, "only %d renders", renders);
    cr_expect_eq(povray_starts(dir), 2);
    cr_expect_eq(count_entries(work, "povray.s", NULL, 0), 4);   /* .pov and .log, twice */
    for (int r = 0; r < renders; r++)
        expect_same_alone(dir, work, r);
}

/* --jobs 1: one process for every render; a scene that fails when parsed a second time stops
   it in its second frame, and the render fails (exit 1) with POV-Ray's message for it. */
Test(field_loop, an_error_in_one_frame_fails_the_render_with_its_message)
{
    const char *dir = test_tmpdir();
    char text[2000], work[1100];
    snprintf(text, sizeof text,
             "%s#if (file_exists(\"seen.txt\"))\n  #error \"this scene renders once\"\n#end\n"
             "#fopen Seen \"seen.txt\" write\n#fclose Seen\n", SCENE);
    write_text(tmp_path(dir, "scene.pov"), text);
    snprintf(work, sizeof work, "%s/work", dir);
    count_povray_starts(dir);
    char *errtext = NULL;
    const char *scene = tmp_path(dir, "scene.pov"), *out = tmp_path(dir, "out.png");
    const int st = run_lens2pov(NULL, &errtext, "render", scene, LENS_DIR "fisheye.10mm.dat",
                                "--width", "160", "--height", "120", "--spp", "16", "--location",
                                "0,1,-4", "--look-at", "0,0.6,0", "--sampling", "field", "--jobs",
                                "1", "--keep-temp", work, "--quiet", "-o", out, (char *)NULL);
    unsetenv("LENS2POV_POVRAY");
    cr_expect_eq(st, 2, "status %d: %s", st, errtext ? errtext : "");
    char expected[1200];
    snprintf(expected, sizeof expected, "%s:8: Parse halted by #error directive: this scene renders once",
             scene);
    cr_expect(errtext && strstr(errtext, expected), "%s", errtext ? errtext : "");
    free(errtext);
    cr_expect_eq(povray_starts(dir), 1);
    cr_expect_geq(count_renders(work), 2);
    cr_expect(!file_exists(out));
}
