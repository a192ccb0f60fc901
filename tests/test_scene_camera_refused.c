/* The scene cameras lens2pov refuses, and the scene's own faults found reading them: exit 2,
   named in the file and line where they stand, and nothing written. */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "scene_markers.h"
#include "support.h"

/* The scene, written into a fresh folder as name, is refused (exit 2) with a message that
   names it and holds why, and no picture is written; its path into scene. Returns the message
   (malloc'd). */
static char *expect_refused(const char *name, const char *text, const char *why, char scene[512])
{
    const char *dir = test_tmpdir();
    char out[512];
    snprintf(scene, 512, "%s/%s", dir, name);
    snprintf(out, sizeof out, "%s/out.png", dir);
    write_text(scene, text);
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "1", "-q", "-o", out);
    cr_expect_eq(st, 2, "%s", errtext ? errtext : "");
    cr_expect(errtext && strstr(errtext, scene) && strstr(errtext, why), "expected '%s' in: %s",
              why, errtext ? errtext : "");
    cr_expect(!file_exists(out), "an output was written");
    return errtext;
}

/* A rotation written to 4 decimals, as exporters write matrices, is a rotation: its vectors
   are skewed by about 1e-4, a shear no picture shows. A shear of 1% is refused. */
Test(scene_camera, a_matrix_rounded_to_four_decimals_is_a_rotation)
{
    expect_markers_as_povray(MARKERS_HEAD
                             "camera { location Lift(Eye) - Target look_at 0 angle 40\n"
                             "  matrix <0.9659, 0, 0.2588, 0, 1, 0, -0.2588, 0, 0.9659, 0, 0, 0>\n"
                             "  translate Target }\n");
    char scene[512];
    free(expect_refused("sheared.pov", MARKERS_HEAD "camera { location <0, 1, -4> look_at 0\n"
                        "  matrix <1, 0, 0, 0.01, 1, 0, 0, 0, 1, 0, 0, 0> }\n", "not perpendicular",
                        scene));
}

Test(scene_camera, orthographic_is_refused)
{
    char scene[512];
    free(expect_refused("ortho.pov", MARKERS_HEAD "camera { orthographic location <0, 1, -4> "
                        "look_at 0 }\n", "orthographic", scene));
}

/* A camera item POV-Ray evaluates to nan (its clock in an animation of one frame) is the
   scene's fault: exit 2, naming the item, the statement's line and the clock. */
Test(scene_camera, a_camera_that_evaluates_to_nan_is_refused)
{
    const char *dir = test_tmpdir();
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/anim.pov", dir);
    snprintf(out, sizeof out, "%s/a.png", dir);
    write_text(scene, "#version 3.7;\nsphere { 0, 1 pigment { rgb 1 } }\n"
                      "camera { location <clock, 0, -5>\n look_at 0 }\n");
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "1", "-q", "-o",
                       out, "--", "+KFI3", "+KFF3");
    cr_expect_eq(st, 2, "exit %d: %s", st, errtext);
    char where[600];
    snprintf(where, sizeof where, "lens2pov: %s:3: the camera's location is not a finite number",
             scene);
    cr_expect(errtext && strncmp(errtext, where, strlen(where)) == 0, "%s", errtext);
    cr_expect(errtext && strstr(errtext, "clock"), "%s", errtext);
    free(errtext);
}

/* An #include of a file that cannot be found may hold a camera: POV-Ray is asked, and its
   error is the answer (exit 2, the scene's line), not the default camera, whose 67 degrees
   the double-Gauss cannot reach. */
Test(scene_camera, a_missing_include_is_reported_not_taken_for_no_camera)
{
    const char *dir = test_tmpdir();
    char scene[512], out[512];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(out, sizeof out, "%s/a.png", dir);
    write_text(scene, "#version 3.7;\n#include \"mycam.inc\"\nPlaceCam(<0, 1, -5>)\n");
    char *errtext = NULL;
    const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "1", "--angle",
                       "scene", "-q", "-o", out);
    cr_expect_eq(st, 2, "exit %d: %s", st, errtext);
    char where[600];
    snprintf(where, sizeof where, "lens2pov: %s:2: ", scene);
    cr_expect(errtext && strncmp(errtext, where, strlen(where)) == 0, "%s", errtext);
    cr_expect(errtext && strstr(errtext, "mycam.inc"), "%s", errtext);
    free(errtext);
}

/* An item that a macro gives: POV-Ray reads the scene, but lens2pov cannot print the items of
   its camera. Said so, with POV-Ray's complaint about the copy, and the camera given on the
   command line renders it. */
Test(scene_camera, an_item_from_a_macro_asks_for_the_camera_on_the_command_line)
{
    char scene[512], out[600];
    char *errtext = expect_refused("macro.pov", MARKERS_HEAD "#macro Aim() look_at Target #end\n"
                                   "camera { location <0, 1, -4> Aim() }\n",
                                   "POV-Ray reads the scene", scene);
    cr_expect(errtext && strstr(errtext, "look_at") && strstr(errtext, "--location"), "%s",
              errtext ? errtext : "");
    free(errtext);
    snprintf(out, sizeof out, "%s.png", scene);
    cr_expect_eq(L2P(NULL, NULL, "render", scene, DGAUSS, SIZE, "--spp", "1", "-q", "-o", out,
                     "--location", "0,1,-4", "--look-at", "0.2,0.5,0"), 0);
    cr_expect(file_exists(out));
}

/* Any other directive inside the block, a conditional that does not stand between items (in
   an expression, or before a word that is no item), a type chosen by a conditional that runs,
   or a word that is no camera item is refused naming the statement's line (exit 2); a type in
   a branch that does not run is not read. POV-Ray's error in a block written over several
   lines names the line it is on. */
