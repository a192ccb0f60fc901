/* The image library (lens2pov-image-io.so) is loaded on the first image read or write, once a
   process: these tests point LENS2POV_IMAGE_IO at a missing file for lens2pov child processes,
   so that the loader runs afresh there and the test runner's own image reads are unaffected. */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "support.h"

#define DGAUSS LENS_DIR "dgauss.50mm.dat"
#define MISSING_LIBRARY "/nonexistent/lens2pov-test/lens2pov-image-io.so"

static void without_library(void)
{
    cr_assert_eq(setenv("LENS2POV_IMAGE_IO", MISSING_LIBRARY, 1), 0);
}

/* Each test runs in a process of its own, except under --no-fork. */
static void restore_library(void)
{
    unsetenv("LENS2POV_IMAGE_IO");
}

TestSuite(image_io_loader, .init = without_library, .fini = restore_library);

/* trace needs no image; develop's first image is the render t.exr, which does not exist either:
   its exit 1 (a missing render would be 2) shows that loading the library failed first. */
Test(image_io_loader, missing_library_fails_naming_its_path)
{
    const char *dir = test_tmpdir();
    const char *prefix = tmp_path(dir, "t"), *picture = tmp_path(dir, "t.png");
    char *errtext = NULL;
    int st = run_lens2pov(NULL, &errtext, "trace", DGAUSS, "--width", "8", "--height", "6",
                          "--spp", "1", "-o", prefix, "--quiet", NULL);
    cr_assert_eq(st, 0, "trace without the library: exit %d: %s", st, errtext);
    free(errtext);
    st = run_lens2pov(NULL, &errtext, "develop", prefix, "-o", picture, NULL);
    cr_assert_eq(st, 1, "exit %d: %s", st, errtext);
    cr_assert(strstr(errtext, "cannot load the image library"), "%s", errtext);
    cr_assert(strstr(errtext, MISSING_LIBRARY), "the path tried: %s", errtext);
    cr_assert(strstr(errtext, "No such file"), "dlerror's reason: %s", errtext);
    free(errtext);
    struct stat s;
    cr_assert_neq(stat(picture, &s), 0, "no picture written");
    const char *outputs[] = {"t.inc", "t.ini", "t.map"};
    for (size_t i = 0; i < sizeof outputs / sizeof outputs[0]; i++)
        unlink(tmp_path(dir, outputs[i]));
    cr_assert_eq(rmdir(dir), 0, "nothing else left in %s", dir);
}

Test(image_io_loader, info_runs_without_the_library)
{
    char *errtext = NULL;
    const int st = run_lens2pov(NULL, &errtext, "info", DGAUSS, NULL);
    cr_assert_eq(st, 0, "exit %d: %s", st, errtext);
    free(errtext);
}

/* render needs the library only to develop, at the very end, and loads it while it traces: it
   must fail before POV-Ray (which would report the scene's error) and commit nothing of the
   trace (the --rays CSV). */
Test(image_io_loader, render_fails_before_povray_and_writes_nothing)
{
    const char *dir = test_tmpdir();
    const char *scene = tmp_path(dir, "s.pov"), *picture = tmp_path(dir, "s.png");
    const char *csv = tmp_path(dir, "rays.csv");
    write_text(scene, "#version 3.7;\nbackground { rgb 1 \n");
    char *errtext = NULL;
    const int st = run_lens2pov(NULL, &errtext, "render", scene, DGAUSS, "--width", "8",
                                "--height", "6", "--spp", "1", "--rays", csv, "-o", picture, NULL);
    cr_assert_eq(st, 1, "exit %d: %s", st, errtext);
    cr_assert(strstr(errtext, "cannot load the image library"), "%s", errtext);
    cr_assert(!strstr(errtext, "s.pov"), "POV-Ray did not run: %s", errtext);
    struct stat s;
    cr_assert_neq(stat(csv, &s), 0, "no trace committed");
    cr_assert_neq(stat(picture, &s), 0, "no picture written");
    free(errtext);
}

/* The point of the library: the executable itself does not link OpenImageIO (ldd lists what
   the dynamic loader would map at start-up). */
Test(image_io_loader, executable_does_not_link_openimageio)
{
    const char *bin = getenv("LENS2POV");
    char command[4096];
    snprintf(command, sizeof command, "ldd '%s' 2>&1", bin && *bin ? bin : "build/lens2pov");
    FILE *p = popen(command, "r");
    cr_assert_not_null(p);
    char line[1024];
    int libraries = 0;
    while (fgets(line, sizeof line, p)) {
        cr_assert(!strstr(line, "OpenImageIO"), "linked at start-up: %s", line);
        libraries++;
    }
    cr_assert_eq(pclose(p), 0, "ldd failed");
    cr_assert(libraries >= 2, "ldd listed %d libraries", libraries);
}
