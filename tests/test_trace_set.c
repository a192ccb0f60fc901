/* A trace's files for its prefix as a set: develop finds the renders by the names the trace
   gave them, a new trace of the prefix removes the includes and inis an earlier one left, and
   develop warns of a render older than its map. End to end, with POV-Ray for the renders. */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "image/image_io.h"
#include "support.h"

#define DGAUSS LENS_DIR "dgauss.50mm.dat"

/* Traces DGAUSS at 24x18 with 2 spp into PREFIX, with the extra options given (at most three,
   NULL-ended). */
static void trace(const char *prefix, const char *a, const char *b, const char *c)
{
    char *errtext = NULL;
    const int st = run_lens2pov(NULL, &errtext, "trace", DGAUSS, "--width", "24", "--height", "18",
                                "--spp", "2", "--quiet", "-o", prefix, a, b, c, (char *)NULL);
    cr_assert_eq(st, 0, "trace: %s", errtext ? errtext : "");
    free(errtext);
}

/* Renders ini through POV-Ray with a plain background, the include beside it. */
static void render(const char *dir, const char *ini, const char *inc)
{
    char wrapper[1024], cmd[4096];
    snprintf(wrapper, sizeof wrapper, "%s/wrapper.pov", dir);
    FILE *f = fopen(wrapper, "w");
    cr_assert_not_null(f);
    fprintf(f, "background { rgb <0.2, 0.5, 0.9> }\n#include \"%s\"\n", inc);
    fclose(f);
    snprintf(cmd, sizeof cmd, "povray '%s' +I'%s' -V -GA >/dev/null 2>&1", ini, wrapper);
    cr_assert_eq(system_povray(cmd), 0, "POV-Ray on %s", ini);
}

/* Two 24 x 18 pictures in dir, RGBA. */
static void read_both(const char *dir, const char *first, const char *second, float **a, float **b)
{
    int w, h, w2, h2;
    l2p_error err;
    cr_assert_eq(image_read_rgba(tmp_path(dir, first), &w, &h, a, &err), 0, "%s", err.text);
    cr_assert_eq(image_read_rgba(tmp_path(dir, second), &w2, &h2, b, &err), 0, "%s", err.text);
    cr_assert(w == 24 && h == 18 && w2 == w && h2 == h, "%dx%d and %dx%d", w, h, w2, h2);
}

/* PREFIX = DIR/p (tmp_path's buffers rotate, so it gets its own) traced as one table and
   rendered through POV-Ray. */
static void trace_and_render(const char *dir, char *prefix, size_t size)
{
    snprintf(prefix, size, "%s/p", dir);
    trace(prefix, NULL, NULL, NULL);
    render(dir, tmp_path(dir, "p.ini"), tmp_path(dir, "p.inc"));
}

/* A trace asked for chunks (--memory-mb) that needs only one names it PREFIX.c000: develop
   finds its render by that name (it looked for PREFIX.exr and failed), and the picture is the
   one developed from the render named outright. */
Test(trace_set, one_chunk_asked_for_is_developed_by_its_own_name)
{
    const char *dir = test_tmpdir();
    char prefix[1024];   /* tmp_path's buffers rotate */
    snprintf(prefix, sizeof prefix, "%s/p", dir);
    trace(prefix, "--memory-mb", "1024", NULL);
    cr_assert(file_exists(tmp_path(dir, "p.c000.ini")) && !file_exists(tmp_path(dir, "p.c001.ini")),
              "the trace is not one chunk of the chunked layout");
    render(dir, tmp_path(dir, "p.c000.ini"), tmp_path(dir, "p.c000.inc"));
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "a.exr"), (char *)NULL),
                 0, "develop: %s", errtext ? errtext : "");
    free(errtext);
    run_lens2pov_ok("develop, the render named", "develop", prefix, tmp_path(dir, "p.c000.exr"), "-o",
                    tmp_path(dir, "b.exr"), (char *)NULL);
    float *a, *b;
    read_both(dir, "a.exr", "b.exr", &a, &b);
    cr_assert(memcmp(a, b, sizeof *a * 4 * 24 * 18) == 0, "the two pictures differ");
    free(a), free(b);
}

