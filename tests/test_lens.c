/* Tests of src/optics/lens.c: the reader's errors (status and line), the awkward files it must take,
   the four shipped prescriptions against their published tables, placement, sag and copying. */
#include <criterion/criterion.h>

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "optics/lens.h"
#include "support.h"

/* ---- helpers ---------------------------------------------------------------------------- */

/* Parses text (which may hold NUL bytes: length is explicit) and expects a refusal whose
   message starts with prefix ("bad.dat:3: " names the line) and contains phrase. */
static void refused_n(const char *text, size_t length, const char *prefix, const char *phrase)
{
    lens l;
    l2p_error err = {0};
    int st = lens_parse(text, length, "lenses/bad.dat", &l, &err);
    cr_assert_eq(st, L2P_BAD_INPUT, "status %d for: %s", st, err.text);
    cr_assert_eq(err.status, L2P_BAD_INPUT);
    cr_assert(strncmp(err.text, prefix, strlen(prefix)) == 0, "'%s' does not start with '%s'",
              err.text, prefix);
    cr_assert(strstr(err.text, phrase) != NULL, "'%s' does not say '%s'", err.text, phrase);
    /* A failed parse leaves nothing behind. */
    cr_assert_eq(l.count, 0);
    cr_assert_null(l.surface);
    cr_assert_null(l.path);
    cr_assert_null(l.name);
}

