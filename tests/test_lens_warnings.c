/* Lens files that can be traced but are likely mistakes get a warning naming file and line:
   surfaces that cross inside their clear apertures, a film that sits in glass (the last row's
   index not 1), a rim that limits the beam from the film's centre more than the stop. No lens
   of the library gets any, focused at infinity or at 2 m. */
#include <criterion/criterion.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "support.h"

static char *info_errors(const char *path)
{
    char *out = NULL, *errtext = NULL;
    cr_assert_eq(run_lens2pov(&out, &errtext, "info", path, NULL), 0, "%s: %s", path, errtext);
    free(out);
    return errtext;
}

/* info's stderr with camera options, and its JSON in *json. */
static char *info_with_camera(const char *path, const char *focus, const char *f_number,
                              char **json)
{
    char *errtext = NULL;
    const int st = f_number ? run_lens2pov(json, &errtext, "info", path, "--json",
                                           "--focus-distance", focus, "--f-number", f_number, NULL)
                            : run_lens2pov(json, &errtext, "info", path, "--json",
                                           "--focus-distance", focus, NULL);
    cr_assert_eq(st, 0, "%s: %s", path, errtext);
    return errtext;
}

/* info of the lens at path, focused at infinity, warns: "warning: PATH" what " of the stop's
   diameter: the lens works at f/N_traced, not the f/N_paraxial its stop gives", with the two
   working f-numbers info gives. */
static void expect_limit_warning(const char *path, const char *what)
{
    char *json = NULL, *errtext = info_with_camera(path, "inf", NULL, &json), want[1400];
    snprintf(want, sizeof want, "warning: %s%s of the stop's diameter: the lens works at f/%.3g, "
             "not the f/%.3g its stop gives", path, what,
             json_number(json, "working_f_number_traced"), json_number(json, "working_f_number"));
    cr_expect(strstr(errtext, want), "%s\nwanted: %s", errtext, want);
    free(json), free(errtext);
}

/* A 30 mm stop 5 mm before a singlet of 20 mm clear aperture, focused at infinity: on the
   axis the front surface's rim passes rays through 66% of the stop's diameter (a meridional
   trace in Python, paraxial film distance 47.536 mm: the ray from the film centre that grazes
   the front rim, 10 mm from the axis, meets the rear surface at 9.818 mm, inside its rim, and
   the stop's plane at 9.919 mm, 66.1% of 15), so the lens works at the traced f-number info
   gives, not the paraxial one. At f/3 the stop limits again: nothing said. */
Test(lens_warnings, a_rim_that_limits_the_axial_beam_is_warned_of)
{
    const char *dir = test_tmpdir(), *path = tmp_path(dir, "bigstop.dat");
    write_text(path, "# a stop wider than the lens\n0 5 0 30\n50 5 1.5168 20\n-50 40 1 20\n");
    expect_limit_warning(path, ":3: the rim of this surface, not the stop (line 2, 30 mm open), "
                               "limits the beam from the film's centre to 66%");
    char *json = NULL, *errtext = info_with_camera(path, "inf", "3", &json);
    cr_expect(!strstr(errtext, "rim of this surface"), "%s", errtext);
    free(json), free(errtext);
}

/* A rear surface of 12 mm radius behind a 30 mm stop: beyond 6.2 mm of the stop's radius (41%:
   a meridional trace in Python, film at the paraxial focus 18.519 mm behind) no ray from the
   film's centre gets to the stop at all, missing the small sphere, so no rim can be named; the
   lens still works slower than its stop says. Thick tracing has no rims and says nothing. */
Test(lens_warnings, heights_of_the_stop_no_ray_reaches_are_warned_of)
{
    const char *dir = test_tmpdir(), *path = tmp_path(dir, "r12.dat");
    write_text(path, "0 5 0 30\n50 8 1.5168 20\n-12 40 1 20\n");
    expect_limit_warning(path, ": its surfaces, not the stop (line 1, 30 mm open), limit the "
                               "beam from the film's centre to 41%");
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "info", path, "--focus-distance", "inf", "--trace",
                              "thick", NULL), 0, "%s", errtext);
    cr_expect(!strstr(errtext, "not the stop"), "%s", errtext);
    free(errtext);
}

Test(lens_warnings, a_film_in_glass_is_warned_of_at_its_line)
{
    const char *dir = test_tmpdir(), *path = tmp_path(dir, "glass.dat");
    write_text(path, "# a singlet whose last row says the film sits in its glass\n"
                     "0 5 0 15\n50 5 1.5168 20\n-50 0 1.5 20\n");
    char *errtext = info_errors(path), want[1200];
    snprintf(want, sizeof want, "%s:4: the last row's index 1.5 is the medium", path);
    cr_expect(strstr(errtext, want), "%s", errtext);
    free(errtext);
}

Test(lens_warnings, crossing_surfaces_are_warned_of_at_their_lines)
{
    const char *dir = test_tmpdir(), *path = tmp_path(dir, "cross.dat");
    /* sags of 1.0 mm each at 10 mm from the axis, 0.1 mm apart on it */
    write_text(path, "50 0.1 1.5 20\n-50 5 1 20\n0 5 0 15\n");
    char *errtext = info_errors(path), want[1200];
    snprintf(want, sizeof want, "%s:1: this surface and the next (line 2) cross", path);
    cr_expect(strstr(errtext, want), "%s", errtext);
    free(errtext);
}

Test(lens_warnings, no_library_lens_gets_either)
{
    DIR *d = opendir(LENS_DIR);
    cr_assert_not_null(d);
    int seen = 0;
    for (struct dirent *e; (e = readdir(d));) {
        const size_t n = strlen(e->d_name);
        if (n < 4 || strcmp(e->d_name + n - 4, ".dat") != 0)
            continue;
        char path[1024];
        snprintf(path, sizeof path, LENS_DIR "%s", e->d_name);
        char *errtext = info_errors(path);
        cr_expect_str_empty(errtext, "%s: %s", e->d_name, errtext);
        free(errtext);
        const char *focus[] = {"inf", "2"};
        for (int f = 0; f < 2; f++) {
            char *json = NULL;
            errtext = info_with_camera(path, focus[f], NULL, &json);
            cr_expect_str_empty(errtext, "%s at %s: %s", e->d_name, focus[f], errtext);
            free(json), free(errtext);
        }
        seen++;
    }
    closedir(d);
    cr_expect_geq(seen, 10);
}

/* A stop just past the singlet's front focal plane puts the exit pupil far behind the film: at
   infinity focus the paraxial working f-number is still the f-number (from the entrance pupil
   and the focal length), positive, as the exit pupil's distance over its diameter gives it. */
Test(lens_warnings, an_exit_pupil_behind_the_film_gives_the_f_number)
{
    const char *dir = test_tmpdir(), *path = tmp_path(dir, "tele.dat");
    write_text(path, "0 47.54 0 20\n50 5 1.5168 12\n-50 40 1 12\n");
    char *json = NULL, *errtext = info_with_camera(path, "inf", NULL, &json);
    const double working = json_number(json, "working_f_number");
    const double n = json_number(json, "f_number");
    cr_expect(working > 0.0 && fabs(working / n - 1.0) < 1e-6, "working f/%g, f/%g", working, n);
    free(json), free(errtext);
}
