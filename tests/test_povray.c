/* Running the real POV-Ray through src/povray/povray.c on a hand-written mesh_camera include: a 4x2
   ray table (one triangle per ray: origin = centroid, direction = normalize((P3-P1) x (P2-P1)),
   rendered 4x3 because of the row bug FS#254), the gamma of old and new scenes, POV-Ray's
   own error lines, chunks in parallel and stopping them on a failure. No .timeout: with it,
   Criterion 2.4's runner leaks 48 bytes under AddressSanitizer when tests run side by side
   (--jobs 2), which fails `make test-sanitize`; each test here takes about a second. */
#include <criterion/criterion.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "povray/povray.h"
#include "support.h"

/* ---------------------------------------------------------------- files */

static char *fmt(const char *f, const char *a, const char *b)
{
    char *s = malloc(4096);
    snprintf(s, 4096, f, a, b);
    return s;
}

/* A 4x2 ray table, every ray from z = -3 along dz (+1 or -1), origins 1 cm apart; the
   include raises the language version only when it is below 3.7, as lens2pov's does. */
static void write_include(const char *path, int dz)
{
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fputs("#if (version < 3.7)\n  #declare Lens2pov_Version = version;\n  #version 3.7;\n#end\n"
          "#declare Lens2pov_Rays = mesh2 {\n  vertex_vectors { 24,\n", f);
    const double e = 1e-3;
    for (int k = 0; k < 8; k++) {
        const double x = 0.01 * (k % 4), y = -0.01 * (k / 4);
        /* P1, P2 = P1 + e y, P3 = P1 + e x: (P3-P1) x (P2-P1) = e^2 z; reversed for -z. */
        const double dy = dz > 0 ? e : 0, dx = dz > 0 ? 0 : e;
        fprintf(f, "<%g,%g,0>,<%g,%g,0>,<%g,%g,0>,\n", x, y, x + dx, y + dy, x + dy, y + dx);
    }
    fputs("  }\n  face_indices { 8,\n", f);
    for (int k = 0; k < 8; k++)
        fprintf(f, "<%d,%d,%d>,\n", 3 * k, 3 * k + 1, 3 * k + 2);
    fputs("  }\n}\ncamera { mesh_camera { 1 0 mesh { Lens2pov_Rays translate <0,0,-3> } } }\n"
          "#undef Lens2pov_Rays\n"
          "#ifdef (Lens2pov_Version)\n  #version Lens2pov_Version;\n  #undef Lens2pov_Version\n"
          "#end\n", f);
    fclose(f);
}

/* Width 4, one row more than the two face rows (FS#254), EXR. */
static void write_ini(const char *path, const char *exr)
{
    char *text = fmt("Width=4\nHeight=3\nAntialias=Off\nOutput_File_Type=E\n"
                     "Output_To_File=On\nOutput_File_Name=%s\nDisplay=Off\n%s", exr, "");
    write_text(path, text);
    free(text);
}

typedef struct fixture {
    char *dir;
    povray_chunk chunk[3];
    char *paths[9];
} fixture;

/* Chunk i: dir/rays.c00i.{inc,ini,exr}, rays along dz[i]. */
static void make_chunks(fixture *fx, const char *dir, int count, const int *dz)
{
    memset(fx, 0, sizeof *fx);
    fx->dir = strdup(dir);
    for (int i = 0; i < count; i++) {
        char name[64];
        snprintf(name, sizeof name, "rays.c%03d", i);
        char *inc = fmt("%s/%s.inc", dir, name), *ini = fmt("%s/%s.ini", dir, name);
        char *exr = fmt("%s/%s.exr", dir, name);
        write_include(inc, dz[i]);
        write_ini(ini, exr);
        fx->chunk[i] = (povray_chunk){inc, ini, exr, 8, NULL, -1, NULL};
        fx->paths[3 * i] = inc, fx->paths[3 * i + 1] = ini, fx->paths[3 * i + 2] = exr;
    }
}