/* A string literal, NULs included; LINE 0 means the message names the file without a line. */
#define REFUSED(text, line, phrase)                                                             \
    refused_n(text, sizeof(text) - 1,                                                          \
              (line) ? "lenses/bad.dat:" #line ": " : "lenses/bad.dat: ", phrase)

static lens parsed(const char *text)
{
    lens l;
    l2p_error err = {0};
    int st = lens_parse(text, strlen(text), "lenses/good.dat", &l, &err);
    cr_assert_eq(st, L2P_OK, "refused: %s", err.text);
    return l;
}

/* A minimal valid lens: front surface, stop, rear surface. */
#define FRONT "10 2 1.5 8\n"
#define STOP "0 1 0 4\n"
#define REAR "-10 5 1 8\n"

static void expect_minimal(const lens *l)
{
    cr_assert_eq(l->count, 3);
    cr_assert_eq(l->stop, 1);
    cr_assert_eq(l->surface[0].radius_mm, 10.0);
    cr_assert_eq(l->surface[0].thickness_mm, 2.0);
    cr_assert_eq(l->surface[0].ior, 1.5);
    cr_assert_eq(l->surface[0].aperture_diameter_mm, 8.0);
    cr_assert_eq(l->surface[1].radius_mm, 0.0);
    cr_assert_eq(l->surface[1].ior, 1.0);
    cr_assert_eq(l->surface[1].aperture_diameter_mm, 4.0);
    cr_assert_eq(l->surface[2].radius_mm, -10.0);
    cr_assert_eq(l->surface[2].thickness_mm, 5.0);
    cr_assert_eq(l->surface[2].ior, 1.0);
    cr_assert_eq(l->surface[2].aperture_diameter_mm, 8.0);
}

/* A fresh directory under /tmp for file tests. */
static void temp_dir(char dir[64])
{
    strcpy(dir, "/tmp/lens_test_XXXXXX");
    cr_assert_not_null(mkdtemp(dir), "mkdtemp: %s", strerror(errno));
}

/* ---- rows that are not four numbers ----------------------------------------------------- */

Test(lens, three_numbers)
{
    REFUSED(FRONT STOP "1 2 3\n", 3, "expected 4 numbers");
    REFUSED(FRONT STOP "1 2 3\n", 3, "got 3");
    REFUSED("5\n" FRONT STOP, 1, "got 1");
}

Test(lens, six_numbers)
{
    REFUSED(FRONT "20 2 1.5 8 5 6\n" STOP, 2, "unexpected '6' after the 5 numbers");
}

Test(lens, text_after_numbers)
{
    REFUSED(FRONT STOP "-10 5 1 8 0 x\n", 3, "unexpected 'x' after the 5 numbers");
    REFUSED(FRONT STOP "-10 5 1 8 x\n", 3, "not a number: 'x'");
    REFUSED(FRONT STOP "-10 5 1 8x\n", 3, "not a number: '8x'");
}

Test(lens, commas)
{
    REFUSED(FRONT "1,2,3,4\n" STOP, 2, "not a number: '1,2,3,4'");
    REFUSED(FRONT "10 2 1,5 8\n" STOP, 2, "not a number: '1,5'");
}

Test(lens, header_without_hash)
{
    REFUSED("radius thickness ior aperture\n" FRONT STOP, 1, "not a number: 'radius'");
}

Test(lens, malformed_numbers)
{
    REFUSED(FRONT STOP "-10 5 1 1e\n", 3, "not a number: '1e'");
    REFUSED(FRONT STOP "--10 5 1 8\n", 3, "not a number: '--10'");
    REFUSED(FRONT STOP "-10 5 1 +-8\n", 3, "not a number: '+-8'");
    REFUSED(FRONT STOP "-10 . 1 8\n", 3, "not a number: '.'");
    REFUSED(FRONT STOP "-10 5 1 1.2.3\n", 3, "not a number: '1.2.3'");
    REFUSED(FRONT STOP "-10 5 1 1e+\n", 3, "not a number: '1e+'");
}

Test(lens, hex_is_not_decimal)
{
    /* strtod reads these; a lens file does not hold them. */
    REFUSED(FRONT STOP "-10 5 1 0x10\n", 3, "not a number: '0x10'");
    REFUSED(FRONT STOP "-10 5 1 0x1p3\n", 3, "not a number: '0x1p3'");
}

Test(lens, not_finite)
{
    REFUSED(FRONT STOP "nan 5 1 8\n", 3, "not a finite number: 'nan'");
    REFUSED(FRONT STOP "-10 5 NaN 8\n", 3, "not a finite number: 'NaN'");
    REFUSED(FRONT STOP "-10 inf 1 8\n", 3, "not a finite number: 'inf'");
    REFUSED(FRONT STOP "-10 5 1 infinity\n", 3, "not a finite number: 'infinity'");
    REFUSED(FRONT STOP "-inf 5 1 8\n", 3, "not a finite number: '-inf'");
    REFUSED(FRONT STOP "-10 5 1 +INF\n", 3, "not a finite number: '+INF'");
}

Test(lens, out_of_range)
{
    REFUSED(FRONT STOP "-10 5 1 1e999\n", 3, "number out of range: '1e999'");
    REFUSED(FRONT STOP "-1e999 5 1 8\n", 3, "number out of range: '-1e999'");
    REFUSED(FRONT STOP "-10 1e-999 1 8\n", 3, "number out of range: '1e-999'");
}

Test(lens, overlong_token)
{
    REFUSED(FRONT STOP "-10 5 1 "
                       "1234567890123456789012345678901234567890123456789012345678901234567890\n",
            3, "a number of 70 characters, more than the 63 any decimal needs: "
               "'12345678901234567890123456789012...'");
}

/* ---- rows that are numbers but not a surface -------------------------------------------- */

Test(lens, aperture_not_positive)
{
    lens l;
    l2p_error err = {0};
    const char text[] = "# a\n#\n" FRONT STOP "\n\n" "-10 5 1 -3\n";
    cr_assert_eq(lens_parse(text, strlen(text), "lenses/x.dat", &l, &err), L2P_BAD_INPUT);
    cr_assert_str_eq(err.text, "lenses/x.dat:7: aperture diameter must be positive, got -3");
    REFUSED(FRONT STOP "-10 5 1 0\n", 3, "aperture diameter must be positive, got 0");
    REFUSED(FRONT "0 1 0 -4\n" REAR, 2, "aperture diameter must be positive, got -4");
}

Test(lens, ior_below_one)
{
    REFUSED(FRONT STOP "-10 5 0.5 8\n", 3, "index of refraction must be at least 1, got 0.5");
    REFUSED(FRONT STOP "-10 5 -1.5 8\n", 3, "index of refraction must be at least 1, got -1.5");
}

Test(lens, ior_zero_off_the_stop)
{
    REFUSED(FRONT STOP "-10 5 0 8\n", 3, "index of refraction must be at least 1, got 0");
    REFUSED(FRONT STOP "-10 5 0 8\n", 3, "0 means air only on the aperture stop");
}

Test(lens, stop_ior_between_zero_and_one)
{
    REFUSED(FRONT "0 1 0.5 4\n" REAR, 2, "must be 0 (air) or at least 1, got 0.5");
    REFUSED(FRONT "0 1 -1 4\n" REAR, 2, "must be 0 (air) or at least 1, got -1");
}

Test(lens, negative_thickness)
{
    REFUSED(FRONT "0 -1 0 4\n" REAR, 2, "thickness must not be negative, got -1");
    /* The last row's thickness is not used, but a negative one is still a wrong file. */
    REFUSED(FRONT STOP "-10 -0.5 1 8\n", 3, "thickness must not be negative, got -0.5");
}

Test(lens, radius_smaller_than_half_aperture)
{
    REFUSED(FRONT STOP "5 1 1.5 10.5\n", 3, "radius 5 is too small for aperture diameter 10.5");
    REFUSED(FRONT STOP "-5 1 1.5 10.5\n", 3, "radius -5 is too small for aperture diameter 10.5");
    /* The stop has no radius: any opening. */
    lens l = parsed("10 2 1.5 8\n0 1 0 400\n-10 5 1 8\n");
    cr_assert_eq(l.surface[1].aperture_diameter_mm, 400.0);
    lens_free(&l);
}

Test(lens, hemisphere_is_allowed)
{
    lens l = parsed("5 2 1.5 10\n" STOP "-5 5 1 10\n");
    cr_assert_eq(l.count, 3);
    /* Its rim is a full radius behind (in front of) the vertex, and finite. */
    cr_assert_float_eq(lens_sag_mm(&l.surface[0], 5.0), -5.0, 1e-12);
    cr_assert_float_eq(lens_sag_mm(&l.surface[2], 5.0), 5.0, 1e-12);
    lens_free(&l);
}

/* ---- what the rows make together -------------------------------------------------------- */

Test(lens, no_stop)
{
    REFUSED(FRONT REAR, 2, "no aperture stop (a row with radius 0) by the end of the file");
}

Test(lens, two_stops)
{
    REFUSED(FRONT STOP REAR "# another\n" STOP REAR, 5, "second aperture stop");
    REFUSED(FRONT STOP REAR "# another\n" STOP REAR, 5, "the first is on line 2");
}

Test(lens, only_the_stop)
{
    REFUSED("# only a stop\n\n" STOP, 3, "no refracting surface");
}

Test(lens, no_surfaces)
{
    REFUSED("", 1, "no surfaces by the end of the file");
    REFUSED("# just\n# comments\n", 2, "no surfaces");
    REFUSED("\n\n  \t \r\n\r\n", 4, "no surfaces");
    REFUSED("# no final newline", 1, "no surfaces");
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_parse(NULL, 0, "lenses/bad.dat", &l, &err), L2P_BAD_INPUT);
    cr_assert_str_eq(err.text, "lenses/bad.dat:1: no surfaces by the end of the file (a row is 4 numbers)");
}

Test(lens, too_many_rows)
{
    /* The stop and then LENS_MAX_SURFACES rows: the first one over the limit is refused. */
    const char *row = "10 1 1.5 8\n";
    const size_t row_length = strlen(row);
    const size_t rows = LENS_MAX_SURFACES;
    char *text = malloc(strlen(STOP) + rows * row_length + 1);
    cr_assert_not_null(text);
    strcpy(text, STOP);
    for (size_t i = 0; i < rows; i++)
        memcpy(text + strlen(STOP) + i * row_length, row, row_length + 1);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_parse(text, strlen(text), "lenses/bad.dat", &l, &err), L2P_BAD_INPUT);
    char expected[64];
    snprintf(expected, sizeof expected, "lenses/bad.dat:%d: more than %d surfaces",
             LENS_MAX_SURFACES + 1, LENS_MAX_SURFACES);
    cr_assert(strncmp(err.text, expected, strlen(expected)) == 0, "%s", err.text);
    /* Exactly the limit is fine. */
    cr_assert_eq(lens_parse(text, strlen(text) - row_length, "big.dat", &l, &err), L2P_OK,
                 "%s", err.text);
    cr_assert_eq(l.count, LENS_MAX_SURFACES);
    lens_free(&l);
    free(text);
}