/* Sampling pixel in chunks, then field, then pixel in one table: each trace leaves only its own
   includes and inis (and the map), whatever the earlier ones wrote; files of the same names that
   lens2pov did not write are kept. */
Test(trace_set, a_trace_removes_what_an_earlier_trace_of_the_prefix_left)
{
    const char *dir = test_tmpdir();
    char prefix[1024];   /* tmp_path's buffers rotate */
    snprintf(prefix, sizeof prefix, "%s/p", dir);
    char listing[4096];
    trace(prefix, "--memory-mb", "0.05", NULL);
    const int chunks = count_entries(dir, "p.c", listing, sizeof listing) / 2;
    cr_assert_gt(chunks, 2, "%s", listing);
    write_text(tmp_path(dir, "p.c999.inc"), "// the user's own\n");
    write_text(tmp_path(dir, "p.f007.ini"), "; the user's own\n");
    trace(prefix, "--sampling", "field", NULL);
    cr_expect_eq(count_entries(dir, "p.c", listing, sizeof listing), 1, "%s", listing);
    cr_expect(file_exists(tmp_path(dir, "p.c999.inc")));
    cr_expect(file_exists(tmp_path(dir, "p.f000.inc")) && file_exists(tmp_path(dir, "p.f000.ini")));
    cr_expect(file_exists(tmp_path(dir, "p.f007.ini")), "the user's file");
    trace(prefix, NULL, NULL, NULL);
    cr_expect_eq(count_entries(dir, "p.f", listing, sizeof listing), 1, "%s", listing);
    cr_expect(file_exists(tmp_path(dir, "p.inc")) && file_exists(tmp_path(dir, "p.ini")) &&
              file_exists(tmp_path(dir, "p.map")));
    trace(prefix, "--memory-mb", "0.05", NULL);   /* the one table's files go in turn */
    cr_expect_not(file_exists(tmp_path(dir, "p.inc")));
    cr_expect_not(file_exists(tmp_path(dir, "p.ini")));
    cr_expect_eq(count_entries(dir, "p.c", listing, sizeof listing), 2 * chunks + 1, "%s", listing);
}

/* A render from an earlier trace of the prefix, developed with the new map: a warning that names
   it; none for a render made after its trace. */
Test(trace_set, develop_warns_of_a_render_older_than_its_map)
{
    const char *dir = test_tmpdir();
    char prefix[1024];
    trace_and_render(dir, prefix, sizeof prefix);
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "a.png"), (char *)NULL),
                 0);
    cr_expect(!errtext || !strstr(errtext, "older than"), "%s", errtext);
    free(errtext);
    usleep(20000);   /* a later time on any file system that keeps hundredths */
    trace(prefix, "--seed", "2", NULL);
    errtext = NULL;
    /* refused too when the new table is shorter than the render's (the render's end is not
       black: a_render_through_the_scenes_own_camera_is_refused) */
    const int st = run_lens2pov(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "b.png"),
                                (char *)NULL);
    cr_assert(st == 0 || (st == 2 && strstr(errtext, "is not black")), "%d: %s", st, errtext);
    cr_expect(errtext && strstr(errtext, "p.exr is older than") && strstr(errtext, "p.map"), "%s",
              errtext ? errtext : "(nothing on stderr)");
    free(errtext);
}

/* With no .ini beside the map (moved away after rendering), the render that is there decides:
   PREFIX.exr for a table of one chunk traced without --memory-mb. */
Test(trace_set, a_one_table_render_is_found_without_its_ini)
{
    const char *dir = test_tmpdir();
    char prefix[1024];
    trace_and_render(dir, prefix, sizeof prefix);
    cr_assert_eq(unlink(tmp_path(dir, "p.ini")), 0);
    run_lens2pov_ok("develop without the ini", "develop", prefix, "-o", tmp_path(dir, "a.png"), (char *)NULL);
    cr_expect(file_exists(tmp_path(dir, "a.png")));
}

/* A scene that reads image_width and image_height (its background's colour here) sees the
   film's size when rendered by hand with the trace's .ini, as under render: both samplings
   give render's picture, bit for bit (the ini's Declare shadows POV-Ray's own, which would
   give the packed image's size; before, the hand render was blue where render's was red). */