static void free_fixture(fixture *fx)
{
    for (int i = 0; i < 9; i++)
        free(fx->paths[i]);
    free(fx->dir);
}

static povray_options options(const char *scene, const char *work_dir, int jobs)
{
    return (povray_options){scene, work_dir, jobs, 1, 0, NULL, NULL, NULL, NULL, 0, 0, 0, NULL, NULL, NULL, NULL, false,
                            NULL};
}

/* The one-chunk table of make_chunks rendered from dir with scene, one job. */
static int render_one_chunk(fixture *fx, const char *dir, const char *scene, l2p_error *err)
{
    make_chunks(fx, dir, 1, (const int[]){1});
    povray_options o = options(scene, dir, 1);
    return povray_render_chunks(fx->chunk, 1, &o, err);
}

/* ---------------------------------------------------------------- reading the EXR back */

/* The 4x3 pixels' RGB, read with oiiotool (the tests link no C++). */
static void read_exr(const char *path, float rgb[12][3])
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "oiiotool --dumpdata '%s' 2>&1", path);
    FILE *p = popen(cmd, "r");
    cr_assert_not_null(p);
    char line[512];
    int seen = 0;
    while (fgets(line, sizeof line, p)) {
        int x, y;
        float r, g, b;
        if (sscanf(line, " Pixel (%d, %d): %f %f %f", &x, &y, &r, &g, &b) == 5 && x < 4 && y < 3) {
            rgb[y * 4 + x][0] = r, rgb[y * 4 + x][1] = g, rgb[y * 4 + x][2] = b;
            seen++;
        }
    }
    cr_assert_eq(pclose(p), 0, "oiiotool failed on %s", path);
    cr_assert_eq(seen, 12, "%s: %d pixels", path, seen);
}

static void expect_uniform(const char *exr, float r, float g, float b)
{
    float rgb[12][3];
    read_exr(exr, rgb);
    for (int i = 0; i < 12; i++)
        cr_expect(fabsf(rgb[i][0] - r) < 1e-3f && fabsf(rgb[i][1] - g) < 1e-3f &&
                      fabsf(rgb[i][2] - b) < 1e-3f,
                  "%s pixel %d: %g %g %g, expected %g %g %g", exr, i, rgb[i][0], rgb[i][1],
                  rgb[i][2], r, g, b);
}

/* ---------------------------------------------------------------- scenes */

/* A glowing plane at z = 0 in front of the rays, and a camera of the scene's own looking the
   other way (it would see black): the lens camera, declared later, must win. */
static const char MODERN_SCENE[] =
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
    "camera { location <0,0,-3> look_at <0,0,-10> }\n"
    "plane { -z, 0 pigment { rgb <0.25,0.5,0.75> } finish { ambient 1 diffuse 0 } }\n";

Test(povray, renders_a_modern_scene_through_the_lens_camera)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
    write_text(scene, MODERN_SCENE);
    fixture fx;
    l2p_error err = {0};
    cr_assert_eq(render_one_chunk(&fx, dir, scene, &err), L2P_OK, "%s", err.text);
    expect_uniform(fx.chunk[0].output_exr, 0.25f, 0.5f, 0.75f);
    free_fixture(&fx);
    free(scene);
    remove_tree(dir);
    free(dir);
}

/* No #version and no assumed_gamma: POV-Ray's own PNG shows the raw 0.25 (64), so the EXR
   must hold sRGB-decoded 0.0509. A povray.ini in the scene's folder (it replaces the system
   one) with another display gamma, alpha and antialiasing must not change that. */
Test(povray, an_old_scene_keeps_its_gamma_and_povray_ini_cannot_change_it)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "old.pov"), *ini = fmt("%s/%s", dir, "povray.ini");
    write_text(scene, "background { rgb 0.25 }\n");
    write_text(ini, "Display_Gamma=1.0\nOutput_Alpha=On\nAntialias=On\n");
    fixture fx;
    l2p_error err = {0};
    cr_assert_eq(render_one_chunk(&fx, dir, scene, &err), L2P_OK, "%s", err.text);
    const float v = powf((0.25f + 0.055f) / 1.055f, 2.4f);
    expect_uniform(fx.chunk[0].output_exr, v, v, v);
    free_fixture(&fx);
    free(scene);
    free(ini);
    remove_tree(dir);
    free(dir);
}