/* ---- binary garbage --------------------------------------------------------------------- */

Test(lens, nul_bytes)
{
    REFUSED(FRONT "0 1\0 0 4\n" REAR, 2, "NUL byte");
    REFUSED(FRONT STOP "-10 5 1 8\0\n", 3, "NUL byte");
    REFUSED(FRONT STOP REAR "# a comment \0 with a NUL\n", 4, "NUL byte");
    REFUSED(FRONT "\0\0\0\0", 2, "NUL byte");
}

Test(lens, binary_garbage)
{
    REFUSED("\x89PNG\r\n\x1a\n", 1, "unexpected byte 0x89");
    REFUSED(FRONT "0 1\x01 0 4\n" REAR, 2, "unexpected byte 0x01");
    REFUSED(FRONT STOP "-10 5 1 8 \xff\xfe\n", 3, "unexpected byte 0xff");
    REFUSED(FRONT "\x1b[31m\n", 2, "unexpected byte 0x1b");
}

Test(lens, line_numbers_in_a_crlf_file)
{
    REFUSED("# header\r\n\r\n10 2 1.5 8\r\n0 1 0 4\r\n\r\n# x\r\n-10 5 1\r\n", 7, "got 3");
}

/* Rows ended by CR alone (old Mac files) read as one line: said so, not "unexpected '-10'
   after the 5 numbers", nor "no surfaces" when that line is a comment. A CR in a comment, or
   before blanks and the LF, is no such thing. */
Test(lens, cr_only_line_endings_are_named)
{
    REFUSED("10 2 1.5 8\r0 1 0 4\r-10 5 1 8\r", 1, "carriage return (CR) inside the line");
    /* a library file's header comment first: the whole file is that comment */
    REFUSED("# a lens\r10 2 1.5 8\r0 1 0 4\r-10 5 1 8\r", 1, "rows end with CR alone");
    lens l = parsed("# a comment\rwith a CR\n10 2 1.5 8 \r \n0 1 0 4\r\n-10 5 1 8\r\n");
    expect_minimal(&l);
    lens_free(&l);
}

/* ---- awkward but valid files ------------------------------------------------------------ */

Test(lens, crlf)
{
    lens l = parsed("10 2 1.5 8\r\n0 1 0 4\r\n-10 5 1 8\r\n");
    expect_minimal(&l);
    lens_free(&l);
}

Test(lens, no_final_newline)
{
    lens l = parsed(FRONT STOP "-10 5 1 8");
    expect_minimal(&l);
    lens_free(&l);
    l = parsed(FRONT STOP "-10 5 1 8\r");
    expect_minimal(&l);
    lens_free(&l);
    l = parsed(FRONT STOP REAR "# last line a comment");
    expect_minimal(&l);
    lens_free(&l);
}

Test(lens, tabs)
{
    lens l = parsed("10\t2\t1.5\t8\n\t0\t 1 \t0\t4\t\n-10\t\t5 1\t8\n");
    expect_minimal(&l);
    lens_free(&l);
}

Test(lens, trailing_comments)
{
    lens l = parsed("10 2 1.5 8 # front\n0 1 0 4# stop\n-10 5 1 8#\n");
    expect_minimal(&l);
    lens_free(&l);
}

Test(lens, exponents_and_signs)
{
    lens l = parsed("1e1 2E0 1.5e+0 +8\n+0 1e-0 0 4.0E0\n-1.0E1 +5 +1 .8e+1\n");
    cr_assert_eq(l.surface[0].radius_mm, 10.0);
    cr_assert_eq(l.surface[0].thickness_mm, 2.0);
    cr_assert_eq(l.surface[0].ior, 1.5);
    cr_assert_eq(l.surface[0].aperture_diameter_mm, 8.0);
    cr_assert_eq(l.stop, 1);
    cr_assert_eq(l.surface[2].radius_mm, -10.0);
    cr_assert_eq(l.surface[2].thickness_mm, 5.0);
    cr_assert_eq(l.surface[2].aperture_diameter_mm, 8.0);
    lens_free(&l);
    l = parsed("10 2 1.5 2.5E-1\n0 1 0 .5\n-10 5. 1 8\n");
    cr_assert_eq(l.surface[0].aperture_diameter_mm, 0.25);
    cr_assert_eq(l.surface[1].aperture_diameter_mm, 0.5);
    cr_assert_eq(l.surface[2].thickness_mm, 5.0);
    lens_free(&l);
}

Test(lens, blank_lines_and_line_numbers)
{
    lens l = parsed("# header\n\n" FRONT "   \n\t\n" STOP REAR "\n\n");
    expect_minimal(&l);
    cr_assert_eq(l.surface[0].line, 3);
    cr_assert_eq(l.surface[1].line, 6);
    cr_assert_eq(l.surface[2].line, 7);
    lens_free(&l);
}

/* ---- the fifth column: Abbe numbers --------------------------------------------------- */

/* FRONT, STOP and REAR with Abbe numbers: the glass's, and 0 on the air rows. */
#define FRONT_V "10 2 1.5 8 64.2\n"
#define STOP_V "0 1 0 4 0\n"
#define REAR_V "-10 5 1 8 0\n"

Test(lens, abbe_numbers_are_read)
{
    lens l = parsed(FRONT_V STOP REAR);
    expect_minimal(&l);
    cr_assert_eq(l.surface[0].abbe, 64.2);
    cr_assert_eq(l.surface[1].abbe, 0.0);
    cr_assert_eq(l.surface[2].abbe, 0.0);
    cr_assert_eq(lens_has_abbe(&l), 1);
    lens_free(&l);
    l = parsed(FRONT_V STOP_V REAR_V);
    expect_minimal(&l);
    cr_assert_eq(l.surface[0].abbe, 64.2);
    lens_free(&l);
}

