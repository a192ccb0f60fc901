/* The scene-camera tests' markers (scene_markers.h). */
#include "scene_markers.h"

#include <criterion/criterion.h>
#include <criterion/logging.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* POV-Ray's own picture of the scene, with the option opt ("" for none). */
static void povray_render(const char *dir, const char *scene, const char *out, const char *opt)
{
    char cmd[1600];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +I%s +O%s +W64 +H48 +FN -A -D -V -GA %s >povray.log 2>&1", dir,
             scene, out, opt);
    cr_assert_eq(system_povray(cmd), 0, "%s", cmd);
}

void expect_markers_in(const char *dir, const char *scene_text, const char *library)
{
    char scene[512], own[512], lens[512], opt[600] = "";
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(own, sizeof own, "%s/own.png", dir);
    snprintf(lens, sizeof lens, "%s/lens.png", dir);
    if (library)
        snprintf(opt, sizeof opt, "+L%s", library);
    write_text(scene, scene_text);
    povray_render(dir, "scene.pov", "own.png", opt);
    char *errtext = NULL;
    const int st = library ? L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "4",
                                 "--angle", "scene", "--jobs", "1", "-q", "-o", lens, "--", opt)
                           : L2P(NULL, &errtext, "render", scene, DGAUSS, SIZE, "--spp", "4",
                                 "--angle", "scene", "--jobs", "1", "-q", "-o", lens);
    cr_assert_eq(st, 0, "render failed: %s", errtext ? errtext : "");
    free(errtext);
    for (int c = 0; c < 3; c++) {
        const marker_centroid a = image_marker(own, c), b = image_marker(lens, c);
        cr_assert(a.found && b.found, "marker %d missing (POV-Ray %d, lens %d)", c, a.found, b.found);
        cr_log_info("marker %d: POV-Ray (%.2f, %.2f), lens (%.2f, %.2f)", c, a.x, a.y, b.x, b.y);
        /* The lens has a little distortion and depth of field; a pixel is the tolerance. */
        cr_expect(fabs(a.x - b.x) < 1.0 && fabs(a.y - b.y) < 1.0,
                  "marker %d: POV-Ray (%.2f, %.2f), lens (%.2f, %.2f)", c, a.x, a.y, b.x, b.y);
    }
}

void expect_markers_as_povray(const char *scene_text)
{
    expect_markers_in(test_tmpdir(), scene_text, NULL);
}