/* The scene's own includes resolve from its folder, the standard ones from POV-Ray's. */
Test(povray, includes_resolve_from_the_scene_folder_and_the_library)
{
    char *dir = strdup(test_tmpdir()), *sub = fmt("%s/%s", dir, "scenes");
    mkdir(sub, 0777);
    char *scene = fmt("%s/%s", sub, "s.pov"), *mine = fmt("%s/%s", sub, "mine.inc");
    write_text(mine, "#declare MyColour = rgb <0.5, 0.25, 0>;\n");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n#include \"colors.inc\"\n"
                    "#include \"mine.inc\"\nbackground { MyColour }\n");
    fixture fx;
    l2p_error err = {0};
    cr_assert_eq(render_one_chunk(&fx, dir, scene, &err), L2P_OK, "%s", err.text);
    expect_uniform(fx.chunk[0].output_exr, 0.5f, 0.25f, 0.0f);
    free_fixture(&fx);
    free(scene);
    free(mine);
    free(sub);
    remove_tree(dir);
    free(dir);
}

/* A folder and file name POV-Ray cannot read (a space is fine, é is not): it gets links. */
Test(povray, scene_paths_that_are_not_ascii_work_and_errors_name_them)
{
    char *dir = strdup(test_tmpdir()), *sub = fmt("%s/%s", dir, "sc\xc3\xa8ne 1");
    mkdir(sub, 0777);
    char *scene = fmt("%s/%s", sub, "\xc3\xa9t\xc3\xa9.pov"), *mine = fmt("%s/%s", sub, "mine.inc");
    write_text(mine, "#declare MyColour = rgb 0.5;\n");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                    "#include \"mine.inc\"\nbackground { MyColour }\n");
    fixture fx;
    l2p_error err = {0};
    cr_assert_eq(render_one_chunk(&fx, dir, scene, &err), L2P_OK, "%s", err.text);
    expect_uniform(fx.chunk[0].output_exr, 0.5f, 0.5f, 0.5f);

    write_text(mine, "#declare MyColour = rgb 0.5;\nsphere { 0, 1 pigment { foo } }\n");
    povray_options o = options(scene, dir, 1);
    cr_assert_eq(povray_render_chunks(fx.chunk, 1, &o, &err), L2P_BAD_INPUT);
    char *expected = fmt("%s:%s: ", mine, "2");
    cr_expect(strncmp(err.text, expected, strlen(expected)) == 0, "%s", err.text);
    free(expected);
    free_fixture(&fx);
    free(scene);
    free(mine);
    free(sub);
    remove_tree(dir);
    free(dir);
}

/* POV-Ray's parse error comes back as FILE:LINE: message, nothing else from its log. */
Test(povray, a_syntax_error_names_the_file_and_line)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "bad.pov");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                    "sphere { <0,0,0>, 1 pigment { rgb 1 }\nbox { 0, 1 }\n");
    fixture fx;
    l2p_error err = {0};
    cr_assert_eq(render_one_chunk(&fx, dir, scene, &err), L2P_BAD_INPUT);
    cr_assert_eq(err.status, L2P_BAD_INPUT);
    char *expected = fmt("%s:4: No matching } in 'sphere', box found instead%s", scene, "");
    cr_expect_str_eq(err.text, expected);
    free(expected);
    free_fixture(&fx);
    free(scene);
    remove_tree(dir);
    free(dir);
}