Test(lens, four_columns_have_no_abbe_numbers)
{
    lens l = parsed(FRONT STOP REAR);
    cr_assert_eq(lens_has_abbe(&l), 0);
    for (int i = 0; i < l.count; i++) {
        cr_assert_eq(l.surface[i].abbe, 0.0);
        /* Without an Abbe number the index is the same at every wavelength. */
        cr_assert_eq(lens_index_at(&l.surface[i], 400.0), l.surface[i].ior);
        cr_assert_eq(lens_index_at(&l.surface[i], 700.0), l.surface[i].ior);
    }
    lens_free(&l);
}

Test(lens, abbe_number_on_air_must_be_zero)
{
    REFUSED(FRONT_V "0 1 0 4 3\n" REAR, 2, "Abbe number must be 0 on an air row (index 0), got 3");
    REFUSED(FRONT_V STOP "-10 5 1 8 30\n", 3,
            "Abbe number must be 0 on an air row (index 1), got 30");
    REFUSED(FRONT STOP "-10 5 1 8 -1\n", 3, "must be 0 on an air row");
}

Test(lens, abbe_number_of_glass_must_be_positive)
{
    REFUSED("10 2 1.5 8 0\n" STOP REAR, 1,
            "Abbe number of the glass behind the surface must be positive, got 0");
    REFUSED("10 2 1.5 8 -64\n" STOP REAR, 1, "must be positive, got -64");
    REFUSED("10 2 1.5 8 nan\n" STOP REAR, 1, "not a finite number: 'nan'");
    REFUSED("10 2 1.5 8 inf\n" STOP REAR, 1, "not a finite number: 'inf'");
    REFUSED("10 2 1.5 8 1e999\n" STOP REAR, 1, "out of range");
    /* below 5 no optical material disperses (below 0.66 the Cauchy fit's index falls under 1) */
    REFUSED("10 2 1.5 8 0.01\n" STOP REAR, 1, "Abbe number 0.01 disperses more than any optical material");
    REFUSED("10 2 1.5 8 1e-300\n" STOP REAR, 1, "Abbe number 1e-300 disperses");
}

Test(lens, abbe_numbers_on_every_glass_row_or_none)
{
    REFUSED(FRONT STOP "-10 2 1.6 8 30\n-20 5 1 8\n", 3,
            "Abbe number on this glass row, but none on the glass row of line 1");
    REFUSED(FRONT_V STOP "-10 2 1.6 8\n-20 5 1 8\n", 3,
            "no Abbe number on this glass row, but the glass row of line 1 has one");
    /* Air rows may give 0 or nothing, whatever the glass rows do. */
    lens l = parsed(FRONT STOP_V REAR_V);
    cr_assert_eq(lens_has_abbe(&l), 0);
    lens_free(&l);
    l = parsed(FRONT_V STOP "-10 2 1.6 8 30\n-20 5 1 8 0\n");
    cr_assert_eq(l.surface[2].abbe, 30.0);
    lens_free(&l);
}

Test(lens, stop_in_glass_takes_an_abbe_number)
{
    lens l = parsed(FRONT_V "0 1 1.5 4 64.2\n" REAR);
    cr_assert_eq(l.surface[1].abbe, 64.2);
    lens_free(&l);
    REFUSED(FRONT_V "0 1 1.5 4\n" REAR, 2, "no Abbe number on this glass row");
}

/* The Cauchy fit: n_d at the d line, n_F - n_C = (n_d - 1) / V_d, falling with wavelength. */
Test(lens, index_at_wavelength_is_the_cauchy_fit)
{
    const lens_surface s = {.ior = 1.5168, .abbe = 64.17};
    cr_assert_float_eq(lens_index_at(&s, 587.5618), 1.5168, 1e-15);
    const double nf = lens_index_at(&s, 486.1327), nc = lens_index_at(&s, 656.2725);
    cr_assert_float_eq(nf - nc, 0.5168 / 64.17, 1e-15);
    cr_assert_gt(lens_index_at(&s, 400.0), nf);
    cr_assert_lt(lens_index_at(&s, 700.0), nc);
    /* By hand: B = 0.5168 / (64.17 (1/486.1327^2 - 1/656.2725^2)) nm^2,
       A = 1.5168 - B / 587.5618^2, n(450 nm) = A + B / 450^2. */
    const double b = 0.5168 / (64.17 * (1 / (486.1327 * 486.1327) - 1 / (656.2725 * 656.2725)));
    const double a = 1.5168 - b / (587.5618 * 587.5618);
    cr_assert_float_eq(lens_index_at(&s, 450.0), a + b / (450.0 * 450.0), 1e-15);
    cr_assert_float_eq(b, 4217.377, 0.001, "B = %.6f nm^2", b);
    /* N-BK7 (n_d 1.5168, V_d 64.17) in Schott's catalogue: n_F 1.52238, n_C 1.51432. */
    cr_assert_float_eq(nf, 1.52238, 1e-4, "n_F %.6f", nf);
    cr_assert_float_eq(nc, 1.51432, 1e-4, "n_C %.6f", nc);
}

Test(lens, byte_order_mark)
{
    lens l = parsed("\xEF\xBB\xBF" FRONT STOP REAR);
    expect_minimal(&l);
    lens_free(&l);
}

/* ---- surfaces that cross --------------------------------------------------------------- */

/* The textbook sag R - sqrt(R^2 - rho^2), toward the film for R > 0: an independent form of
   the gap between two neighbouring surfaces at height rho. */
static double textbook_gap(double r1, double t, double r2, double rho)
{
    const double s1 = r1 - copysign(sqrt(r1 * r1 - rho * rho), r1);
    const double s2 = r2 - copysign(sqrt(r2 * r2 - rho * rho), r2);
    return t - s1 + s2;
}

