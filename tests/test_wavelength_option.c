/* --wavelength takes the lens to one wavelength: info still says that the file gives Abbe
   numbers, and on a file without them, where it changes nothing, every command says so. */
#include <criterion/criterion.h>
#include <stdlib.h>
#include <string.h>
#include "support.h"

Test(wavelength_option, info_keeps_saying_the_file_gives_abbe_numbers)
{
    char *out = NULL, *errtext = NULL;
    cr_assert_eq(run_lens2pov(&out, &errtext, "info", LENS_DIR "cooke-triplet.50mm.dat",
                              "--wavelength", "450", NULL), 0, "%s", errtext);
    cr_expect(strstr(out, "Abbe numbers given") && strstr(out, "450 nm"), "%s", out);
    cr_expect_str_empty(errtext);
    free(out), free(errtext);
    cr_assert_eq(run_lens2pov(&out, &errtext, "info", LENS_DIR "cooke-triplet.50mm.dat",
                              "--wavelength", "450", "--json", NULL), 0, "%s", errtext);
    cr_expect(strstr(out, "\"abbe_numbers\": true") && strstr(out, "\"wavelength_nm\": 450"),
              "%s", out);
    free(out), free(errtext);
    /* with camera options too (the camera's lens, at 450 nm, has no Abbe numbers left) */
    cr_assert_eq(run_lens2pov(&out, &errtext, "info", LENS_DIR "cooke-triplet.50mm.dat",
                              "--wavelength", "450", "--focus-distance", "inf", NULL), 0, "%s",
                 errtext);
    cr_expect(strstr(out, "Abbe numbers given"), "%s", out);
    cr_expect_str_empty(errtext);
    free(out), free(errtext);
}

Test(wavelength_option, a_lens_without_abbe_numbers_is_warned_of)
{
    const char *dir = test_tmpdir();
    char *out = NULL, *errtext = NULL;
    const char *warning = "gives no Abbe numbers, so its indices are the same at every "
                          "wavelength: --wavelength 450 changes nothing";
    cr_assert_eq(run_lens2pov(&out, &errtext, "info", LENS_DIR "dgauss.50mm.dat", "--wavelength",
                              "450", NULL), 0, "%s", errtext);
    cr_expect(strstr(errtext, warning) && !strstr(out, "Abbe"), "%s%s", out, errtext);
    free(out), free(errtext);
    cr_assert_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "dgauss.50mm.dat", "--wavelength",
                              "450", "--width", "8", "--height", "6", "--spp", "1", "-q", "-o",
                              tmp_path(dir, "t"), NULL), 0, "%s", errtext);
    cr_expect(strstr(errtext, warning), "%s", errtext);
    free(errtext);
    cr_assert_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "cooke-triplet.50mm.dat",
                              "--wavelength", "450", "--width", "8", "--height", "6", "--spp",
                              "1", "-q", "-o", tmp_path(dir, "c"), NULL), 0, "%s", errtext);
    cr_expect_str_empty(errtext);
    free(errtext);
}