Test(povray, a_missing_image_file_is_named)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "img.pov");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n\n"
                    "plane { z, 1 pigment { image_map { png \"nofile.png\" } } }\n");
    fixture fx;
    l2p_error err = {0};
    cr_assert_eq(render_one_chunk(&fx, dir, scene, &err), L2P_BAD_INPUT);
    char *expected = fmt("%s:4: %s", scene, "Cannot find file 'nofile.png'");
    cr_expect(strncmp(err.text, expected, strlen(expected)) == 0, "%s", err.text);
    free(expected);
    free_fixture(&fx);
    free(scene);
    remove_tree(dir);
    free(dir);
}

Test(povray, a_missing_scene_is_bad_input)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "none.pov");
    fixture fx;
    l2p_error err = {0};
    cr_assert_eq(render_one_chunk(&fx, dir, scene, &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, scene) && strstr(err.text, "No such file"), "%s", err.text);
    cr_expect(access(fx.chunk[0].output_exr, F_OK) != 0);
    free_fixture(&fx);
    free(scene);
    remove_tree(dir);
    free(dir);
}

Test(povray, a_missing_povray_says_which_package)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
    write_text(scene, MODERN_SCENE);
    fixture fx;
    make_chunks(&fx, dir, 1, (const int[]){1});
    povray_options o = options(scene, dir, 1);
    o.povray = "no-such-povray-here";
    l2p_error err = {0};
    cr_assert_eq(povray_render_chunks(fx.chunk, 1, &o, &err), L2P_FAILED);
    cr_expect_str_eq(err.text, "no-such-povray-here: not found (install Debian's povray package)");
    free_fixture(&fx);
    free(scene);
    remove_tree(dir);
    free(dir);
}

/* Two chunks at once, the second looking back at another plane. POV-Ray runs behind a
   script that waits until both have started: run one after the other, the first gives up. */
Test(povray, two_chunks_render_in_parallel)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
    char *script = fmt("%s/%s", dir, "barrier"), *marks = fmt("%s/%s", dir, "started");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                    "plane { -z, 0 pigment { rgb <1,0,0> } finish { ambient 1 diffuse 0 } }\n"
                    "plane { z, -10 pigment { rgb <0,1,0> } finish { ambient 1 diffuse 0 } }\n");
    char *text = fmt("#!/bin/sh\ntouch '%s'.$$\nn=0\n"
                     "while [ $(ls '%s'.* | wc -l) -lt 2 ]; do\n"
                     "  n=$((n+1)); [ $n -lt 100 ] || { echo 'not in parallel' >&2; exit 1; }\n"
                     "  sleep 0.05\ndone\nexec povray \"$@\"\n", marks, marks);
    write_text(script, text);
    free(text);
    chmod(script, 0755);
    fixture fx;
    make_chunks(&fx, dir, 2, (const int[]){1, -1});
    povray_options o = options(scene, dir, 2);
    o.povray = script;
    l2p_error err = {0};
    cr_assert_eq(povray_render_chunks(fx.chunk, 2, &o, &err), L2P_OK, "%s", err.text);
    expect_uniform(fx.chunk[0].output_exr, 1, 0, 0);
    expect_uniform(fx.chunk[1].output_exr, 0, 1, 0);
    free_fixture(&fx);
    free(scene);
    free(script);
    free(marks);
    remove_tree(dir);
    free(dir);
}

/* A failing chunk stops the other one, whose stand-in for POV-Ray would sleep for a minute:
   the call returns at once, the sleeper is gone and nothing is left to reap. With exec the
   stand-in becomes the sleeper; without, it starts the sleeper in its background and waits,
   as a user's wrapper in LENS2POV_POVRAY may, and the sleeper must be stopped with it. */