Test(lens, crossing_surfaces_are_found_at_the_rim)
{
    /* A biconvex element too thin for its aperture: its faces meet 1.2 mm from the axis, well
       inside the 12 mm rim. */
    lens l = parsed("0 1 0 6\n62.8 0.1 1.5 24\n-45.7 40 1 24\n");
    double rho = 0.0, gap = 0.0;
    cr_assert_eq(lens_crossing(&l, &rho, &gap), 1);
    cr_assert_eq(rho, 12.0);
    cr_assert_float_eq(gap, textbook_gap(62.8, 0.1, -45.7, 12.0), 1e-12);
    cr_assert(gap < -2.6, "gap %g", gap);
    lens_free(&l);
    /* A meniscus whose back is flatter than its front (the gap falls with the height). */
    l = parsed("10 0.5 1.5 16\n20 1 1 16\n0 5 0 4\n");
    cr_assert_eq(lens_crossing(&l, &rho, &gap), 0);
    cr_assert_float_eq(gap, textbook_gap(10, 0.5, 20, 8.0), 1e-12);
    lens_free(&l);
    /* Thick enough by a micrometre at the rim: no crossing. */
    const double edge = -textbook_gap(62.8, 0.0, -45.7, 12.0) + 1e-3;
    char text[128];
    snprintf(text, sizeof text, "0 1 0 6\n62.8 %.9f 1.5 24\n-45.7 40 1 24\n", edge);
    l = parsed(text);
    cr_assert_eq(lens_crossing(&l, &rho, &gap), -1);
    lens_free(&l);
    l = parsed(FRONT STOP REAR);
    cr_assert_eq(lens_crossing(&l, &rho, &gap), -1);
    lens_free(&l);
}

Test(lens, no_shipped_lens_crosses_and_a_crossing_one_is_traced_with_a_warning)
{
    char path[512], dir[64];
    static const char *const names[] = {
        "cooke-triplet.50mm", "dgauss.50mm", "fisheye-dx.10.5mm", "fisheye.10mm", "macro.105mm",
        "petzval.50mm", "portrait.85mm", "retrofocus.28mm", "retrofocus.35mm", "sonnar.180mm",
        "sonnar.50mm", "takumar.135mm", "takumar.50mm", "telephoto.250mm", "tessar.100mm",
        "wide.22mm", "zoom.200mm", "zoom.80mm"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        snprintf(path, sizeof path, "%s/lenses/%s.dat", LENS2POV_SOURCE_DIR, names[k]);
        lens l;
        l2p_error err = {0};
        cr_assert_eq(lens_read(path, &l, &err), L2P_OK, "%s", err.text);
        double rho, gap;
        cr_expect_eq(lens_crossing(&l, &rho, &gap), -1, "%s: %g mm at %g mm", names[k], gap, rho);
        lens_free(&l);
    }
    temp_dir(dir);
    snprintf(path, sizeof path, "%s/thin.dat", dir);
    write_text(path, "# too thin\n0 1 0 6\n62.8 0.1 1.5 24\n-45.7 40 1 24\n");
    char *out = NULL, *errout = NULL;
    cr_assert_eq(run_lens2pov(&out, &errout, "info", path, NULL), 0, "%s", errout);
    char where[600];
    snprintf(where, sizeof where, "lens2pov: warning: %s:3: ", path);
    cr_expect(errout && strncmp(errout, where, strlen(where)) == 0, "%s", errout);
    cr_expect(errout && strstr(errout, "(line 4) cross"), "%s", errout);
    free(out);
    free(errout);
    unlink(path);
    rmdir(dir);
}

Test(lens, stop_index_zero_means_air)
{
    lens l = parsed(FRONT STOP REAR);
    cr_assert_eq(l.surface[1].ior, 1.0);
    cr_assert_eq(lens_ior_front(&l, 2), 1.0);
    lens_free(&l);
}

Test(lens, stop_index_given_is_kept)
{
    /* A stop inside a glass: the index says the medium behind it. */
    lens l = parsed("10 2 1.5 8\n0 1 1.5 4\n-10 5 1 8\n");
    cr_assert_eq(l.surface[1].ior, 1.5);
    cr_assert_eq(lens_ior_front(&l, 2), 1.5);
    lens_free(&l);
    l = parsed("10 2 1.5 8\n0 1 1 4\n-10 5 1 8\n");
    cr_assert_eq(l.surface[1].ior, 1.0);
    lens_free(&l);
}

Test(lens, derived_fields)
{
    lens l = parsed(FRONT STOP REAR);
    cr_assert_str_eq(l.path, "lenses/good.dat");
    cr_assert_str_eq(l.name, "good");
    cr_assert_float_eq(l.surface[0].curvature_per_mm, 0.1, 1e-15);
    cr_assert_eq(l.surface[1].curvature_per_mm, 0.0);
    cr_assert_float_eq(l.surface[2].curvature_per_mm, -0.1, 1e-15);
    cr_assert_eq(l.stop_diameter_mm, 4.0);
    cr_assert_eq(l.film_distance_mm, 0.0);
    /* Placed at film distance 0: rear vertex on the film, the others one thickness apart. */
    cr_assert_eq(l.surface[2].vertex_z_mm, 0.0);
    cr_assert_eq(l.surface[1].vertex_z_mm, 1.0);
    cr_assert_eq(l.surface[0].vertex_z_mm, 3.0);
    cr_assert_eq(lens_semi_aperture_mm(&l, 1), 2.0);
    cr_assert_eq(lens_semi_aperture_mm(&l, 0), 4.0);
    lens_free(&l);
}

Test(lens, names)
{
    static const struct {
        const char *path, *name;
    } cases[] = {
        {"lenses/dgauss.50mm.dat", "dgauss.50mm"},
        {"dgauss.50mm.dat", "dgauss.50mm"},
        {"/a/b/my.lens", "my.lens"},
        {"a.dat.txt", "a.dat.txt"},
        {"dir.dat/lens", "lens"},
        {".dat", ".dat"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        lens l;
        l2p_error err = {0};
        const char *text = FRONT STOP REAR;
        cr_assert_eq(lens_parse(text, strlen(text), cases[i].path, &l, &err), L2P_OK);
        cr_assert_str_eq(l.path, cases[i].path);
        cr_assert_str_eq(l.name, cases[i].name);
        lens_free(&l);
    }
}

/* ---- lens_read -------------------------------------------------------------------------- */

Test(lens, read_file)
{
    char dir[64], path[128];
    temp_dir(dir);
    snprintf(path, sizeof path, "%s/my.lens.dat", dir);
    const char text[] = "# test\r\n" FRONT STOP "-10 5 1 8";
    write_bytes(path, text, sizeof text - 1);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_OK, "%s", err.text);
    expect_minimal(&l);
    cr_assert_str_eq(l.path, path);
    cr_assert_str_eq(l.name, "my.lens");
    cr_assert_eq(l.surface[0].line, 2);
    lens_free(&l);
    unlink(path);
    rmdir(dir);
}

