/* A field render from files: trace --sampling field writes the field map and each render's
   include and ini, POV-Ray renders them as a user would, develop makes the picture; it is the
   picture render --sampling field makes, pixel for pixel. The map round-trips and refuses what
   is not one. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "field/field_develop.h"
#include "field/fieldmap.h"
#include "image/image_io.h"
#include "support.h"

static const char *SCENE =
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
    "light_source { <-3, 5, -4> rgb 1 }\n"
    "sky_sphere { pigment { gradient y color_map { [0 rgb <0.6,0.7,0.9>] [1 rgb <0.1,0.2,0.6>] } } }\n"
    "plane { y, 0 pigment { checker rgb 0.9 rgb 0.1 scale 0.5 } finish { ambient 0.2 diffuse 0.8 } }\n"
    "sphere { <0.3, 0.8, 0.5>, 0.8 pigment { rgb <0.8, 0.2, 0.1> } finish { ambient 0.2 diffuse 0.8 } }\n";

static float *read_picture(const char *path)
{
    int w, h;
    float *px;
    l2p_error err;
    cr_assert_eq(image_read_rgba(path, &w, &h, &px, &err), 0, "%s", err.text);
    cr_assert(w == 40 && h == 30, "%s is %dx%d", path, w, h);
    return px;
}

/* Traces, renders each ini through POV-Ray with a wrapper that includes the scene and the
   render's include (as the README says), develops; returns the number of renders. */
static int by_hand(const char *dir, const char *lens, const char *out)
{
    const char *prefix = tmp_path(dir, "ft");
    char *errtext = NULL;
    const int st = run_lens2pov(NULL, &errtext, "trace", lens, "--width", "40", "--height", "30",
                                "--spp", "6", "--sampling", "field", "--location", "0,1,-4",
                                "--look-at", "0,0.6,0", "--quiet", "-o", prefix, (char *)NULL);
    cr_assert_eq(st, 0, "trace: %s", errtext ? errtext : "");
    free(errtext);
    int renders = 0;
    for (;; renders++) {
        char ini[1024], inc[1024], wrapper[1024], cmd[4096];
        snprintf(ini, sizeof ini, "%s.f%03d.ini", prefix, renders);
        snprintf(inc, sizeof inc, "%s.f%03d.inc", prefix, renders);
        if (!file_exists(ini))
            break;
        snprintf(wrapper, sizeof wrapper, "%s/wrapper%d.pov", dir, renders);
        FILE *f = fopen(wrapper, "w");
        fprintf(f, "#include \"%s/scene.pov\"\n#include \"%s\"\n", dir, inc);
        fclose(f);
        snprintf(cmd, sizeof cmd, "povray '%s' +I'%s' -V -GA >/dev/null 2>&1", ini, wrapper);
        cr_assert_eq(system_povray(cmd), 0, "POV-Ray on %s", ini);
    }
    cr_assert(renders > 0, "trace wrote no render's ini");
    errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "develop", prefix, "-o", out, (char *)NULL), 0,
                 "develop: %s", errtext ? errtext : "");
    free(errtext);
    return renders;
}

/* Through a lens without dispersion and one with it (the map's bands). */
Test(field_files, trace_povray_develop_is_render)
{
    const char *lenses[] = {LENS_DIR "dgauss.50mm.dat", LENS_DIR "cooke-triplet.50mm.dat"};
    for (int i = 0; i < 2; i++) {
        const char *dir = test_tmpdir();
        write_text(tmp_path(dir, "scene.pov"), SCENE);
        const char *hand = tmp_path(dir, "hand.exr"), *whole = tmp_path(dir, "whole.exr");
        by_hand(dir, lenses[i], hand);
        run_lens2pov_ok("render", "render", tmp_path(dir, "scene.pov"), lenses[i], "--width", "40",
                        "--height", "30", "--spp", "6", "--sampling", "field", "--location",
                        "0,1,-4", "--look-at", "0,0.6,0", "--quiet", "-o", whole, NULL);
        float *a = read_picture(hand), *b = read_picture(whole);
        int differ = 0;
        for (int k = 0; k < 4 * 40 * 30; k++)
            differ += a[k] != b[k];
        cr_expect_eq(differ, 0, "%s: %d values differ between trace + POV-Ray + develop and render",
                     lenses[i], differ);
        double sum = 0;
        for (int k = 0; k < 4 * 40 * 30; k++)
            sum += a[k];
        cr_expect(sum > 100, "the picture is not black (%g)", sum);
        free(a), free(b);
    }
}

/* Developing a render at a time, the pictures given last first, makes the picture develop
   makes of them all at once, bit for bit (the renders are added in their order whatever order
   they come in); a render given twice is refused. */