static void expect_a_failure_stops_the_sleeper(bool exec)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
    char *script = fmt("%s/%s", dir, "fakepov"), *pidfile = fmt("%s/%s", dir, "sleeper.pid");
    write_text(scene, MODERN_SCENE);
    const char *sleeper = exec ? "echo $$ > \"$p\"; exec sleep 60"
                               : "sleep 60 & echo $! > \"$p\"; wait";
    char *text = fmt("#!/bin/sh\np='%s'\ncase \"$*\" in\n*c001*) %s;;\n"
                     "*) while [ ! -s \"$p\" ]; do sleep 0.05; done\n"
                     "   echo \"File '/x/y.pov' line 7: Parse Error: broken\" >&2; exit 1;;\nesac\n",
                     pidfile, sleeper);
    write_text(script, text);
    free(text);
    chmod(script, 0755);
    fixture fx;
    make_chunks(&fx, dir, 2, (const int[]){1, 1});
    povray_options o = options(scene, dir, 2);
    o.povray = script;
    /* The failing chunk waits until the sleeper has written its pid. */
    l2p_error err = {0};
    cr_assert_eq(povray_render_chunks(fx.chunk, 2, &o, &err), L2P_BAD_INPUT);
    cr_expect_str_eq(err.text, "/x/y.pov:7: broken");
    FILE *f = fopen(pidfile, "r");
    cr_assert_not_null(f, "the sleeper never started");
    int pid = 0;
    cr_expect_eq(fscanf(f, "%d", &pid), 1);
    fclose(f);
    cr_expect(pid > 0 && kill(pid, 0) != 0 && errno == ESRCH, "sleeper %d still there", pid);
    cr_expect(waitpid(-1, NULL, WNOHANG) < 0 && errno == ECHILD, "a child is left");
    free_fixture(&fx);
    free(scene);
    free(script);
    free(pidfile);
    remove_tree(dir);
    free(dir);
}

Test(povray, a_failure_stops_the_other_processes)
{
    expect_a_failure_stops_the_sleeper(true);
}

Test(povray, a_failure_stops_what_a_wrapper_started)
{
    expect_a_failure_stops_the_sleeper(false);
}

/* POV-Ray's "Timed out waiting for worker thread startup" (a loaded machine) is passing: the
   chunk is started again, at most seven times. A stand-in that fails so once renders the second
   time; one that always does fails the render with POV-Ray's message after eight starts. */
Test(povray, a_thread_startup_timeout_is_retried)
{
    for (int always = 0; always < 2; always++) {
        char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
        char *script = fmt("%s/%s", dir, "slowpov"), *count = fmt("%s/%s", dir, "starts");
        write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                        "plane { -z, 0 pigment { rgb <1,0,0> } finish { ambient 1 diffuse 0 } }\n");
        char *text = fmt(always ? "#!/bin/sh\necho x >> '%s'\n"
                                  "echo 'Timed out waiting for worker thread startup' >&2; exit 1\n%s"
                                : "#!/bin/sh\necho x >> '%s'\n"
                                  "if [ $(wc -l < '%s') -lt 2 ]; then\n"
                                  "  echo 'Timed out waiting for worker thread startup' >&2; exit 1\nfi\n"
                                  "exec povray \"$@\"\n", count, always ? "" : count);
        write_text(script, text);
        free(text);
        chmod(script, 0755);
        fixture fx;
        make_chunks(&fx, dir, 1, (const int[]){1});
        povray_options o = options(scene, dir, 1);
        o.povray = script;
        l2p_error err = {0};
        const int st = povray_render_chunks(fx.chunk, 1, &o, &err);
        char *starts = read_text(count, NULL);
        const int n = starts ? (int)(strlen(starts) / 2) : 0;
        if (always) {
            cr_expect_eq(st, L2P_FAILED);
            cr_expect(strstr(err.text, "Timed out"), "%s", err.text);
            cr_expect_eq(n, 8, "started %d times", n);
        } else {
            cr_expect_eq(st, L2P_OK, "%s", err.text);
            cr_expect_eq(n, 2, "started %d times", n);
            expect_uniform(fx.chunk[0].output_exr, 1, 0, 0);
        }
        free(starts);
        free_fixture(&fx);
        free(scene), free(script), free(count);
        remove_tree(dir);
        free(dir);
    }
}

/* ---------------------------------------------------------------- sequences */