Test(lens, read_mkstemp_file_with_error)
{
    char path[] = "/tmp/lens_test_XXXXXX";
    int fd = mkstemp(path);
    cr_assert(fd >= 0, "mkstemp: %s", strerror(errno));
    const char text[] = FRONT "\n" STOP "-10 5 1 8 0 9\n";
    cr_assert_eq(write(fd, text, sizeof text - 1), (ssize_t)(sizeof text - 1));
    close(fd);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_BAD_INPUT);
    char expected[128];
    snprintf(expected, sizeof expected, "%s:4: unexpected '9' after the 5 numbers", path);
    cr_assert_str_eq(err.text, expected);
    cr_assert_null(l.surface);
    unlink(path);
}

Test(lens, read_binary_file)
{
    char path[] = "/tmp/lens_test_XXXXXX";
    int fd = mkstemp(path);
    cr_assert(fd >= 0);
    const unsigned char garbage[] = {0x7f, 'E', 'L', 'F', 2, 1, 1, 0, 0, 0, '\n', 0xff};
    cr_assert_eq(write(fd, garbage, sizeof garbage), (ssize_t)sizeof garbage);
    close(fd);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_BAD_INPUT);
    char expected[128];
    snprintf(expected, sizeof expected, "%s:1: NUL byte", path);
    cr_assert(strncmp(err.text, expected, strlen(expected)) == 0, "%s", err.text);
    unlink(path);
}

Test(lens, read_missing_file)
{
    char dir[64], path[128], expected[256];
    temp_dir(dir);
    snprintf(path, sizeof path, "%s/missing.dat", dir);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_BAD_INPUT);
    cr_assert_eq(err.status, L2P_BAD_INPUT);
    snprintf(expected, sizeof expected, "%s: %s", path, strerror(ENOENT));
    cr_assert_str_eq(err.text, expected);
    cr_assert_null(l.surface);
    rmdir(dir);
}

Test(lens, read_directory)
{
    char dir[64], expected[256];
    temp_dir(dir);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(dir, &l, &err), L2P_BAD_INPUT);
    snprintf(expected, sizeof expected, "%s: %s", dir, strerror(EISDIR));
    cr_assert_str_eq(err.text, expected);
    cr_assert_null(l.surface);
    rmdir(dir);
}

Test(lens, read_too_large)
{
    char path[] = "/tmp/lens_test_XXXXXX";
    int fd = mkstemp(path);
    cr_assert(fd >= 0);
    /* Sparse: costs no disk. */
    cr_assert_eq(ftruncate(fd, (off_t)LENS_MAX_FILE_BYTES + 1), 0);
    close(fd);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_BAD_INPUT);
    char expected[128];
    snprintf(expected, sizeof expected, "%s: larger than 16 MiB", path);
    cr_assert(strncmp(err.text, expected, strlen(expected)) == 0, "%s", err.text);
    unlink(path);
}

Test(lens, read_endless_device)
{
    /* No size to check beforehand: the limit must stop the read itself. */
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read("/dev/zero", &l, &err), L2P_BAD_INPUT);
    cr_assert_str_eq(err.text, "/dev/zero: larger than 16 MiB: not a lens file");
}

Test(lens, read_pipe)
{
    int fds[2];
    cr_assert_eq(pipe(fds), 0);
    const char text[] = FRONT STOP REAR;
    cr_assert_eq(write(fds[1], text, sizeof text - 1), (ssize_t)(sizeof text - 1));
    close(fds[1]);
    char path[64];
    snprintf(path, sizeof path, "/dev/fd/%d", fds[0]);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_OK, "%s", err.text);
    expect_minimal(&l);
    lens_free(&l);
    close(fds[0]);
}

Test(lens, read_empty_file)
{
    char path[] = "/tmp/lens_test_XXXXXX";
    int fd = mkstemp(path);
    cr_assert(fd >= 0);
    close(fd);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_BAD_INPUT);
    char expected[128];
    snprintf(expected, sizeof expected, "%s:1: no surfaces by the end of the file (a row is 4 numbers)", path);
    cr_assert_str_eq(err.text, expected);
    unlink(path);
}

/* ---- the shipped lenses against the tables of docs/lenses.md ----------------------------- */

typedef struct table_row {
    double radius, thickness, ior, aperture;
} table_row;

static const table_row DGAUSS[] = {
    {29.475, 3.76, 1.67, 25.2},   {84.83, 0.12, 1, 25.2},     {19.275, 4.025, 1.67, 23},
    {40.77, 3.275, 1.699, 23},    {12.75, 5.705, 1, 18},      {0, 4.5, 0, 17.1},
    {-14.495, 1.18, 1.603, 17},   {40.77, 6.065, 1.658, 20},  {-20.385, 0.19, 1, 20},
    {437.065, 3.22, 1.717, 20},   {-39.73, 0, 1, 20},
};

static const table_row WIDE[] = {
    {35.98738, 1.21638, 1.54, 23.716}, {11.69718, 9.9957, 1, 17.996},
    {13.08714, 5.12622, 1.772, 12.364}, {-22.63294, 1.76924, 1.617, 9.812},
    {71.05802, 0.8184, 1, 9.152},      {0, 2.27766, 0, 8.756},
    {-9.58584, 2.43254, 1.617, 8.184}, {-11.28864, 0.11506, 1, 9.152},
    {-166.7765, 3.09606, 1.713, 10.648}, {-7.5911, 1.32682, 1.805, 11.44},
    {-16.7662, 3.98068, 1, 12.276},    {-7.70286, 1.21638, 1.617, 13.42},
    {-11.97328, 0, 1, 17.996},
};