Test(trace_set, a_hand_render_sees_the_films_size_as_render_does)
{
    const char *dir = test_tmpdir();
    char scene[1024], prefix[1024], cmd[4096];
    snprintf(scene, sizeof scene, "%s/aspect.pov", dir);
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1 }\n"
                      "camera { location <0, 0, -5> look_at <0, 0, 0> }\n"
                      "background { rgb (image_width = 24 & image_height = 18) ? <1, 0, 0> "
                      ": <0, 0, 1> }\n");
    const char *sampling[] = {"pixel", "field"};
    for (int s = 0; s < 2; s++) {
        snprintf(prefix, sizeof prefix, "%s/%s", dir, sampling[s]);
        run_lens2pov_ok("trace", "trace", DGAUSS, "--scene", scene, "--width", "24", "--height",
                        "18", "--spp", "2", "--quiet", "--sampling", sampling[s], "-o", prefix,
                        (char *)NULL);
        const bool field = s == 1;
        for (int r = 0; r < (field ? 100 : 1); r++) {   /* each render of the trace */
            char ini[1100], inc[1100], wrapper[1100];
            snprintf(ini, sizeof ini, field ? "%s.f%03d.ini" : "%s.ini", prefix, r);
            snprintf(inc, sizeof inc, field ? "%s.f%03d.inc" : "%s.inc", prefix, r);
            if (!file_exists(ini))
                break;
            snprintf(wrapper, sizeof wrapper, "%s/wrap-%s.pov", dir, sampling[s]);
            FILE *f = fopen(wrapper, "w");
            cr_assert_not_null(f);
            fprintf(f, "#include \"%s\"\n#include \"%s\"\n", scene, inc);
            fclose(f);
            snprintf(cmd, sizeof cmd, "povray '%s' +I'%s' -V -GA >/dev/null 2>&1", ini, wrapper);
            cr_assert_eq(system_povray(cmd), 0, "POV-Ray on %s", ini);
        }
        run_lens2pov_ok("develop", "develop", prefix, "-o", tmp_path(dir, "hand.exr"), (char *)NULL);
        run_lens2pov_ok("render", "render", scene, DGAUSS, "--width", "24", "--height", "18",
                        "--spp", "2", "--quiet", "--sampling", sampling[s], "-o",
                        tmp_path(dir, "render.exr"), (char *)NULL);
        float *a, *b;
        read_both(dir, "hand.exr", "render.exr", &a, &b);
        cr_expect(a[4 * (9 * 24 + 12)] > 0.5 && a[4 * (9 * 24 + 12) + 2] == 0.0,
                  "%s: the hand render's centre is not red: %g %g %g", sampling[s],
                  a[4 * (9 * 24 + 12)], a[4 * (9 * 24 + 12) + 1], a[4 * (9 * 24 + 12) + 2]);
        cr_expect(memcmp(a, b, sizeof *a * 4 * 24 * 18) == 0, "%s: the two pictures differ",
                  sampling[s]);
        free(a), free(b);
    }
}

/* A render made with the include before the scene's camera (POV-Ray keeps the last camera) is
   the scene's own picture of the packed image's size: the end of its last row, past the table,
   is not black as a render through the include leaves it, and develop refuses it, naming the
   render. The same render through the include develops. */