/* A script standing in for POV-Ray that notes each start in dir/starts, then runs it. */
static char *counting_povray(const char *dir)
{
    char *script = fmt("%s/%s", dir, "countpov"), *starts = fmt("%s/%s", dir, "starts");
    /* a start that timed out starting its threads (the runner starts it again) is not one;
       a start is noted first, since a process whose pictures are in is killed */
    char *text = fmt("#!/bin/sh\necho start >> '%s'\npovray \"$@\" 2>\"$0.err.$$\"; st=$?\n"
                     "cat \"$0.err.$$\" >&2\ngrep -q 'Timed out waiting for worker thread startup' "
                     "\"$0.err.$$\" && echo retry >> '%s'\nrm -f \"$0.err.$$\"\nexit $st\n", starts,
                     starts);
    write_text(script, text);
    chmod(script, 0755);
    free(text);
    free(starts);
    return script;
}

static int povray_starts(const char *dir)
{
    char *starts = fmt("%s/%s", dir, "starts");
    char *text = read_text(starts, NULL);
    int n = 0;
    for (const char *p = text; p && (p = strstr(p, "start")) != NULL; p++)
        n++;
    for (const char *p = text; p && (p = strstr(p, "retry")) != NULL; p++)
        n--;
    free(text);
    free(starts);
    return n;
}

/* Two chunks, one looking at each plane, as the two frames of one POV-Ray process: each
   frame's picture is its own chunk's, in its chunk's output_exr, and no frame file is left;
   a scene reading frame_number and clock sees a still's. */
Test(povray, a_sequence_renders_its_chunks_as_the_frames_of_one_process)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                    "#if (frame_number != 0 | clock != 0 | final_frame != 0) #error \"animated\" #end\n"
                    "plane { -z, 0 pigment { rgb <1,0,0> } finish { ambient 1 diffuse 0 } }\n"
                    "plane { z, -10 pigment { rgb <0,1,0> } finish { ambient 1 diffuse 0 } }\n");
    char *script = counting_povray(dir);
    fixture fx;
    make_chunks(&fx, dir, 2, (const int[]){1, -1});
    povray_options o = options(scene, dir, 2);
    o.povray = script;
    l2p_error err = {0};
    cr_assert_eq(povray_render_sequences(fx.chunk, (const int[]){2}, 1, &o, &err), L2P_OK, "%s",
                 err.text);
    expect_uniform(fx.chunk[0].output_exr, 1, 0, 0);
    expect_uniform(fx.chunk[1].output_exr, 0, 1, 0);
    cr_expect_eq(povray_starts(dir), 1);
    cr_expect_eq(count_entries(dir, "povray.s000.f", NULL, 0), 0, "frame files left");

    /* one chunk a sequence: a process each, the same pictures */
    unlink(fx.chunk[0].output_exr), unlink(fx.chunk[1].output_exr);
    cr_assert_eq(povray_render_sequences(fx.chunk, (const int[]){1, 1}, 2, &o, &err), L2P_OK,
                 "%s", err.text);
    expect_uniform(fx.chunk[0].output_exr, 1, 0, 0);
    expect_uniform(fx.chunk[1].output_exr, 0, 1, 0);
    cr_expect_eq(povray_starts(dir), 3);
    free_fixture(&fx);
    free(scene);
    free(script);
    remove_tree(dir);
    free(dir);
}

/* What picture_done saw: the chunks in the order reported, and how many of them came while
   their POV-Ray process still ran (the script notes its end in dir/ended). */
typedef struct reports {
    const fixture *fx;
    char *ended;
    int chunk[8], count, while_running, fail_at;
} reports;

static int note_picture(void *ctx, int k, l2p_error *err)
{
    reports *r = ctx;
    if (r->count < 8)
        r->chunk[r->count] = k;
    r->count++;
    if (access(r->ended, F_OK) != 0)
        r->while_running++;
    /* complete where it was reported: every pixel its chunk's colour */
    expect_uniform(r->fx->chunk[k].output_exr, k == 1 ? 0 : 1, k == 1 ? 1 : 0, 0);
    return k == r->fail_at ? l2p_fail(err, L2P_FAILED, NULL, 0, "stopped at chunk %d", k) : L2P_OK;
}