static const table_row FISHEYE[] = {
    {30.2249, 0.8335, 1.62, 30.34},   {11.3931, 7.4136, 1, 20.68},
    {75.2019, 1.0654, 1.639, 17.8},   {8.3349, 11.1549, 1, 13.42},
    {9.5882, 2.0054, 1.654, 9.02},    {43.8677, 5.3895, 1, 8.14},
    {0, 1.4163, 0, 6.08},             {29.4541, 2.1934, 1.517, 5.96},
    {-5.2265, 0.9714, 1.805, 5.84},   {-14.2884, 0.0627, 1, 5.96},
    {-22.3726, 0.94, 1.673, 5.96},    {-15.0404, 0, 1, 6.52},
};

static const table_row TELEPHOTO[] = {
    {54.6275, 12.52, 1.529, 47.5}, {-86.365, 3.755, 1.599, 44.5}, {271.7625, 2.8175, 1, 41.5},
    {0, 67.4125, 0, 40.5},         {-32.13, 3.755, 1.613, 31.5},  {49.5325, 12.52, 1.603, 33.5},
    {-50.945, 0, 1, 37},
};

typedef struct shipped {
    const char *file, *name;
    const table_row *rows;
    int count, stop;
    double total_length_mm;       /* sum of the table's thicknesses but the last, by hand */
    double stop_to_rear_mm;       /* sum of the thicknesses from the stop row to row n-2 */
    double film_distance_mm;      /* CS348B */
} shipped;

#define ROWS(t) t, (int)(sizeof t / sizeof t[0])

static const shipped SHIPPED[] = {
    {"dgauss.50mm.dat", "dgauss.50mm", ROWS(DGAUSS), 5, 32.04, 15.155, 36.77},
    {"wide.22mm.dat", "wide.22mm", ROWS(WIDE), 5, 33.37114, 14.4452, 14.54},
    {"fisheye.10mm.dat", "fisheye.10mm", ROWS(FISHEYE), 6, 33.4461, 5.5838, 23.192},
    {"telephoto.250mm.dat", "telephoto.250mm", ROWS(TELEPHOTO), 3, 102.78, 83.6875, 123.7439},
};

static lens read_shipped(const shipped *s)
{
    char path[512];
    snprintf(path, sizeof path, "%s/lenses/%s", LENS2POV_SOURCE_DIR, s->file);
    lens l;
    l2p_error err = {0};
    cr_assert_eq(lens_read(path, &l, &err), L2P_OK, "%s", err.text);
    return l;
}

Test(lens, shipped_rows_match_tables)
{
    for (size_t k = 0; k < sizeof SHIPPED / sizeof SHIPPED[0]; k++) {
        const shipped *s = &SHIPPED[k];
        lens l = read_shipped(s);
        cr_assert_str_eq(l.name, s->name);
        cr_assert_eq(l.count, s->count, "%s: %d rows", s->file, l.count);
        cr_assert_eq(l.stop, s->stop, "%s: stop %d", s->file, l.stop);
        cr_assert_eq(l.stop_diameter_mm, s->rows[s->stop].aperture);
        for (int i = 0; i < l.count; i++) {
            const table_row *t = &s->rows[i];
            const lens_surface *f = &l.surface[i];
            cr_assert_eq(f->radius_mm, t->radius, "%s row %d", s->file, i);
            cr_assert_eq(f->thickness_mm, t->thickness, "%s row %d", s->file, i);
            cr_assert_eq(f->ior, t->ior == 0 ? 1.0 : t->ior, "%s row %d", s->file, i);
            cr_assert_eq(f->aperture_diameter_mm, t->aperture, "%s row %d", s->file, i);
            cr_assert(i == 0 || f->line > l.surface[i - 1].line);
        }
        /* The header comment names the source before the first row. */
        cr_assert_gt(l.surface[0].line, 3, "%s: no header comment", s->file);
        lens_free(&l);
    }
}

Test(lens, shipped_total_length)
{
    for (size_t k = 0; k < sizeof SHIPPED / sizeof SHIPPED[0]; k++) {
        lens l = read_shipped(&SHIPPED[k]);
        cr_assert_float_eq(lens_total_length_mm(&l), SHIPPED[k].total_length_mm, 1e-9, "%s: %.17g",
                           SHIPPED[k].file, lens_total_length_mm(&l));
        lens_free(&l);
    }
}

Test(lens, shipped_vertices_at_cs348b_film_distance)
{
    for (size_t k = 0; k < sizeof SHIPPED / sizeof SHIPPED[0]; k++) {
        const shipped *s = &SHIPPED[k];
        lens l = read_shipped(s);
        lens_set_film_distance(&l, s->film_distance_mm);
        cr_assert_eq(l.film_distance_mm, s->film_distance_mm);
        cr_assert_eq(l.surface[l.count - 1].vertex_z_mm, s->film_distance_mm);
        cr_assert_float_eq(l.surface[0].vertex_z_mm, s->film_distance_mm + s->total_length_mm,
                           1e-9, "%s", s->file);
        cr_assert_float_eq(l.surface[s->stop].vertex_z_mm,
                           s->film_distance_mm + s->stop_to_rear_mm, 1e-9, "%s", s->file);
        /* Each vertex one table thickness in front of the next. */
        for (int i = 0; i + 1 < l.count; i++)
            cr_assert_float_eq(l.surface[i].vertex_z_mm - l.surface[i + 1].vertex_z_mm,
                               s->rows[i].thickness, 1e-12, "%s row %d", s->file, i);
        lens_free(&l);
    }
}

Test(lens, film_distance_moves_the_lens_rigidly)
{
    lens l = read_shipped(&SHIPPED[0]);
    lens_set_film_distance(&l, 0.0);
    double z0[16];
    for (int i = 0; i < l.count; i++)
        z0[i] = l.surface[i].vertex_z_mm;
    lens_set_film_distance(&l, 40.0);
    for (int i = 0; i < l.count; i++)
        cr_assert_float_eq(l.surface[i].vertex_z_mm, z0[i] + 40.0, 1e-12);
    /* The last row's thickness (0 in the table) plays no part: change it, nothing moves. */
    l.surface[l.count - 1].thickness_mm = 1000.0;
    lens_set_film_distance(&l, 40.0);
    cr_assert_float_eq(l.surface[0].vertex_z_mm, z0[0] + 40.0, 1e-12);
    cr_assert_float_eq(lens_total_length_mm(&l), 32.04, 1e-9);
    lens_free(&l);
}