Test(scene_camera, other_directives_and_unknown_words_are_refused)
{
    const char *dir = test_tmpdir();
    static const struct {
        const char *camera, *why;
        int status, line;
    } cases[] = {
        {"camera { location <0, 1, -4>\n  #declare A = 1; look_at 0 }\n", "#warning", 2, 1},
        {"camera { 3 location <0, 1, -4>\n  look_at 0 }\n", "not a camera", 2, 1},
        {"camera { location <0, 1, -4>\n  #if (0) bogus 3 #end look_at 0 }\n", "between", 2, 1},
        {"camera { location <0, 1, -4> angle #if (1) 40 #else 50 #end }\n", "between", 2, 1},
        {"camera { location <0, #if (1) 1 #else 2 #end, -4> }\n", "between", 2, 1},
        {"camera { location <0, 1, -4> #if (1) orthographic #end }\n", "conditional", 2, 1},
        {"camera { location <0, 1, -4> #if (0) orthographic #end look_at 0 }\n", NULL, 0, 0},
        {"\ncamera\n{\n  #if (1)\n    angle 40\n  #else\n    angle 50\n  #end\n"
         "  look_at Undeclared\n}\n", "Undeclared", 2, 9},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        char scene[512], out[512], where[600];
        snprintf(scene, sizeof scene, "%s/d%zu.pov", dir, k);
        snprintf(out, sizeof out, "%s/d%zu.png", dir, k);
        write_text(scene, cases[k].camera);
        char *errtext = NULL;
        const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "1", "-q",
                           "-o", out);
        snprintf(where, sizeof where, "lens2pov: %s:%d: ", scene, cases[k].line);
        cr_expect_eq(st, cases[k].status, "case %zu: %s", k, errtext ? errtext : "");
        if (cases[k].why)
            cr_expect(errtext && !strncmp(errtext, where, strlen(where)) &&
                          strstr(errtext, cases[k].why),
                      "case %zu: expected '%s' and '%s' in: %s", k, where, cases[k].why,
                      errtext ? errtext : "");
        free(errtext);
    }
}

/* What is wrong with a camera in an included file is reported in that file's name and line:
   a camera lens2pov cannot stand in for (exit 2), and POV-Ray's own error. Nothing is
   written; with explicit placement the first scene renders. */
Test(scene_camera, an_included_cameras_faults_name_its_file)
{
    const char *dir = test_tmpdir();
    char scene[512], broken[512], inc[512], bad[512], out[512];
    snprintf(scene, sizeof scene, "%s/inc.pov", dir);
    snprintf(broken, sizeof broken, "%s/broken.pov", dir);
    snprintf(inc, sizeof inc, "%s/ortho.inc", dir);
    snprintf(bad, sizeof bad, "%s/bad.inc", dir);
    snprintf(out, sizeof out, "%s/out.png", dir);
    write_text(inc, "\n\ncamera { orthographic location <0, 1, -4> look_at 0 }\n");
    write_text(bad, "\ncamera { location <0, 1, -4> look_at Undeclared }\n");
    write_text(scene, MARKERS_HEAD "#include \"ortho.inc\"\n");
    write_text(broken, MARKERS_HEAD "#include \"bad.inc\"\n");
    char *errtext = NULL, where[600];
    int st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "1", "-q", "-o", out);
    snprintf(where, sizeof where, "lens2pov: %s:3: ", inc);
    cr_expect_eq(st, 2, "%s", errtext ? errtext : "");
    cr_expect(errtext && !strncmp(errtext, where, strlen(where)) && strstr(errtext, "orthographic"),
              "expected '%s' in: %s", where, errtext ? errtext : "");
    free(errtext);
    st = L2P(NULL, &errtext, "render", broken, DGAUSS, SIZE, "--spp", "1", "-q", "-o", out);
    snprintf(where, sizeof where, "lens2pov: %s:2: ", bad);
    cr_expect_neq(st, 0);
    cr_expect(errtext && !strncmp(errtext, where, strlen(where)) && strstr(errtext, "Undeclared"),
              "expected '%s' in: %s", where, errtext ? errtext : "");
    free(errtext);
    struct stat sb;
    cr_expect(stat(out, &sb) != 0, "an output was written");
    st = L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "1", "--location", "0,1,-4",
             "--look-at", "0,0,0", "-q", "-o", out);
    cr_expect_eq(st, 0, "%s", errtext ? errtext : "");
    free(errtext);
}

/* A camera statement without its '}' is the scene's fault, whether its items are literals
   (read without POV-Ray) or not: trace --scene is refused (exit 2) with POV-Ray's own message
   at the statement, not traced with the items read so far. */
Test(scene_camera, an_unclosed_camera_is_the_scenes_fault)
{
    static const char *const scenes[] = {
        "#version 3.7;\ncamera { location <0, 1, -5> look_at <0, 1, 0>\n",
        "camera { location 5 look_at 0\n",
    };
    for (int k = 0; k < 2; k++) {
        const char *dir = test_tmpdir();
        const char *scene = tmp_path(dir, "open.pov");
        write_text(scene, scenes[k]);
        char *errtext = NULL;
        const int st = L2P(NULL, &errtext, "trace", DGAUSS, "--scene", scene, SIZE, "--spp", "1",
                           "-q", "-o", tmp_path(dir, "t"));
        cr_expect_eq(st, 2, "scene %d: exit %d: %s", k, st, errtext ? errtext : "");
        cr_expect(errtext && strstr(errtext, scene) && strstr(errtext, "No matching }"),
                  "scene %d: %s", k, errtext ? errtext : "");
        cr_expect_not(file_exists(tmp_path(dir, "t.map")));
        free(errtext);
    }
}