Test(field_files, developing_a_render_at_a_time_is_developing_all)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *all = tmp_path(dir, "all.exr"), *each = tmp_path(dir, "each.exr");
    const int renders = by_hand(dir, LENS_DIR "dgauss.50mm.dat", all);
    field_map m;
    l2p_error err;
    cr_assert_eq(field_map_read(tmp_path(dir, "ft.map"), &m, &err), 0, "%s", err.text);
    cr_assert_eq(m.renders, renders);
    field_developer d;
    cr_assert_eq(field_develop_start(&d, &m, &err), 0, "%s", err.text);
    for (int r = renders - 1; r >= 0; r--) {
        char path[1024];
        snprintf(path, sizeof path, "%s.f%03d.exr", tmp_path(dir, "ft"), r);
        cr_assert_eq(field_develop_add(&d, r, path, &err), 0, "%s", err.text);
        cr_expect_eq(d.next, r ? 0 : renders, "render %d given: %d added", r, d.next);
        cr_expect_eq(field_develop_add(&d, r, path, &err), L2P_FAILED, "render %d twice", r);
    }
    cr_assert_eq(field_develop_finish(&d, each, &err), 0, "%s", err.text);
    field_develop_free(&d);
    field_map_free(&m);
    float *a = read_picture(all), *b = read_picture(each);
    cr_expect(memcmp(a, b, sizeof *a * 4 * 40 * 30) == 0, "the pictures differ");
    free(a), free(b);
}

/* With remove_pictures, as render's own work folder has it, each picture goes once it is in
   the sums and not before (a picture that came early waits for those before it), and the
   picture is the one developing them all makes. */
Test(field_files, a_developed_picture_goes_once_it_is_added)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *all = tmp_path(dir, "all.exr"), *each = tmp_path(dir, "each.exr");
    const int renders = by_hand(dir, LENS_DIR "dgauss.50mm.dat", all);
    cr_assert_geq(renders, 2, "one render shows no picture waiting");
    field_map m;
    l2p_error err;
    cr_assert_eq(field_map_read(tmp_path(dir, "ft.map"), &m, &err), 0, "%s", err.text);
    field_developer d;
    cr_assert_eq(field_develop_start(&d, &m, &err), 0, "%s", err.text);
    d.remove_pictures = true;
    char path[64][1024];
    cr_assert_leq(renders, 64);
    for (int r = 0; r < renders; r++)
        snprintf(path[r], sizeof path[r], "%s.f%03d.exr", tmp_path(dir, "ft"), r);
    for (int r = renders - 1; r >= 0; r--) {
        cr_assert_eq(field_develop_add(&d, r, path[r], &err), 0, "%s", err.text);
        for (int q = r; q < renders; q++)
            cr_expect_eq(file_exists(path[q]), r > 0, "render %d given: picture %d %s", r, q,
                         r > 0 ? "gone before it was added" : "still there once added");
    }
    cr_assert_eq(field_develop_finish(&d, each, &err), 0, "%s", err.text);
    field_develop_free(&d);
    field_map_free(&m);
    float *a = read_picture(all), *b = read_picture(each);
    cr_expect(memcmp(a, b, sizeof *a * 4 * 40 * 30) == 0, "the pictures differ");
    free(a), free(b);
}

/* develop refuses renders that do not belong to the map: too few, and one of another size,
   naming it; nothing is written. */
Test(field_files, develop_refuses_renders_of_another_map)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const int renders = by_hand(dir, LENS_DIR "dgauss.50mm.dat", tmp_path(dir, "hand.exr"));
    const char *prefix = tmp_path(dir, "ft"), *out = tmp_path(dir, "bad.exr");
    char *errtext = NULL, first[1024], other[1024];
    snprintf(first, sizeof first, "%s.f000.exr", prefix);
    cr_assert_eq(run_lens2pov(NULL, &errtext, "develop", prefix, first, "-o", out, (char *)NULL), 2);
    if (renders > 1)
        cr_expect(strstr(errtext, "render"), "%s", errtext);
    free(errtext);
    /* every render named, the first replaced by a picture of another size */
    snprintf(other, sizeof other, "%s/small.exr", dir);
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "oiiotool '%s' --resize 5x5 -o '%s'", first, other);
    cr_assert_eq(system(cmd), 0);
    char *args[16] = {"develop", (char *)prefix, other};
    int n = 3;
    char names[8][1024];
    for (int r = 1; r < renders && r < 8; r++) {
        snprintf(names[r], sizeof names[r], "%s.f%03d.exr", prefix, r);
        args[n++] = names[r];
    }
    args[n++] = "-o", args[n++] = (char *)out, args[n] = NULL;
    errtext = NULL;
    cr_assert_eq(run_lens2pov_argv(NULL, &errtext, args), 2);
    cr_expect(strstr(errtext, "small.exr") && strstr(errtext, "not render 0"), "%s", errtext);
    free(errtext);
    cr_expect(!file_exists(out));
}

/* The map's bytes: a truncated map, or one whose first line is not the field map's, is refused
   with the file's name; a sub-image placed outside its render is refused. */