/* ---- sag -------------------------------------------------------------------------------- */

/* The textbook form, with the sign of the geometry: a positive radius has its centre toward
   the film, so the rim lies toward the film (negative). */
static double sag_reference(double radius, double rho)
{
    const double depth = fabs(radius) - sqrt(radius * radius - rho * rho);
    return radius > 0 ? -depth : depth;
}

Test(lens, sag_matches_sphere_on_shipped_lenses)
{
    for (size_t k = 0; k < sizeof SHIPPED / sizeof SHIPPED[0]; k++) {
        lens l = read_shipped(&SHIPPED[k]);
        for (int i = 0; i < l.count; i++) {
            const lens_surface *s = &l.surface[i];
            const double rho = 0.5 * s->aperture_diameter_mm;
            const double sag = lens_sag_mm(s, rho);
            if (i == l.stop) {
                cr_assert_eq(sag, 0.0);
                continue;
            }
            cr_assert_float_eq(sag, sag_reference(s->radius_mm, rho), 1e-12, "%s row %d",
                               SHIPPED[k].file, i);
            /* The rim point lies on the sphere whose centre is at vertex_z - radius. */
            const double centre_z = s->vertex_z_mm - s->radius_mm;
            const double dz = s->vertex_z_mm + sag - centre_z;
            cr_assert_float_eq(sqrt(rho * rho + dz * dz), fabs(s->radius_mm), 1e-11);
            cr_assert_eq(lens_sag_mm(s, -rho), sag);
            cr_assert_eq(lens_sag_mm(s, 0.0), 0.0);
        }
        lens_free(&l);
    }
}

Test(lens, sag_sign)
{
    lens l = read_shipped(&SHIPPED[0]);
    /* dgauss row 0, radius +29.475: bulges toward the scene, rim toward the film. */
    cr_assert_lt(lens_sag_mm(&l.surface[0], 12.6), 0.0);
    cr_assert_float_eq(lens_sag_mm(&l.surface[0], 12.6),
                       -(29.475 - sqrt(29.475 * 29.475 - 12.6 * 12.6)), 1e-12);
    /* Row 6, radius -14.495: centre toward the scene, rim toward it too. */
    cr_assert_gt(lens_sag_mm(&l.surface[6], 8.5), 0.0);
    cr_assert_float_eq(lens_sag_mm(&l.surface[6], 8.5),
                       14.495 - sqrt(14.495 * 14.495 - 8.5 * 8.5), 1e-12);
    lens_free(&l);
}

Test(lens, sag_of_nearly_flat_surface)
{
    /* R = 1e12: R - sqrt(R^2 - rho^2) is 0 in doubles; the sag is -rho^2 / (2R) to 1e-24. */
    lens l = parsed("1e12 2 1.5 20\n" STOP "-1e12 5 1 20\n");
    const double rho = 10.0, expected = rho * rho / (2.0 * 1e12);
    cr_assert_eq(sag_reference(1e12, rho), 0.0, "the reference no longer shows the cancellation");
    const double front = lens_sag_mm(&l.surface[0], rho);
    const double rear = lens_sag_mm(&l.surface[2], rho);
    cr_assert_lt(fabs(front + expected) / expected, 1e-12, "front sag %.17g", front);
    cr_assert_lt(fabs(rear - expected) / expected, 1e-12, "rear sag %.17g", rear);
    lens_free(&l);
}

Test(lens, sag_beyond_the_sphere_is_nan)
{
    lens_surface s = {.radius_mm = 5.0, .curvature_per_mm = 0.2};
    cr_assert(isnan(lens_sag_mm(&s, 6.0)));
}

/* ---- copy and free ---------------------------------------------------------------------- */

Test(lens, copy_is_independent)
{
    lens a = read_shipped(&SHIPPED[0]);
    lens_set_film_distance(&a, 36.77);
    lens b;
    cr_assert_eq(lens_copy(&b, &a), L2P_OK);
    cr_assert_neq(b.surface, a.surface);
    cr_assert_neq(b.path, a.path);
    cr_assert_neq(b.name, a.name);
    cr_assert_str_eq(b.path, a.path);
    cr_assert_str_eq(b.name, a.name);
    cr_assert_eq(b.count, a.count);
    cr_assert_eq(b.stop, a.stop);
    cr_assert_eq(b.stop_diameter_mm, a.stop_diameter_mm);
    cr_assert_eq(b.film_distance_mm, a.film_distance_mm);
    cr_assert_eq(memcmp(b.surface, a.surface, (size_t)a.count * sizeof *a.surface), 0);

    b.surface[0].radius_mm = 1.0;
    b.name[0] = 'X';
    b.stop_diameter_mm = 1.0;
    lens_set_film_distance(&b, 100.0);
    cr_assert_eq(a.surface[0].radius_mm, 29.475);
    cr_assert_str_eq(a.name, "dgauss.50mm");
    cr_assert_eq(a.stop_diameter_mm, 17.1);
    cr_assert_eq(a.surface[a.count - 1].vertex_z_mm, 36.77);

    lens_free(&a);
    cr_assert_eq(b.surface[1].radius_mm, 84.83);   /* b survives a's free */
    lens_free(&b);
}

Test(lens, free_is_safe)
{
    lens l = parsed(FRONT STOP REAR);
    lens_free(&l);
    cr_assert_null(l.surface);
    cr_assert_eq(l.count, 0);
    lens_free(&l);   /* twice: nothing left to free */
    lens_free(NULL);
    lens empty = {0}, copy;
    cr_assert_eq(lens_copy(&copy, &empty), L2P_OK);
    cr_assert_null(copy.surface);
    lens_free(&copy);
}