/* A sequence's frames are reported one by one in their order, each complete in its chunk's
   output_exr, and (POV-Ray closes a frame's picture before it parses the next one, and takes
   about a quarter of a second to exit) most of them before their process has ended. A
   nonzero return stops the run with its error. */
Test(povray, a_sequence_reports_each_frame_when_povray_has_closed_it)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                    "plane { -z, 0 pigment { rgb <1,0,0> } finish { ambient 1 diffuse 0 } }\n"
                    "plane { z, -10 pigment { rgb <0,1,0> } finish { ambient 1 diffuse 0 } }\n");
    char *script = fmt("%s/%s", dir, "endpov"), *ended = fmt("%s/%s", dir, "ended");
    /* POV-Ray runs in the background of the stand-in, which passes on the runner's SIGTERM
       and waits for it: a stand-in killed with POV-Ray still running (the run stopped below)
       would leave it writing into the test's folder while the folder is removed. */
    char *text = fmt("#!/bin/sh\ntrap 'kill $pid 2>/dev/null; wait; exit 143' TERM\n"
                     "povray \"$@\" & pid=$!\nwait $pid; st=$?\necho end > '%s'\nexit $st\n%s",
                     ended, "");
    write_text(script, text);
    chmod(script, 0755);
    fixture fx;
    make_chunks(&fx, dir, 3, (const int[]){1, -1, 1});
    povray_options o = options(scene, dir, 1);
    o.povray = script;
    reports seen = {.fx = &fx, .ended = ended, .fail_at = -1};
    o.picture_done = note_picture;
    o.picture_ctx = &seen;
    l2p_error err = {0};
    cr_assert_eq(povray_render_sequences(fx.chunk, (const int[]){3}, 1, &o, &err), L2P_OK, "%s",
                 err.text);
    cr_assert_eq(seen.count, 3);
    for (int k = 0; k < 3; k++)
        cr_expect_eq(seen.chunk[k], k, "report %d is chunk %d", k, seen.chunk[k]);
    cr_expect_geq(seen.while_running, 1, "every frame was reported after POV-Ray had ended");
    cr_expect_eq(count_entries(dir, "povray.s000.f", NULL, 0), 0, "frame files left");

    /* an error from picture_done stops the run with it */
    for (int k = 0; k < 3; k++)
        unlink(fx.chunk[k].output_exr);
    unlink(ended);
    seen = (reports){.fx = &fx, .ended = ended, .fail_at = 0};
    cr_assert_eq(povray_render_sequences(fx.chunk, (const int[]){3}, 1, &o, &err), L2P_FAILED);
    cr_expect_str_eq(err.text, "stopped at chunk 0");
    cr_expect_eq(seen.count, 1);
    free_fixture(&fx);
    free(scene), free(script), free(ended), free(text);
    remove_tree(dir);
    free(dir);
}

/* Once every picture of a process is in, the runner does not wait for the process to end
   (POV-Ray only winds down after its last picture, a third to half a second): the stand-in
   notes its pid, runs POV-Ray, then writes dir/ended. Both a sequence and a chunk return
   with their pictures, the stand-in gone before it could write dir/ended; so with POV-Ray
   options of the user's that leave it nothing more to do (quality, threads, Declare=, +L). With
   others (which might make POV-Ray do more after its picture) the run waits for the process
   to end. */