Test(field_files, the_map_is_checked)
{
    const char *dir = test_tmpdir();
    const char *prefix = tmp_path(dir, "ft"), *path = tmp_path(dir, "ft.map");
    run_lens2pov_ok("trace", "trace", LENS_DIR "dgauss.50mm.dat", "--width", "40", "--height", "30",
                    "--spp", "3", "--sampling", "field", "--quiet", "-o", prefix, NULL);
    field_map m;
    l2p_error err;
    cr_assert_eq(field_map_read(path, &m, &err), 0, "%s", err.text);
    cr_expect(m.header.spp == 3 && m.renders >= 1 && m.header.crop_x1 == 40);
    float w[40 * 30];
    cr_assert_eq(field_map_weights(&m, 2, w, &err), 0, "%s", err.text);
    int passing = 0;
    for (int i = 0; i < 40 * 30; i++)
        passing += w[i] > 0;
    cr_expect(passing > 40 * 30 / 2, "%d pixels weighted", passing);
    field_map_free(&m);

    size_t length;
    char *bytes = read_text(path, &length);
    write_bytes(path, bytes, length - 1);   /* truncated */
    cr_assert_eq(field_map_read(path, &m, &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, "ft.map") && strstr(err.text, "truncated"), "%s", err.text);
    bytes[9] = 'X';   /* lens2pov-Xieldmap */
    write_bytes(path, bytes, length);
    cr_assert_eq(field_map_read(path, &m, &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, "field map"), "%s", err.text);
    bytes[9] = 'f';
    bytes[18] = '9';   /* lens2pov-fieldmap 9: still a field map to develop, of another version */
    write_bytes(path, bytes, length);
    cr_expect(field_map_is_one(path));
    char *errtext = NULL;
    cr_expect_eq(run_lens2pov(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "x.png"), (char *)NULL), 2);
    cr_expect(errtext && strstr(errtext, "'lens2pov-fieldmap 1'"), "%s", errtext ? errtext : "");
    free(errtext);
    bytes[18] = '1';
    /* sub-image 0's dx, in the last table: its quadruple is 16 * spp bytes from the end */
    bytes[length - 16 * 3 + 4] = (char)0xff;
    bytes[length - 16 * 3 + 5] = (char)0xff;
    write_bytes(path, bytes, length);
    cr_assert_eq(field_map_read(path, &m, &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, "sub-image 0"), "%s", err.text);
    free(bytes);
}

/* render --adaptive with --keep-temp: the work folder's map is a map of pieces (version 2),
   and develop makes render's picture from it and the renders, pixel for pixel. The map's
   bytes are checked as version 1's are: truncated, a sub-image outside the crop, outside its
   render. */
Test(field_files, an_adaptive_render_develops_again_from_its_work_folder)
{
    const char *dir = test_tmpdir();
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    const char *work = tmp_path(dir, "work"), *rendered = tmp_path(dir, "render.exr");
    run_lens2pov_ok("render", "render", tmp_path(dir, "scene.pov"), LENS_DIR "telephoto.250mm.dat",
                    "--width", "40", "--height", "30", "--spp", "16", "--adaptive", "--location",
                    "0,1,-4", "--look-at", "0,0.6,0", "--focus-distance", "4", "--keep-temp", work,
                    "--quiet", "-o", rendered, NULL);
    char prefix[1024], path[1100];
    snprintf(prefix, sizeof prefix, "%s/field", work);
    snprintf(path, sizeof path, "%s.map", prefix);
    field_map m;
    l2p_error err;
    cr_assert_eq(field_map_read(path, &m, &err), 0, "%s", err.text);
    cr_expect(m.header.spp == 16 && m.piece && m.subimages > 4, "spp %d, %d sub-images",
              m.header.spp, m.subimages);
    const int subimages = m.subimages;
    field_map_free(&m);
    const char *developed = tmp_path(dir, "developed.exr");
    run_lens2pov_ok("develop", "develop", prefix, "-o", developed, NULL);
    float *a = read_picture(rendered), *b = read_picture(developed);
    for (int i = 0; i < 40 * 30 * 4; i++)
        cr_assert(a[i] == b[i], "pixel %d, channel %d: render %g, develop %g", i / 4, i % 4, a[i], b[i]);
    free(a), free(b);

    size_t length;
    char *bytes = read_text(path, &length);
    write_bytes(path, bytes, length - 1);
    cr_assert_eq(field_map_read(path, &m, &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, "field.map") && strstr(err.text, "truncated"), "%s", err.text);
    /* the last sub-image's record, after the header and the renders' sizes: dx 4 bytes in,
       x0 16 */
    const char *renders = strstr(bytes, "\nrenders ");
    cr_assert_not_null(renders);
    const long long record = SAMPLEMAP_HEADER_BYTES + 8LL * atoi(renders + 9) + 32LL * (subimages - 1);
    char *changed = malloc(length);
    memcpy(changed, bytes, length);
    changed[record + 16] = 40;   /* x0 = 40: the crop is 40 wide */
    write_bytes(path, changed, length);
    cr_assert_eq(field_map_read(path, &m, &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, "does not lie in the crop"), "%s", err.text);
    memcpy(changed, bytes, length);
    changed[record + 4] = (char)0xf0;   /* dx far beyond its render */
    write_bytes(path, changed, length);
    cr_assert_eq(field_map_read(path, &m, &err), L2P_BAD_INPUT);
    cr_expect(strstr(err.text, "does not lie in a render"), "%s", err.text);
    free(changed), free(bytes);
}