Test(trace_set, a_render_through_the_scenes_own_camera_is_refused)
{
    const char *dir = test_tmpdir();
    char prefix[1024], wrapper[1100], cmd[4096];
    snprintf(prefix, sizeof prefix, "%s/p", dir);
    trace(prefix, NULL, NULL, NULL);
    snprintf(wrapper, sizeof wrapper, "%s/before.pov", dir);
    FILE *f = fopen(wrapper, "w");
    cr_assert_not_null(f);
    fprintf(f, "#include \"%s/p.inc\"\ncamera { location <0, 0, -5> look_at 0 }\n"
               "background { rgb <0.2, 0.5, 0.9> }\n", dir);
    fclose(f);
    snprintf(cmd, sizeof cmd, "povray '%s/p.ini' +I'%s' -V -GA >/dev/null 2>&1", dir, wrapper);
    cr_assert_eq(system_povray(cmd), 0, "POV-Ray on %s", wrapper);
    char *errtext = NULL;
    cr_expect_eq(run_lens2pov(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "a.png"),
                              (char *)NULL), 2, "%s", errtext);
    char want[1200];
    snprintf(want, sizeof want, "%s/p.exr: pixel (", dir);
    cr_expect(strstr(errtext, want) && strstr(errtext, "POV-Ray keeps the last camera"), "%s", errtext);
    cr_expect(!file_exists(tmp_path(dir, "a.png")));
    free(errtext);
    render(dir, tmp_path(dir, "p.ini"), tmp_path(dir, "p.inc"));
    run_lens2pov_ok("develop", "develop", prefix, "-o", tmp_path(dir, "b.png"), (char *)NULL);
}

/* A render POV-Ray wrote as PNG (+FN after the trace's .ini) has its highlights clipped:
   develop says so, naming it, and still develops it. */
Test(trace_set, a_render_that_is_not_exr_is_warned_of)
{
    const char *dir = test_tmpdir();
    char prefix[1024], wrapper[1100], cmd[4096], png[1100];
    snprintf(prefix, sizeof prefix, "%s/p", dir);
    trace(prefix, NULL, NULL, NULL);
    snprintf(wrapper, sizeof wrapper, "%s/wrapper.pov", dir);
    write_text(wrapper, "background { rgb 3 }\n#include \"p.inc\"\n");
    snprintf(png, sizeof png, "%s/p.png", dir);
    snprintf(cmd, sizeof cmd, "cd '%s' && povray p.ini +I'%s' +FN +O'%s' -V -GA >/dev/null 2>&1",
             dir, wrapper, png);
    cr_assert_eq(system_povray(cmd), 0, "POV-Ray on %s", wrapper);
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "develop", prefix, png, "-o",
                              tmp_path(dir, "a.png"), (char *)NULL), 0, "%s", errtext);
    char want[1200];
    snprintf(want, sizeof want, "warning: %s is not an OpenEXR render", png);
    cr_expect(strstr(errtext, want), "%s", errtext);
    free(errtext);
}

/* render renders a chunk as soon as it is written, before the map, which is renamed into place
   last: the map takes the time the table was begun, so that its own renders are never older
   than it (develop of a kept folder warned of every chunk rendered before the trace ended). */
Test(trace_set, a_kept_renders_map_is_not_newer_than_its_renders)
{
    const char *dir = test_tmpdir();
    char keep[1024], scene[1100];
    snprintf(keep, sizeof keep, "%s/kept", dir);
    snprintf(scene, sizeof scene, "%s/s.pov", dir);
    write_text(scene, "background { rgb 0.5 }\n");
    run_lens2pov_ok("render", "render", scene, DGAUSS, "--width", "96", "--height", "72", "--spp",
                    "8", "--sampling", "pixel", "--memory-mb", "2", "--keep-temp", keep, "-q", "-o",
                    tmp_path(dir, "a.png"), (char *)NULL);
    struct stat map, first;
    cr_assert_eq(stat(tmp_path(keep, "rays.map"), &map), 0);
    cr_assert_eq(stat(tmp_path(keep, "rays.c000.inc"), &first), 0, "not chunked");
    cr_assert(file_exists(tmp_path(keep, "rays.c001.inc")), "one chunk only");
    cr_expect(map.st_mtim.tv_sec < first.st_mtim.tv_sec ||
              (map.st_mtim.tv_sec == first.st_mtim.tv_sec &&
               map.st_mtim.tv_nsec <= first.st_mtim.tv_nsec),
              "the map is newer than the first chunk's include");
    char prefix[1100], *errtext = NULL;
    snprintf(prefix, sizeof prefix, "%s/rays", keep);
    cr_assert_eq(run_lens2pov(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "b.png"),
                              (char *)NULL), 0, "%s", errtext);
    cr_expect(!strstr(errtext, "older than"), "%s", errtext);
    free(errtext);
}