Test(povray, a_process_whose_pictures_are_in_is_not_waited_for)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "scene.pov");
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                    "plane { -z, 0 pigment { rgb <1,0,0> } finish { ambient 1 diffuse 0 } }\n"
                    "plane { z, -10 pigment { rgb <0,1,0> } finish { ambient 1 diffuse 0 } }\n");
    char *script = fmt("%s/%s", dir, "lingerpov"), *pidfile = fmt("%s/%s", dir, "pid");
    char *ended = fmt("%s/%s", dir, "ended");
    char *text = fmt("#!/bin/sh\necho $$ > '%s'\npovray \"$@\"; st=$?\necho end >> '%s'\nexit $st\n",
                     pidfile, ended);
    write_text(script, text);
    chmod(script, 0755);
    fixture fx;
    make_chunks(&fx, dir, 2, (const int[]){1, -1});
    povray_options o = options(scene, dir, 1);
    o.povray = script;
    l2p_error err = {0};
    for (int sequence = 1; sequence >= 0; sequence--) {
        unlink(pidfile);
        cr_assert_eq(sequence ? povray_render_sequences(fx.chunk, (const int[]){2}, 1, &o, &err)
                              : povray_render_chunks(fx.chunk, 1, &o, &err),
                     L2P_OK, "%s", err.text);
        expect_uniform(fx.chunk[0].output_exr, 1, 0, 0);
        if (sequence)
            expect_uniform(fx.chunk[1].output_exr, 0, 1, 0);
        int pid = 0;
        FILE *f = fopen(pidfile, "r");
        cr_assert_not_null(f, "the stand-in never noted its pid");
        cr_expect_eq(fscanf(f, "%d", &pid), 1);
        fclose(f);
        cr_expect(pid > 0 && kill(pid, 0) != 0 && errno == ESRCH, "stand-in %d still there", pid);
        cr_expect_neq(access(ended, F_OK), 0, "the run waited for the stand-in's end");
        cr_expect(waitpid(-1, NULL, WNOHANG) < 0 && errno == ECHILD, "a child is left");
    }
    /* POV-Ray options of the user's that leave it nothing to do after its pictures: not
       waited for; any other: waited for */
    char *const plain[] = {"+Q9", "Declare=Lens2pov_Test=1", "+WT1", "+L/tmp"};
    char *const other[] = {"+GD"};
    o.user_args = plain;
    o.user_arg_count = 4;
    cr_assert_eq(povray_render_chunks(fx.chunk, 1, &o, &err), L2P_OK, "%s", err.text);
    cr_expect_neq(access(ended, F_OK), 0, "the run waited with %s", plain[1]);
    o.user_args = other;
    o.user_arg_count = 1;
    cr_assert_eq(povray_render_chunks(fx.chunk, 1, &o, &err), L2P_OK, "%s", err.text);
    cr_expect_eq(access(ended, F_OK), 0, "the run did not wait with %s", other[0]);
    free_fixture(&fx);
    free(scene), free(script), free(pidfile), free(ended), free(text);
    remove_tree(dir);
    free(dir);
}

/* A scene that fails only when parsed a second time fails the sequence in its second frame,
   with POV-Ray's own message for it, not the first frame's warnings. */
Test(povray, an_error_in_a_later_frame_fails_with_its_message)
{
    char *dir = strdup(test_tmpdir()), *scene = fmt("%s/%s", dir, "once.pov");
    write_text(scene, "#version 3.7;\n"
                    "#if (file_exists(\"seen.txt\"))\n  #error \"this scene renders once\"\n#end\n"
                    "#fopen Seen \"seen.txt\" write\n#fclose Seen\n"
                    "plane { -z, 0 pigment { rgb <1,0,0> } finish { ambient 1 diffuse 0 } }\n");
    fixture fx;
    make_chunks(&fx, dir, 2, (const int[]){1, 1});
    povray_options o = options(scene, dir, 1);
    l2p_error err = {0};
    cr_assert_eq(povray_render_sequences(fx.chunk, (const int[]){2}, 1, &o, &err), L2P_BAD_INPUT);
    char *expected = fmt("%s:3: Parse halted by #error directive: this scene renders once%s",
                         scene, "");
    cr_expect_str_eq(err.text, expected);
    free(expected);
    free_fixture(&fx);
    free(scene);
    remove_tree(dir);
    free(dir);
}
