/* Bad input never crashes and never loses data (issue 5, part 3):
   - every invalid option value is refused with exit 2, one line on stderr that starts with
     "lens2pov: " and names the option, and no output at all;
   - every malformed lens file is refused with exit 2 and "lens2pov: FILE:LINE: what", and no
     output;
   - killing lens2pov in the middle of writing leaves the previous outputs intact: SIGINT and
     SIGTERM also leave no temporary file behind; SIGKILL cannot be caught, so its temporary
     files (PREFIX.inc.tmp followed by 12 random hex digits, ...) stay, but the outputs
     themselves are never touched, because they only ever appear by rename(2).
   The fuzz targets (tests/fuzz/) and valgrind (tools/valgrind.sh) cover the rest. */
#include <criterion/criterion.h>
#include <criterion/parameterized.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "base/outfile.h"
#include "image/image_io.h"
#include "support.h"

extern char **environ;

#define COOKE LENS_DIR "cooke-triplet.50mm.dat"
#define DGAUSS LENS_DIR "dgauss.50mm.dat"

/* Files in dir other than those listed (NULL-terminated); returns how many, and names the
   first in *first (static buffer). */
static int unexpected_files(const char *dir, const char *const *allowed, const char **first)
{
    static char name[256];
    DIR *d = opendir(dir);
    cr_assert_not_null(d, "%s", dir);
    int n = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        bool ok = false;
        for (int i = 0; allowed && allowed[i]; i++)
            ok |= !strcmp(e->d_name, allowed[i]);
        if (!ok && n++ == 0)
            snprintf(name, sizeof name, "%s", e->d_name);
    }
    closedir(d);
    *first = name;
    return n;
}

/* ---------------------------------------------------------------- invalid options */

/* One bad command line: words after "lens2pov" (OUT is replaced by a prefix in a fresh
   folder, OUTEXR by an image path there, SCENE by a scene there, DIR by the folder itself),
   and words the message must contain. */
typedef struct bad_line {
    const char *words[16];
    const char *expect;
} bad_line;

static const bad_line BAD_OPTIONS[] = {
    /* sizes and samples: zero, negative, not a number, fractional, empty, out of range */
    {{"trace", DGAUSS, "--width", "0", "-o", "OUT"}, "--width"},
    {{"trace", DGAUSS, "--width", "-640", "-o", "OUT"}, "--width"},
    {{"trace", DGAUSS, "--width", "abc", "-o", "OUT"}, "--width"},
    {{"trace", DGAUSS, "--width", "1.5", "-o", "OUT"}, "--width"},
    {{"trace", DGAUSS, "--width", "", "-o", "OUT"}, "--width"},
    {{"trace", DGAUSS, "--width", "99999999999", "-o", "OUT"}, "at most 2147483647"},
    {{"trace", DGAUSS, "--width=0", "-o", "OUT"}, "--width"},
    {{"trace", DGAUSS, "--height", "0", "-o", "OUT"}, "--height"},
    {{"trace", DGAUSS, "--height", "-1", "-o", "OUT"}, "--height"},
    {{"trace", DGAUSS, "--spp", "0", "-o", "OUT"}, "--spp"},
    {{"trace", DGAUSS, "--spp", "-4", "-o", "OUT"}, "--spp"},
    {{"trace", DGAUSS, "--spp", "4x", "-o", "OUT"}, "--spp"},
    {{"trace", DGAUSS, "--width", "100000", "--height", "100000", "-o", "OUT"}, "pixels"},
    /* film */
    {{"trace", DGAUSS, "--film-diagonal", "0", "-o", "OUT"}, "--film-diagonal"},
    {{"trace", DGAUSS, "--film-diagonal", "-35", "-o", "OUT"}, "--film-diagonal"},
    {{"trace", DGAUSS, "--film-diagonal", "nan", "-o", "OUT"}, "--film-diagonal"},
    {{"trace", DGAUSS, "--film-diagonal", "inf", "-o", "OUT"}, "--film-diagonal"},
    {{"trace", DGAUSS, "--film-diagonal", "1e999", "-o", "OUT"}, "--film-diagonal"},
    {{"trace", DGAUSS, "--film-distance", "-1", "-o", "OUT"}, "--film-distance"},
    {{"trace", DGAUSS, "--film-distance", "far", "-o", "OUT"}, "--film-distance"},
    {{"trace", DGAUSS, "--focus-distance", "0", "-o", "OUT"}, "--focus-distance"},
    {{"trace", DGAUSS, "--focus-distance", "-2", "-o", "OUT"}, "--focus-distance"},
    {{"trace", DGAUSS, "--focus-distance", "nan", "-o", "OUT"}, "--focus-distance"},
    {{"trace", DGAUSS, "--crop", "0,0,0,0", "-o", "OUT"}, "--crop"},
    {{"trace", DGAUSS, "--crop", "1,2,3", "-o", "OUT"}, "--crop"},
    {{"trace", DGAUSS, "--crop", "0,0,700,10", "-o", "OUT"}, "--crop"},
    {{"trace", DGAUSS, "--crop", "5,5,2,9", "-o", "OUT"}, "--crop"},
    {{"trace", DGAUSS, "--crop", "0,0,99999999999,1", "-o", "OUT"}, "--crop"},
    /* aperture */
    {{"trace", DGAUSS, "--aperture-diameter", "0", "-o", "OUT"}, "--aperture-diameter"},
    {{"trace", DGAUSS, "--aperture-diameter", "-3", "-o", "OUT"}, "--aperture-diameter"},
    {{"trace", DGAUSS, "--aperture-diameter", "100", "-o", "OUT"}, "aperture diameter"},
    {{"trace", DGAUSS, "--f-number", "0", "-o", "OUT"}, "--f-number"},
    {{"trace", DGAUSS, "--f-number", "0.1", "-o", "OUT"}, "--f-number"},
    /* names */
    {{"trace", DGAUSS, "--pupil", "exit", "-o", "OUT"}, "--pupil"},
    {{"trace", DGAUSS, "--pupil", "", "-o", "OUT"}, "--pupil"},
    {{"trace", DGAUSS, "--trace", "paraxial", "-o", "OUT"}, "--trace"},
    {{"trace", DGAUSS, "--weighting", "cos4", "-o", "OUT"}, "--weighting"},
    /* contradictions */
    {{"trace", DGAUSS, "--film-distance", "36", "--focus-distance", "3", "-o", "OUT"},
     "--film-distance and --focus-distance"},
    {{"trace", DGAUSS, "--focus-distance", "inf", "--film-distance", "36", "-o", "OUT"},
     "--film-distance and --focus-distance"},
    {{"trace", DGAUSS, "--aperture-diameter", "5", "--f-number", "4", "-o", "OUT"},
     "--aperture-diameter and --f-number"},
    {{"trace", DGAUSS, "--rays", "OUT.inc", "-o", "OUT"}, "--rays"},
    {{"trace", DGAUSS, "--rays", "OUT.map", "-o", "OUT"}, "--rays"},
    {{"trace", DGAUSS, "--rays", "OUT.exr", "-o", "OUT"}, "--rays"},
    {{"trace", DGAUSS, "--sampling", "field", "--rays", "OUT.f000.inc", "-o", "OUT"}, "--rays"},
    {{"trace", DGAUSS, "--sampling", "field", "--rays", "OUT.f001.exr", "-o", "OUT"}, "--rays"},
    {{"trace", DGAUSS, "--memory-mb", "1", "--rays", "OUT.c000.ini", "-o", "OUT"}, "--rays"},
    /* placement */
    {{"trace", DGAUSS, "--location", "1,2", "-o", "OUT"}, "--location"},
    {{"trace", DGAUSS, "--location", "1,2,nan", "-o", "OUT"}, "--location"},
    {{"trace", DGAUSS, "--look-at", "<0,0,1", "-o", "OUT"}, "--look-at"},
    {{"trace", DGAUSS, "--look-at", "0,0,0", "-o", "OUT"}, "--look-at"},
    {{"trace", DGAUSS, "--sky", "0,0,1", "-o", "OUT"}, "--sky must not be parallel"},
    {{"trace", DGAUSS, "--sky", "0,0,0", "-o", "OUT"}, "--sky must be a direction"},
    {{"trace", DGAUSS, "--location", "0,0,-1e308", "--look-at", "0,0,1e308", "-o", "OUT"},
     "too far apart"},
    {{"trace", DGAUSS, "--unit-mm", "0", "-o", "OUT"}, "--unit-mm"},
    {{"trace", DGAUSS, "--unit-mm", "-1000", "-o", "OUT"}, "--unit-mm"},
    {{"trace", DGAUSS, "--seed", "-1", "-o", "OUT"}, "--seed"},
    {{"trace", DGAUSS, "--seed", "99999999999999999999999", "-o", "OUT"}, "--seed"},
    {{"trace", DGAUSS, "--unit-mm", "1e-9", "-o", "OUT"}, "--unit-mm"},
    {{"trace", DGAUSS, "--unit-mm", "1e12", "-o", "OUT"}, "--unit-mm"},
    /* running */
    {{"render", "SCENE", DGAUSS, "--jobs", "0", "-o", "OUTEXR"}, "--jobs"},
    {{"render", "SCENE", DGAUSS, "--jobs", "100000", "-o", "OUTEXR"}, "--jobs"},
    {{"render", "SCENE", DGAUSS, "--memory-mb", "0", "-o", "OUTEXR"}, "--memory-mb"},
    {{"render", "SCENE", DGAUSS, "--memory-mb", "-5", "-o", "OUTEXR"}, "--memory-mb"},
    {{"render", "SCENE", DGAUSS, "--memory-mb", "1e300", "-o", "OUTEXR"}, "--memory-mb"},
    {{"render", "SCENE", DGAUSS, "-o", "OUT.jpg"}, "image type"},
    {{"render", "SCENE", DGAUSS, "--width", "0", "-o", "OUTEXR"}, "--width"},
    /* blades */
    {{"trace", DGAUSS, "--aperture-blades", "2", "-o", "OUT"}, "--aperture-blades"},
    {{"trace", DGAUSS, "--aperture-blades", "33", "-o", "OUT"}, "--aperture-blades"},
    {{"trace", DGAUSS, "--aperture-blades", "-1", "-o", "OUT"}, "--aperture-blades"},
    {{"trace", DGAUSS, "--blade-rotation", "x", "-o", "OUT"}, "--blade-rotation"},
    {{"trace", DGAUSS, "--aperture-blades", "6", "--trace", "thick", "-o", "OUT"}, "--trace full"},
    {{"trace", DGAUSS, "--sampling", "field", "--memory-mb", "10", "-o", "OUT"}, "--memory-mb"},
    /* dispersion and wavelengths */
    {{"trace", DGAUSS, "--dispersion", "on", "-o", "OUT"}, "Abbe numbers"},
    {{"trace", COOKE, "--dispersion", "on", "--trace", "thick", "-o", "OUT"}, "--trace full"},
    {{"trace", COOKE, "--dispersion", "yes", "-o", "OUT"}, "--dispersion"},
    {{"trace", COOKE, "--wavelength", "500", "--dispersion", "on", "-o", "OUT"}, "--wavelength"},
    {{"info", COOKE, "--wavelength", "200"}, "--wavelength"},
    {{"info", COOKE, "--wavelength", "nan"}, "--wavelength"},
    {{"info", COOKE, "--dispersion", "on"}, "does not take --dispersion"},
    /* the command line itself */
    {{"trace", DGAUSS, "--frobnicate", "1", "-o", "OUT"}, "--frobnicate"},
    {{"trace", DGAUSS, "-o"}, "-o"},
    {{"trace", DGAUSS, "-o", ""}, "-o"},
    {{"trace", DGAUSS, "--rays", "", "-o", "OUT"}, "--rays"},
    {{"trace", DGAUSS}, "-o"},
    {{"trace", DGAUSS, DGAUSS, "-o", "OUT"}, "argument"},
    {{"frobnicate", DGAUSS, "-o", "OUT"}, "frobnicate"},
    {{"info", DGAUSS, "--width", "0"}, "--width"},
    {{"info", DGAUSS, "--spp", "-1"}, "--spp"},
    /* options the command does not take */
    {{"trace", DGAUSS, "--jobs", "2", "-o", "OUT"}, "trace does not take --jobs"},
    {{"info", DGAUSS, "--quiet"}, "info does not take --quiet"},
    {{"info", DGAUSS, "--seed", "3"}, "info does not take --seed"},
    {{"info", DGAUSS, "-o", "OUT"}, "info does not take -o"},
    {{"develop", "OUT", "--spp", "4", "-o", "OUTEXR"}, "develop does not take --spp"},
    {{"render", "SCENE", DGAUSS, "--json", "-o", "OUTEXR"}, "render does not take --json"},
    {{"info", DGAUSS, "--json=1"}, "--json"},
    /* a value forgotten: the next option is not taken for it */
    {{"plot", DGAUSS, "--what", "-o", "OUT.png"}, "--what needs a value, not the option -o"},
    {{"trace", DGAUSS, "--spp", "--quiet", "-o", "OUT"}, "--spp needs a value, not the option"},
    {{"diagram", DGAUSS, "-o", ".svg"}, "no file name before .svg"},
    {{"--version", "extra"}, "--version takes nothing"},
    /* the scene a folder; a kept folder made for a run refused before any work is not left */
    {{"render", "DIR", DGAUSS, "-o", "OUTEXR"}, "is a folder, not a scene file"},
    {{"render", "SCENE", DGAUSS, "--f-number", "1", "--keep-temp", "OUT", "-o", "OUTEXR"},
     "--f-number"},
};

/* The parameters of a test a row: row numbers, in Criterion's shared memory (a test's process
   cannot follow the table's pointers, which are the runner's). */
static void free_rows(struct criterion_test_params *p)
{
    cr_free(p->params);
}

static struct criterion_test_params row_numbers(size_t n)
{
    size_t *rows = cr_malloc(n * sizeof *rows);
    for (size_t i = 0; i < n; i++)
        rows[i] = i;
    return cr_make_param_array(size_t, rows, n, free_rows);
}

/* One test a row, so that Criterion runs them side by side and names the row that fails. */
ParameterizedTestParameters(robustness, bad_command_lines_are_refused)
{
    return row_numbers(sizeof BAD_OPTIONS / sizeof BAD_OPTIONS[0]);
}

ParameterizedTest(size_t *row, robustness, bad_command_lines_are_refused)
{
    const bad_line *b = &BAD_OPTIONS[*row];
    const char *dir = test_tmpdir();
    char out[512], outexr[512], scene[512], named[16][512];
    snprintf(out, sizeof out, "%s/p", dir);
    snprintf(outexr, sizeof outexr, "%s/p.exr", dir);
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    write_text(scene, "#version 3.7;\nbackground { rgb 1 }\n");
    char *w[16] = {0};
    char line[1024] = "";
    for (int k = 0; k < 15 && b->words[k]; k++) {
        const char *x = b->words[k];
        if (!strncmp(x, "OUT.", 4))   /* OUT.EXT: p.EXT in the folder */
            snprintf(named[k], sizeof named[k], "%s/p%s", dir, x + 3);
        w[k] = !strcmp(x, "OUT")           ? out
               : !strcmp(x, "OUTEXR")      ? outexr
               : !strncmp(x, "OUT.", 4)    ? named[k]
               : !strcmp(x, "SCENE")       ? scene
               : !strcmp(x, "DIR")         ? (char *)dir
                                           : (char *)x;
        strncat(line, x, sizeof line - strlen(line) - 2);
        strcat(line, " ");
    }
    char *errtext = NULL, *outtext = NULL;
    const int st = run_lens2pov(&outtext, &errtext, w[0], w[1], w[2], w[3], w[4], w[5], w[6],
                                w[7], w[8], w[9], w[10], w[11], w[12], w[13], w[14], NULL);
    cr_expect_eq(st, 2, "`%s`: exit %d: %s", line, st, errtext);
    cr_expect(strncmp(errtext, "lens2pov: ", 10) == 0, "`%s`: %s", line, errtext);
    cr_expect(strchr(errtext, '\n') == errtext + strlen(errtext) - 1,
              "`%s`: not one line: %s", line, errtext);
    cr_expect_not_null(strstr(errtext, b->expect), "`%s`: '%s' not in: %s", line, b->expect,
                       errtext);
    cr_expect_str_empty(outtext, "`%s`: wrote to stdout: %s", line, outtext);
    const char *const allowed[] = {"scene.pov", NULL};
    const char *first;
    cr_expect_eq(unexpected_files(dir, allowed, &first), 0, "`%s` left %s", line, first);
    free(errtext);
    free(outtext);
    remove_tree(dir);
}

/* A look-at point 1e155 away is far, not a sky along the view: the direction's squared
   length overflowed and the sky was refused as parallel to it. */
Test(robustness, a_far_look_at_point_is_a_direction)
{
    char *errtext = NULL, *outtext = NULL;
    cr_expect_eq(run_lens2pov(&outtext, &errtext, "info", DGAUSS, "--look-at", "0,0.5,1e155",
                              "--json", NULL), 0, "%s", errtext);
    cr_expect(outtext && strstr(outtext, "\"hfov_deg\": 31."), "%s", outtext ? outtext : "");
    free(errtext);
    free(outtext);
}

/* ---------------------------------------------------------------- malformed lens files */

typedef struct bad_lens {
    const char *text;
    int length;            /* 0: strlen(text) */
    int line;              /* the line the message must name; 0: the file only */
    const char *expect;
} bad_lens;

static const bad_lens BAD_LENSES[] = {
    {"", 0, 1, "no surfaces"},
    {"# nothing but a comment\n\n", 0, 2, "no surfaces"},
    {"50 5 1.5 20\n-50 0 1 20\n", 0, 2, "no aperture stop"},
    {"0 5 0 10\n", 0, 1, "only the aperture stop"},
    {"50 5 1.5\n0 5 0 10\n-50 0 1 20\n", 0, 1, "expected 4 numbers"},
    {"50 5 1.5 20 7 8\n0 5 0 10\n-50 0 1 20\n", 0, 1, "after the 5 numbers"},
    {"50 5 1.5 20\n0 5 0 10\n-50 0 1 20 0 abc\n", 0, 3, "after the 5 numbers"},
    {"50 5 1.5 20\n0 5 0 10\n-50 0 1 20 abc\n", 0, 3, "not a number"},
    /* the fifth column, the Abbe number */
    {"50 5 1.5 20 60\n0 5 0 10 2\n-50 0 1 20\n", 0, 2, "must be 0 on an air row"},
    {"50 5 1.5 20 60\n0 5 0 10\n-50 0 1 20 60\n", 0, 3, "must be 0 on an air row"},
    {"50 5 1.5 20 0\n0 5 0 10\n-50 0 1 20\n", 0, 1, "must be positive"},
    {"50 5 1.5 20 -60\n0 5 0 10\n-50 0 1 20\n", 0, 1, "must be positive"},
    {"50 5 1.5 20 nan\n0 5 0 10\n-50 0 1 20\n", 0, 1, "not a finite number"},
    {"50 5 1.5 20\n0 5 0 10\n-50 3 1.6 20 40\n-80 0 1 20\n", 0, 3, "give every glass row one"},
    {"50 5 1.5 20 60\n0 5 0 10\n-50 3 1.6 20\n-80 0 1 20\n", 0, 3, "give every glass row one"},
    {"50 5 1,5 20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "not a number"},
    {"0x10 5 1.5 20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "not a number"},
    {"50 5 1.5 nan\n0 5 0 10\n-50 0 1 20\n", 0, 1, "not a finite number"},
    {"50 5 1.5 20\n0 5 0 inf\n-50 0 1 20\n", 0, 2, "not a finite number"},
    {"50 5 1.5 20\n0 5 0 10\n-50 0 1 1e999\n", 0, 3, "out of range"},
    {"50 5 1.5 20\n0 4.9e-324 0 10\n-50 0 1 20\n", 0, 2, "out of range"},
    {"50 -5 1.5 20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "thickness"},
    {"50 5 0.5 20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "index of refraction"},
    {"50 5 0 20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "index of refraction"},
    {"50 5 1.5 -20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "aperture diameter"},
    {"50 5 1.5 0\n0 5 0 10\n-50 0 1 20\n", 0, 1, "aperture diameter"},
    {"5 5 1.5 20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "too small"},
    {"50 5 1.5 20\n0 5 0 10\n0 5 0 10\n-50 0 1 20\n", 0, 3, "second aperture stop"},
    {"50 5 1.5 20\n0 5 0 10\n-50 0 1 20\n\0\n", 34, 4, "NUL"},
    {"50 5 1.5 20\n0 5 0 10\n\xff\xfe-50 0 1 20\n", 0, 3, "byte"},
    {"50 5 1.5 20\r\n0 5 0 10\r\n-50 0 1.5 20 40 x\r\n", 0, 3, "after the 5 numbers"},
    {"1234567890123456789012345678901234567890123456789012345678901234567890 5 1.5 20\n", 0, 1,
     "a number of 70 characters"},
    /* rows that read as numbers but make no lens */
    {"50 5 1 20\n0 5 0 10\n-50 0 1 20\n", 0, 1, "afocal"},
    {"50 1e300 1.5 20\n0 5 0 10\n-50 0 1 20\n", 0, -1, ""},
    {"50 5 1e300 20\n0 5 0 10\n-50 0 1 20\n", 0, -1, ""},
    {"1e-300 5 1.5 1e-300\n0 5 0 10\n-50 0 1 20\n", 0, -1, ""},
    {"1e300 5 1.5 1e300\n0 5 0 1e300\n-1e300 0 1 1e300\n", 0, -1, ""},
    {"1e308 1e308 1e308 1e308\n0 1e308 0 1e308\n-1e308 0 1 1e308\n", 0, -1, ""},
    {"1e-307 1e-307 1 1e-307\n0 1e-307 0 1e-307\n-1e-307 0 1.5 1e-307\n", 0, -1, ""},
};

/* Rows with line -1: refused with exit 2 and FILE:LINE for some line of the file. `info`
   reads the lens the same way as `trace` and is run on the rows the optics refuse (where the
   two commands go through different code). One test a row. */
/* The refusal after any warnings (surfaces that cross, lens_lookup.c) on lines of their own. */
static const char *after_warnings(const char *errtext)
{
    while (errtext && strncmp(errtext, "lens2pov: warning: ", 19) == 0 && strchr(errtext, '\n'))
        errtext = strchr(errtext, '\n') + 1;
    return errtext;
}

ParameterizedTestParameters(robustness, bad_lens_files_are_refused_with_their_line)
{
    return row_numbers(sizeof BAD_LENSES / sizeof BAD_LENSES[0]);
}

ParameterizedTest(size_t *row, robustness, bad_lens_files_are_refused_with_their_line)
{
    const size_t i = *row;
    const bad_lens *b = &BAD_LENSES[i];
    const char *dir = test_tmpdir();
    char lens_path[512], out[512], csv[512];
    snprintf(lens_path, sizeof lens_path, "%s/bad.dat", dir);
    snprintf(out, sizeof out, "%s/p", dir);
    snprintf(csv, sizeof csv, "%s/p.csv", dir);
    FILE *f = fopen(lens_path, "wb");
    cr_assert_not_null(f);
    fwrite(b->text, 1, b->length ? (size_t)b->length : strlen(b->text), f);
    fclose(f);
    for (int cmd = b->line >= 0 && b->line <= 1 ? 1 : 0; cmd < 2; cmd++) {
        char *all = NULL;
        const int st = cmd == 0
                           ? run_lens2pov(NULL, &all, "info", lens_path, "--json", NULL)
                           : run_lens2pov(NULL, &all, "trace", lens_path, "--width", "8",
                                          "--height", "6", "--spp", "1", "--rays", csv, "-o",
                                          out, "--quiet", NULL);
        const char *errtext = after_warnings(all);
        cr_expect_eq(st, 2, "lens %zu (%s): exit %d: %s", i, cmd ? "trace" : "info", st,
                     errtext);
        char where[600];
        if (b->line > 0)
            snprintf(where, sizeof where, "lens2pov: %s:%d: ", lens_path, b->line);
        else
            snprintf(where, sizeof where, "lens2pov: %s:", lens_path);
        cr_expect(strncmp(errtext, where, strlen(where)) == 0, "lens %zu: '%s' expected in: %s",
                  i, where, errtext);
        if (b->line < 0) {
            /* Some line: "FILE:N: " with N a number. */
            const char *p = errtext + strlen(where);
            cr_expect(*p >= '1' && *p <= '9', "lens %zu: no line in: %s", i, errtext);
        }
        cr_expect_not_null(strstr(errtext, b->expect), "lens %zu: '%s' not in: %s", i,
                           b->expect, errtext);
        free(all);
    }
    const char *const allowed[] = {"bad.dat", NULL};
    const char *left;
    cr_expect_eq(unexpected_files(dir, allowed, &left), 0, "lens %zu left %s", i, left);
    remove_tree(dir);
}

/* A missing lens file, a folder and an unreadable file: exit 2 and the path. */
Test(robustness, lens_paths_that_are_not_files)
{
    const char *dir = test_tmpdir();
    const char *paths[] = {tmp_path(dir, "missing.dat"), dir};
    for (int i = 0; i < 2; i++) {
        char *errtext = NULL;
        const int st = run_lens2pov(NULL, &errtext, "trace", paths[i], "-o",
                                    tmp_path(dir, "p"), "--quiet", NULL);
        cr_expect_eq(st, 2, "%s: exit %d", paths[i], st);
        cr_expect_not_null(strstr(errtext, paths[i]), "%s", errtext);
        free(errtext);
    }
    const char *first;
    cr_expect_eq(unexpected_files(dir, NULL, &first), 0, "left %s", first);
    remove_tree(dir);
}

/* A complete small trace into DIR/p with its CSV, and the bytes of its four files, for the
   tests that check a later run leaves them alone. */
typedef struct previous_run {
    char *text[4];
    size_t length[4];
} previous_run;

static const char *const RUN_FILES[] = {"p.inc", "p.ini", "p.map", "p.csv"};

static previous_run make_previous_run(const char *dir)
{
    char prefix[512], csv[512];
    snprintf(prefix, sizeof prefix, "%s/p", dir);
    snprintf(csv, sizeof csv, "%s/p.csv", dir);
    cr_assert_eq(run_lens2pov(NULL, NULL, "trace", DGAUSS, "--width", "8", "--height", "6",
                              "--rays", csv, "-o", prefix, "--quiet", NULL), 0);
    previous_run r;
    for (int i = 0; i < 4; i++)
        cr_assert_not_null(r.text[i] = read_text(tmp_path(dir, RUN_FILES[i]), &r.length[i]));
    return r;
}

/* Each of the four files still holds the previous run's bytes; frees them. */
static void expect_previous_run(const char *dir, previous_run *r, const char *after_what)
{
    for (int i = 0; i < 4; i++) {
        size_t n;
        char *now = read_text(tmp_path(dir, RUN_FILES[i]), &n);
        cr_expect(now && n == r->length[i] && memcmp(now, r->text[i], n) == 0,
                  "after %s: %s is not the previous run's any more", after_what, RUN_FILES[i]);
        free(now);
        free(r->text[i]);
    }
}

/* A failed run (a bad option after good ones, a bad lens) leaves the outputs of the previous
   run untouched. */
Test(robustness, a_failed_run_leaves_the_previous_outputs_alone)
{
    const char *dir = test_tmpdir();
    const char *prefix = tmp_path(dir, "p"), *csv = tmp_path(dir, "p.csv");
    previous_run before = make_previous_run(dir);
    const char *bad = tmp_path(dir, "bad.dat");
    write_text(bad, "50 5 1.5 20\n0 5 0 10\n-50 0 1\n");
    cr_expect_eq(run_lens2pov(NULL, NULL, "trace", bad, "--rays", csv, "-o", prefix, "--quiet",
                              NULL), 2);
    cr_expect_eq(run_lens2pov(NULL, NULL, "trace", DGAUSS, "--width", "16", "--rays", csv,
                              "--aperture-diameter", "99", "-o", prefix, "--quiet", NULL), 2);
    expect_previous_run(dir, &before, "failed runs");
    const char *const allowed[] = {"p.inc", "p.ini", "p.map", "p.csv", "bad.dat", NULL};
    const char *first;
    cr_expect_eq(unexpected_files(dir, allowed, &first), 0, "left %s", first);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- killed while writing */

/* With attr (NULL: none), as posix_spawn takes it. */
static pid_t spawn_lens2pov_with(char *const argv[], const char *tmpdir,
                                 const posix_spawnattr_t *attr)
{
    const char *bin = getenv("LENS2POV");
    if (!bin)
        bin = LENS2POV_SOURCE_DIR "/build/lens2pov";
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
    /* The environment with TMPDIR replaced (render's workspace goes there). */
    char **env = NULL;
    size_t n = 0;
    while (environ[n])
        n++;
    env = calloc(n + 2, sizeof *env);
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (strncmp(environ[i], "TMPDIR=", 7))
            env[k++] = environ[i];
    char tmp[600];
    snprintf(tmp, sizeof tmp, "TMPDIR=%s", tmpdir);
    env[k++] = tmp;
    env[k] = NULL;
    char *args[32];
    args[0] = (char *)bin;
    for (int i = 0; argv[i]; i++) {
        args[i + 1] = argv[i];
        args[i + 2] = NULL;
    }
    pid_t pid;
    cr_assert_eq(posix_spawn(&pid, bin, &fa, attr, args, env), 0);
    posix_spawn_file_actions_destroy(&fa);
    free(env);
    return pid;
}

static pid_t spawn_lens2pov(char *const argv[], const char *tmpdir)
{
    return spawn_lens2pov_with(argv, tmpdir, NULL);
}

/* Whether dir holds a file whose name contains part, with at least min_bytes. */
static bool has_file(const char *dir, const char *part, off_t min_bytes)
{
    DIR *d = opendir(dir);
    if (!d)
        return false;
    bool found = false;
    for (struct dirent *e; !found && (e = readdir(d)) != NULL;) {
        if (!strstr(e->d_name, part))
            continue;
        char path[1024];
        struct stat s;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        found = stat(path, &s) == 0 && s.st_size >= min_bytes;
    }
    closedir(d);
    return found;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* Traces a big table into PREFIX, over a complete earlier run, and kills it once its
   temporary include holds a megabyte (or after 5 s). */
static void kill_trace_while_writing(int sig)
{
    const char *dir = test_tmpdir();
    char prefix[512], csv[512];
    snprintf(prefix, sizeof prefix, "%s/p", dir);
    snprintf(csv, sizeof csv, "%s/p.csv", dir);
    previous_run before = make_previous_run(dir);

    char *argv[] = {"trace", DGAUSS, "--width", "2000", "--height", "2000", "--spp", "4",
                    "--rays", csv, "-o", prefix, "--quiet", NULL};
    const pid_t pid = spawn_lens2pov(argv, dir);
    for (int waited = 0; waited < 5000 && !has_file(dir, "p.inc.tmp", 1 << 20); waited += 10)
        sleep_ms(10);
    cr_assert(has_file(dir, "p.inc.tmp", 1), "the big trace never started writing");
    sleep_ms(300);
    cr_assert_eq(kill(pid, sig), 0);
    int status = 0;
    cr_assert_eq(waitpid(pid, &status, 0), pid);
    cr_expect(WIFSIGNALED(status) && WTERMSIG(status) == sig,
              "signal %d: the run ended with status %#x", sig, status);

    char killed[32];
    snprintf(killed, sizeof killed, "signal %d", sig);
    expect_previous_run(dir, &before, killed);
    const char *const allowed[] = {"p.inc", "p.ini", "p.map", "p.csv", NULL};
    const char *first;
    const int stray = unexpected_files(dir, allowed, &first);
    if (sig != SIGKILL)
        cr_expect_eq(stray, 0, "signal %d left %s", sig, first);
    else
        cr_log_info("SIGKILL left %d temporary file(s), e.g. %s (expected: it cannot be caught)",
                    stray, stray ? first : "-");
    remove_tree(dir);
}

Test(robustness, sigint_while_writing_keeps_the_previous_outputs_and_no_temporary_file)
{
    kill_trace_while_writing(SIGINT);
}

Test(robustness, sigterm_while_writing_keeps_the_previous_outputs_and_no_temporary_file)
{
    kill_trace_while_writing(SIGTERM);
}

Test(robustness, sigkill_while_writing_keeps_the_previous_outputs)
{
    kill_trace_while_writing(SIGKILL);
}

/* render killed while POV-Ray runs: the previous image stays, and the workspace (in TMPDIR)
   and the temporary image are removed. */
Test(robustness, sigint_during_render_keeps_the_previous_image_and_cleans_up)
{
    const char *dir = test_tmpdir();
    char scene[512], image[512];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(image, sizeof image, "%s/img.png", dir);
    /* A scene slow enough to be caught in the middle: many spheres, reflective. */
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 20 }\n"
                      "background { rgb 0.3 }\nlight_source { <2, 5, -3> rgb 1 }\n"
                      "#for (I, 0, 400) sphere { <mod(I, 20) * 0.3 - 3, div(I, 20) * 0.3 - 3, 6>,"
                      " 0.2 pigment { rgb <1, 0.5, 0.2> } finish { reflection 0.8 } } #end\n");
    write_text(image, "previous image");
    char *argv[] = {"render", scene, DGAUSS, "--width", "320", "--height", "240", "--spp", "16",
                    "--look-at", "0,0,6", "--jobs", "2", "-o", image, "--quiet", NULL};
    const pid_t pid = spawn_lens2pov(argv, dir);
    for (int waited = 0; waited < 10000 && !has_file(dir, "lens2pov.", 0); waited += 10)
        sleep_ms(10);
    cr_assert(has_file(dir, "lens2pov.", 0), "render never made its workspace");
    sleep_ms(1500);
    cr_assert_eq(kill(pid, SIGINT), 0);
    int status = 0;
    cr_assert_eq(waitpid(pid, &status, 0), pid);
    cr_expect(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT, "status %#x", status);
    size_t n;
    char *text = read_text(image, &n);
    cr_expect(text && !strcmp(text, "previous image"), "the previous image was replaced");
    free(text);
    const char *const allowed[] = {"scene.pov", "img.png", NULL};
    const char *first;
    cr_expect_eq(unexpected_files(dir, allowed, &first), 0, "left %s", first);
    remove_tree(dir);
}

/* An animation stopped midway keeps the frames it finished, as POV-Ray's own would: each frame
   is developed as soon as its renders are in. A stand-in for POV-Ray renders frame 1 and
   sleeps in frames 2 and 3 (the scene-camera probe, -F, runs as it is); once frame 1's
   picture is there, SIGINT. Both samplings. */
Test(robustness, an_animation_stopped_midway_keeps_its_finished_frames)
{
    static const char *const samplings[] = {"field", "pixel"};
    for (int k = 0; k < 2; k++) {
        const char *dir = test_tmpdir();
        char scene[512], script[512], out[512], first[512], last[512];
        snprintf(scene, sizeof scene, "%s/scene.pov", dir);
        snprintf(script, sizeof script, "%s/slowpov", dir);
        snprintf(out, sizeof out, "%s/anim.png", dir);
        snprintf(first, sizeof first, "%s/anim1.png", dir);
        snprintf(last, sizeof last, "%s/anim3.png", dir);
        write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                          "background { rgb 0.3 }\nsphere { <0, 0, 6>, 1 pigment { rgb 1 } "
                          "finish { emission 1 } }\n");
        write_text(script, "#!/bin/sh\ncase \" $* \" in *\" -F \"*|*\" +SF1 \"*) "
                           "exec povray \"$@\";; esac\nexec sleep 60\n");
        chmod(script, 0755);
        setenv("LENS2POV_POVRAY", script, 1);
        char *argv[] = {"render", scene, DGAUSS, "--width", "32", "--height", "24", "--spp",
                        "4", "--sampling", (char *)samplings[k], "--look-at", "0,0,6", "-o", out,
                        "--quiet", "--", "+KFI1", "+KFF3", NULL};
        const pid_t pid = spawn_lens2pov(argv, dir);
        unsetenv("LENS2POV_POVRAY");
        for (int waited = 0; waited < 60000 && !has_file(dir, "anim1.png", 1); waited += 10)
            sleep_ms(10);
        cr_expect(has_file(dir, "anim1.png", 1), "%s: frame 1 never came", samplings[k]);
        cr_assert_eq(kill(pid, SIGINT), 0);
        int status = 0;
        cr_assert_eq(waitpid(pid, &status, 0), pid);
        cr_expect(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT, "status %#x", status);
        int w = 0, h = 0;
        float *px = NULL;
        l2p_error e;
        cr_expect_eq(image_read_rgba(first, &w, &h, &px, &e), 0, "%s: %s", samplings[k], e.text);
        cr_expect(w == 32 && h == 24 && px && px[4 * (12 * 32 + 16)] > 0.5f,
                  "%s: frame 1 is %dx%d, its centre %g", samplings[k], w, h, px ? px[4 * (12 * 32 + 16)] : -1.0);
        free(px);
        cr_expect(!file_exists(last), "%s: frame 3 was written", samplings[k]);
        const char *const allowed[] = {"scene.pov", "slowpov", "anim1.png", NULL};
        const char *left;
        cr_expect_eq(unexpected_files(dir, allowed, &left), 0, "%s: left %s", samplings[k], left);
        remove_tree(dir);
    }
}

/* The state letter of process pid (/proc/PID/stat: R, S, T, Z, ...); 0 when it is gone. */
static char process_state(int pid)
{
    char path[64], text[512] = "";
    snprintf(path, sizeof path, "/proc/%d/stat", pid);
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    const size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    const char *paren = strrchr(text, ')');   /* the command's name may hold anything */
    return paren && paren[1] == ' ' ? paren[2] : 0;
}

/* A user's POV-Ray wrapper that does not exec POV-Ray (a stand-in whose "render" is a sleeper
   in its background; the scene-camera probe, -F, runs POV-Ray as it is): Ctrl-Z (SIGTSTP)
   stops the sleeper with render, SIGCONT continues both, and SIGTERM ends render with
   everything it started and leaves nothing behind. */
Test(robustness, a_wrappers_povray_is_stopped_continued_and_ended_with_render)
{
    const char *dir = test_tmpdir();
    char scene[512], script[512], out[512], pidfile[512];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(script, sizeof script, "%s/wrapper", dir);
    snprintf(out, sizeof out, "%s/out.png", dir);
    snprintf(pidfile, sizeof pidfile, "%s/sleeper.pid", dir);
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
                      "background { rgb 0.3 }\n");
    char text[2000];
    snprintf(text, sizeof text, "#!/bin/sh\ncase \" $* \" in *\" -F \"*) exec povray \"$@\";; esac\n"
                                "sleep 60 & echo $! > '%s/sleeper.tmp' && mv '%s/sleeper.tmp' '%s'\nwait\n",
             dir, dir, pidfile);
    write_text(script, text);
    chmod(script, 0755);
    setenv("LENS2POV_POVRAY", script, 1);
    char *argv[] = {"render", scene, DGAUSS, "--width", "16", "--height", "12", "--spp", "2",
                    "--jobs", "1", "-o", out, "--quiet", NULL};
    /* As a shell with job control starts it: a process group of its own, whose parent is
       outside it (in an orphaned group, as the runner's may be, the system discards a stop),
       and SIGTSTP neither ignored nor blocked. */
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t tstp, none;
    sigemptyset(&tstp);
    sigaddset(&tstp, SIGTSTP);
    sigemptyset(&none);
    posix_spawnattr_setsigdefault(&attr, &tstp);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF |
                                        POSIX_SPAWN_SETSIGMASK);
    const pid_t pid = spawn_lens2pov_with(argv, dir, &attr);
    posix_spawnattr_destroy(&attr);
    unsetenv("LENS2POV_POVRAY");
    for (int waited = 0; waited < 60000 && !has_file(dir, "sleeper.pid", 1); waited += 10)
        sleep_ms(10);
    FILE *f = fopen(pidfile, "r");
    int sleeper = 0;
    cr_assert(f && fscanf(f, "%d", &sleeper) == 1, "the wrapper never started its sleeper");
    fclose(f);
    cr_expect_neq(process_state(sleeper), 'T', "the sleeper is stopped before Ctrl-Z");
    cr_assert_eq(kill(pid, SIGTSTP), 0);
    int status = 0;
    cr_assert_eq(waitpid(pid, &status, WUNTRACED), pid);
    cr_expect(WIFSTOPPED(status), "render did not stop: status %#x", status);
    char state = 0;
    for (int waited = 0; waited < 5000 && (state = process_state(sleeper)) != 'T'; waited += 10)
        sleep_ms(10);
    cr_expect_eq(state, 'T', "the sleeper is not stopped with render: %c", state);
    cr_assert_eq(kill(pid, SIGCONT), 0);
    for (int waited = 0; waited < 5000 && (state = process_state(sleeper)) == 'T'; waited += 10)
        sleep_ms(10);
    cr_expect(state && state != 'T', "the sleeper is not continued with render: %c", state);
    cr_assert_eq(kill(pid, SIGTERM), 0);
    cr_assert_eq(waitpid(pid, &status, 0), pid);
    cr_expect(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM, "status %#x", status);
    cr_expect(kill(sleeper, 0) != 0 && errno == ESRCH, "the sleeper %d is still there (%c)",
              sleeper, process_state(sleeper));
    const char *const allowed[] = {"scene.pov", "wrapper", "sleeper.pid", NULL};
    const char *left;
    cr_expect_eq(unexpected_files(dir, allowed, &left), 0, "left %s", left);
    remove_tree(dir);
}

/* Temporary files are created exclusively under unpredictable names: symbolic links planted at
   the names the previous code used (OUT.EXT.tmpPID, for the next few hundred process ids) are
   never written through, and two temporary files of one prefix get different names, each a
   new file of its own. */
Test(robustness, planted_links_never_receive_a_temporary_file)
{
    const char *dir = test_tmpdir();
    char *victim = strdup(tmp_path(dir, "victim"));   /* tmp_path's buffers rotate */
    write_text(victim, "keep me\n");
    const char *exts[] = {"inc", "ini", "map", "csv"};
    const pid_t next = getpid();
    for (int e = 0; e < 4; e++)
        for (int k = 0; k < 300; k++) {
            char name[64];
            snprintf(name, sizeof name, "out.%s.tmp%ld", exts[e], (long)next + k);
            cr_assert_eq(symlink(victim, tmp_path(dir, name)), 0);
        }
    run_lens2pov_ok("trace", "trace", DGAUSS, "--width", "8", "--height", "6", "--spp", "2", "-o",
                    tmp_path(dir, "out"), "--rays", tmp_path(dir, "out.csv"), "--quiet", NULL);
    size_t n;
    char *kept = read_text(victim, &n);
    cr_assert_str_eq(kept, "keep me\n", "a planted link was written through");
    free(kept);
    free(victim);
    struct stat sb;
    cr_assert_eq(lstat(tmp_path(dir, "out.ini"), &sb), 0);
    cr_assert(S_ISREG(sb.st_mode), "out.ini is a file of its own, not a link");

    char *a = NULL, *b = NULL;
    const char *prefix = tmp_path(dir, "t.tmp");
    const int fa = outfile_create_temp(prefix, ".x", &a), fb = outfile_create_temp(prefix, ".x", &b);
    cr_assert(fa >= 0 && fb >= 0);
    cr_assert_str_neq(a, b);
    cr_assert_eq(strncmp(a, prefix, strlen(prefix)), 0);
    cr_assert_eq(strlen(a), strlen(prefix) + 12 + 2, "%s", a);
    close(fa);
    close(fb);
    free(a);
    free(b);
}

/* Text outputs named by symbolic links (an absolute one and a chain of two) are written
   through them, and the links stay. */
Test(robustness, outputs_named_by_links_are_written_through_them)
{
    const char *dir = test_tmpdir();
    char *svg = strdup(tmp_path(dir, "lens.svg")), *csv = strdup(tmp_path(dir, "rays.csv"));
    char *svg_link = strdup(tmp_path(dir, "diagram.svg")), *csv_link = strdup(tmp_path(dir, "a.csv"));
    char *csv_middle = strdup(tmp_path(dir, "b.csv"));
    cr_assert_eq(symlink(svg, svg_link), 0);
    cr_assert_eq(symlink("b.csv", csv_link), 0);
    cr_assert_eq(symlink("rays.csv", csv_middle), 0);
    run_lens2pov_ok("diagram", "diagram", DGAUSS, "-o", svg_link, NULL);
    run_lens2pov_ok("trace", "trace", DGAUSS, "--width", "8", "--height", "6", "--spp", "1", "-o",
                    tmp_path(dir, "t"), "--rays", csv_link, "--quiet", NULL);
    struct stat sb;
    const char *links[] = {svg_link, csv_link, csv_middle};
    for (int i = 0; i < 3; i++) {
        cr_assert_eq(lstat(links[i], &sb), 0);
        cr_assert(S_ISLNK(sb.st_mode), "%s was replaced", links[i]);
    }
    size_t n;
    char *text = read_text(svg, &n);
    cr_assert(text && strstr(text, "<svg"), "the diagram did not reach the link's target");
    free(text);
    text = read_text(csv, &n);
    cr_assert(text && n > 100, "the rays did not reach the end of the chain");
    free(text);
    free(svg), free(csv), free(svg_link), free(csv_link), free(csv_middle);
}

/* An output may not be an input: each is refused (exit 2, naming the file and what it is)
   before any work, and the input is left as it was. */
Test(robustness, an_output_naming_an_input_is_refused)
{
    const char *dir = test_tmpdir();
    char *lens = strdup(tmp_path(dir, "mine.dat")), *scene = strdup(tmp_path(dir, "scene.png"));
    char *link = strdup(tmp_path(dir, "link.svg")), *prefix = strdup(tmp_path(dir, "t"));
    char *lens_inc = strdup(tmp_path(dir, "t.inc"));
    size_t n;
    char *text = read_text(DGAUSS, &n);
    write_text(lens, text);
    write_text(lens_inc, text);
    write_text(scene, "camera { location <0, 0, -5> look_at 0 } sphere { 0, 1 pigment { rgb 1 } }\n");
    cr_assert_eq(symlink(lens, link), 0);
    run_lens2pov_ok("trace", "trace", lens, "--width", "8", "--height", "6", "--spp", "1", "-o",
                    tmp_path(dir, "p"), "--quiet", NULL);
    char *picture = strdup(tmp_path(dir, "p.exr"));
    write_text(picture, "stands for POV-Ray's render\n");
    struct {
        const char *args[16], *victim, *role;
    } cases[] = {
        {{"trace", lens, "--width", "8", "--height", "6", "-o", prefix, "--rays", lens, NULL}, lens, "the lens"},
        {{"trace", lens_inc, "--width", "8", "--height", "6", "-o", prefix, NULL}, lens_inc, "the lens"},
        {{"diagram", lens, "-o", link, NULL}, lens, "the lens"},
        {{"render", scene, lens, "--width", "8", "--height", "6", "-o", scene, NULL}, scene, "the scene"},
        {{"develop", tmp_path(dir, "p"), "-o", picture, NULL}, picture, "a render to develop"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char *before = read_text(cases[k].victim, &n), *out = NULL, *errout = NULL;
        const int status = run_lens2pov_argv(&out, &errout, (char *const *)cases[k].args);
        cr_expect_eq(status, 2, "%s: exit %d: %s", cases[k].args[0], status, errout);
        cr_expect(errout && strstr(errout, cases[k].role), "%s: %s", cases[k].args[0], errout);
        char *after = read_text(cases[k].victim, &n);
        cr_expect_str_eq(after, before, "%s overwrote %s", cases[k].args[0], cases[k].victim);
        free(before), free(after), free(out), free(errout);
    }
    free(text), free(lens), free(scene), free(link), free(prefix), free(lens_inc), free(picture);
}

/* A stop so small that diffraction would blur every point over more than 1% of the film's
   diagonal is traced, with a warning naming the Airy disk at the working f-number: on the
   double-Gauss at f/10000, focused at 1 m, 2.44 x 550 nm x 10520 = 14.1 mm (a magnification
   of 1/19 adds 5% to the f-number); at f/64 (0.09 mm, 0.26% of 35 mm) nothing is said. The
   macro at 0.4 m and f/200 works at f/331 (its cone traced by an independent tracer):
   0.444 mm, more than 1% of 35 mm, where the f-number alone gave 0.27 mm. */
Test(robustness, a_stop_too_small_for_ray_optics_is_warned_of)
{
    const char *dir = test_tmpdir();
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "trace", DGAUSS, "--width", "8", "--height", "6", "--spp", "1",
                              "--f-number", "10000", "-o", tmp_path(dir, "a"), "--quiet", NULL), 0);
    cr_expect(strstr(errtext, "warning: at working f/1.052e+04 diffraction") &&
              strstr(errtext, "14.1 mm"), "%s", errtext);
    free(errtext);
    errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "trace", DGAUSS, "--width", "8", "--height", "6", "--spp", "1",
                              "--f-number", "64", "-o", tmp_path(dir, "b"), "--quiet", NULL), 0);
    cr_expect(!strstr(errtext, "diffraction"), "%s", errtext);
    free(errtext);
    errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "trace", LENS_DIR "macro.105mm.dat", "--width", "8",
                              "--height", "6", "--spp", "1", "--f-number", "200",
                              "--focus-distance", "0.4", "-o", tmp_path(dir, "c"), "--quiet",
                              NULL), 0);
    cr_expect(strstr(errtext, "warning: at working f/330.6 diffraction") &&
              strstr(errtext, "0.444 mm"), "%s", errtext);
    free(errtext);
}

/* Whether process pid is gone: no such process, or a zombie waiting for a reaper. */
static bool process_gone(long pid)
{
    if (kill((pid_t)pid, 0) != 0 && errno == ESRCH)
        return true;
    char path[64], state = '?';
    snprintf(path, sizeof path, "/proc/%ld/stat", pid);
    FILE *f = fopen(path, "r");
    if (!f)
        return true;
    const int got = fscanf(f, "%*d (%*[^)]) %c", &state);
    fclose(f);
    return got == 1 && (state == 'Z' || state == 'X');
}

/* render killed outright (SIGKILL: no handler runs) stops its POV-Ray processes all the same
   (they get the parent-death signal), and the next render removes the workspace it left. The
   stand-in for POV-Ray writes its pid and sleeps for a minute. */
Test(robustness, render_killed_outright_leaves_no_povray_and_its_workspace_goes_next_time)
{
    const char *dir = test_tmpdir();
    char *scene = strdup(tmp_path(dir, "scene.pov")), *pids = strdup(tmp_path(dir, "pids"));
    char *fake = strdup(tmp_path(dir, "fakepov")), *image = strdup(tmp_path(dir, "img.png"));
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb 1 }\n");
    char script[1200];
    snprintf(script, sizeof script, "#!/bin/sh\necho $$ >> '%s'\nexec sleep 60\n", pids);
    write_text(fake, script);
    cr_assert_eq(chmod(fake, 0755), 0);
    cr_assert_eq(setenv("LENS2POV_POVRAY", fake, 1), 0);
    char *argv[] = {"render", scene, DGAUSS, "--width", "64", "--height", "48", "--spp", "4",
                    "--jobs", "2", "--memory-mb", "0.15", "-o", image, "--quiet", NULL};
    const pid_t pid = spawn_lens2pov(argv, dir);
    long started[2] = {0, 0};
    int n = 0;
    for (int waited = 0; waited < 20000 && n < 2; waited += 20) {
        sleep_ms(20);
        FILE *f = fopen(pids, "r");
        for (n = 0; f && n < 2 && fscanf(f, "%ld", &started[n]) == 1;)
            n++;
        if (f)
            fclose(f);
    }
    cr_assert_eq(n, 2, "the two POV-Ray stand-ins never started");
    cr_assert_eq(kill(pid, SIGKILL), 0);
    cr_assert_eq(waitpid(pid, NULL, 0), pid);
    for (int k = 0; k < 2; k++) {
        int waited = 0;
        while (waited < 5000 && !process_gone(started[k])) {
            sleep_ms(20);
            waited += 20;
        }
        cr_expect(process_gone(started[k]), "POV-Ray stand-in %ld outlived lens2pov", started[k]);
    }
    char left[64];
    snprintf(left, sizeof left, "lens2pov.%ld.", (long)pid);
    cr_assert(has_file(dir, left, 0), "the killed render left no workspace to clean");
    /* The next render, with the real POV-Ray, sweeps it away. */
    cr_assert_eq(unsetenv("LENS2POV_POVRAY"), 0);
    char *again[] = {"render", scene, DGAUSS, "--width", "8", "--height", "6", "--spp", "1",
                     "-o", image, "--quiet", NULL};
    const pid_t next = spawn_lens2pov(again, dir);
    int status = 0;
    cr_assert_eq(waitpid(next, &status, 0), next);
    cr_assert(WIFEXITED(status) && WEXITSTATUS(status) == 0, "status %#x", status);
    cr_expect_not(has_file(dir, left, 0), "the killed render's workspace is still there");
    free(scene);
    free(pids);
    free(fake);
    free(image);
}

/* Every output is checked before any work: a missing folder, a folder where a file is
   expected, a device. Exit 2 with a message naming the path, nothing written, and before the tracing:
   the 79 M samples asked for take far longer to trace and write, so a bound of 10 s leaves
   room for a sanitizer build on a loaded machine (2 s seen) and still tells the two apart. */
Test(robustness, bad_output_paths_are_refused_before_any_work)
{
    const char *dir = test_tmpdir();
    char *scene = strdup(tmp_path(dir, "scene.pov")), *sub = strdup(tmp_path(dir, "sub"));
    char *missing = strdup(tmp_path(dir, "missing/x")), *missing_png = strdup(tmp_path(dir, "missing/x.png"));
    char *out = strdup(tmp_path(dir, "out")), *png = strdup(tmp_path(dir, "out.png"));
    write_text(scene, "background { rgb 1 }\n");
    cr_assert_eq(mkdir(sub, 0755), 0);
    cr_assert_eq(mkdir(tmp_path(dir, "dir.png"), 0755), 0);
    char *dir_png = strdup(tmp_path(dir, "dir.png"));
    /* Names POV-Ray's .ini (or its command line, for the workspace) cannot carry. */
    char *quote = strdup(tmp_path(dir, "a\"b")), *newline = strdup(tmp_path(dir, "a\nb"));
    char *accent = strdup(tmp_path(dir, "caf\xc3\xa9")), *keep_quote = strdup(tmp_path(dir, "k\"eep"));
    char *keep_missing = strdup(tmp_path(dir, "missing/keep"));
    struct {
        const char *args[16];
        const char *named;
    } cases[] = {
        {{"trace", DGAUSS, "-o", missing}, missing},
        {{"trace", DGAUSS, "-o", out, "--rays", sub}, sub},
        {{"trace", DGAUSS, "-o", out, "--rays", missing}, missing},
        {{"render", scene, DGAUSS, "--width", "1280", "--height", "960", "--spp", "64", "-o", missing_png}, missing_png},
        {{"render", scene, DGAUSS, "--width", "1280", "--height", "960", "--spp", "64", "-o", dir_png}, dir_png},
        {{"render", scene, DGAUSS, "--width", "1280", "--height", "960", "--spp", "64", "-o", png, "--rays", sub}, sub},
        {{"develop", out, "-o", missing_png}, missing_png},
        {{"trace", DGAUSS, "-o", quote}, quote},
        {{"trace", DGAUSS, "-o", newline}, newline},
        {{"trace", DGAUSS, "-o", accent}, accent},
        {{"render", scene, DGAUSS, "--width", "1280", "--height", "960", "--spp", "64", "-o", png, "--keep-temp", keep_quote}, keep_quote},
        {{"render", scene, DGAUSS, "--width", "1280", "--height", "960", "--spp", "64", "-o", png, "--keep-temp", keep_missing}, keep_missing},
        {{"render", scene, DGAUSS, "--width", "1280", "--height", "960", "--spp", "64", "-o", png, "--keep-temp", scene}, scene},
        /* a device: nothing can be renamed onto it */
        {{"trace", DGAUSS, "-o", out, "--rays", "/dev/null"}, "/dev/null: is not a regular file"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *const *a = cases[i].args;
        char *errtext = NULL;
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        const int st = run_lens2pov(NULL, &errtext, a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7],
                                    a[8], a[9], a[10], a[11], a[12], a[13], a[14], a[15], NULL);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        const double seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        cr_expect_eq(st, 2, "case %zu: exit %d: %s", i, st, errtext);
        cr_expect(errtext && strstr(errtext, cases[i].named), "case %zu: %s", i, errtext);
        cr_expect_lt(seconds, 10.0, "case %zu took %.2f s", i, seconds);
        free(errtext);
        const char *const allowed[] = {"scene.pov", "sub", "dir.png", NULL};
        const char *first;
        cr_expect_eq(unexpected_files(dir, allowed, &first), 0, "case %zu wrote %s", i, first);
    }
    free(scene);
    free(sub);
    free(missing);
    free(missing_png);
    free(out);
    free(png);
    free(dir_png);
    free(quote);
    free(newline);
    free(accent);
    free(keep_quote);
    free(keep_missing);
}

/* ';', '#', '\'' and ',' end or split an unquoted .ini value: the ini quotes a name that has
   them, and POV-Ray writes the render where it says. */
Test(robustness, ini_names_renders_with_semicolons_and_commas_quoted)
{
    const char *dir = test_tmpdir();
    char *prefix = strdup(tmp_path(dir, "x;y,z#w'v"));
    cr_assert_eq(run_lens2pov(NULL, NULL, "trace", DGAUSS, "--width", "8", "--height", "6",
                              "-q", "-o", prefix, NULL), 0);
    char ini[600], want[700];
    snprintf(ini, sizeof ini, "%s.ini", prefix);
    snprintf(want, sizeof want, "Output_File_Name=\"%s.exr\"\n", prefix);
    char *text = read_text(ini, NULL);
    cr_assert_not_null(text);
    cr_expect_not_null(strstr(text, want), "%s", text);
    free(text);
    free(prefix);
    remove_tree(dir);
}

/* Every command answers --help with exit 0 on stdout, naming each option it takes and its
   default, whatever else is on the line; --version names the program. */
Test(robustness, every_command_has_help_and_there_is_a_version)
{
    const struct {
        const char *command;
        const char *options[12];
    } cases[] = {
        {"info", {"--json", "--width", "--pupil", "--unit-mm", "[640 x 480]"}},
        {"trace", {"--output", "--rays", "--memory-mb", "--quiet", "--crop", "--unit-mm", "[1000]"}},
        {"develop", {"--output"}},
        {"render", {"--output", "--jobs", "--memory-mb", "--rays", "--keep-temp", "--quiet",
                    "--f-number", "[1024]", "[stop-image"}},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char *out = NULL, *errtext = NULL;
        const int st = run_lens2pov(&out, &errtext, cases[i].command, "--width", "7", "--help", NULL);
        cr_assert_eq(st, 0, "%s --help: exit %d: %s", cases[i].command, st, errtext);
        cr_assert(strstr(out, "usage: lens2pov ") && strstr(out, cases[i].command), "%s", out);
        for (int k = 0; cases[i].options[k]; k++)
            cr_expect(strstr(out, cases[i].options[k]), "%s --help lacks %s", cases[i].command,
                      cases[i].options[k]);
        free(out);
        free(errtext);
    }
    char *out = NULL, *errtext = NULL;
    cr_assert_eq(run_lens2pov(&out, &errtext, "--version", NULL), 0);
    cr_assert_eq(strncmp(out, "lens2pov ", 9), 0, "%s", out);
    free(out);
    free(errtext);
}

/* "--name" options a help text lists (long names only), into names[], at most max. */
static int listed_options(const char *help, char names[][32], int count, int max)
{
    for (const char *p = help; (p = strstr(p, "--")) != NULL; p += 2) {
        if (p > help && p[-1] != ' ' && p[-1] != '|')
            continue;
        size_t n = 2;
        while ((p[n] >= 'a' && p[n] <= 'z') || p[n] == '-')
            n++;
        bool seen = false;
        for (int i = 0; i < count; i++)
            seen |= strlen(names[i]) == n && !strncmp(names[i], p, n);
        if (!seen && n > 2 && n < 32 && count < max)
            snprintf(names[count++], 32, "%.*s", (int)n, p);
    }
    return count;
}

static bool help_lists(const char *help, const char *name)
{
    char names[64][32];
    const int n = listed_options(help, names, 0, 64);
    for (int i = 0; i < n; i++)
        if (!strcmp(names[i], name))
            return true;
    return false;
}

/* The options a command accepts are exactly those its --help lists: every option any command
   lists is tried on every command; where it is not listed, the refusal names the command and
   the option (exit 2); where it is, it is not refused as foreign. */
Test(robustness, each_command_takes_exactly_the_options_its_help_lists)
{
    static const char *const commands[] = {"info", "trace", "develop", "render"};
    char *help[4];
    char names[64][32];
    int count = 0;
    for (int k = 0; k < 4; k++) {
        cr_assert_eq(run_lens2pov(&help[k], NULL, commands[k], "--help", NULL), 0);
        count = listed_options(help[k], names, count, 64);
    }
    cr_assert_gt(count, 20, "%d options in the help texts", count);
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < count; i++) {
            char *errtext = NULL, expect[2100];
            const int st = run_lens2pov(NULL, &errtext, commands[k], names[i], NULL);
            snprintf(expect, sizeof expect, "%s does not take %s", commands[k], names[i]);
            if (help_lists(help[k], names[i]))
                cr_expect_null(strstr(errtext, "does not take"), "%s: %s", expect, errtext);
            else
                cr_expect(st == 2 && strstr(errtext, expect), "%s %s: exit %d: %s", commands[k],
                          names[i], st, errtext);
            free(errtext);
        }
    for (int k = 0; k < 4; k++)
        free(help[k]);
}

/* info prints the camera only when a camera option asks for one: not for --json alone. */
Test(robustness, info_prints_the_camera_only_for_camera_options)
{
    char *out = NULL;
    cr_assert_eq(run_lens2pov(&out, NULL, "info", DGAUSS, "--json", NULL), 0);
    cr_expect_null(strstr(out, "film_distance_mm"), "%s", out);
    free(out);
    cr_assert_eq(run_lens2pov(&out, NULL, "info", DGAUSS, "--json", "--width", "64", NULL), 0);
    cr_expect_not_null(strstr(out, "film_distance_mm"), "%s", out);
    free(out);
}

/* ---------------------------------------------------------------- size estimates */

static double seconds_since(const struct timespec *t0)
{
    struct timespec t1;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    return (double)(t1.tv_sec - t0->tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0->tv_nsec);
}

/* A request no disk holds (4e11 rays: tens of terabytes; with field sampling, terabytes of
   renders and weights) is refused from its estimate in well under a second, naming it, with
   nothing written; the same options on a small film work. */
Test(robustness, requests_that_cannot_fit_are_refused_before_tracing)
{
    const char *dir = test_tmpdir();
    char *scene = strdup(tmp_path(dir, "scene.pov")), *out = strdup(tmp_path(dir, "out"));
    char *png = strdup(tmp_path(dir, "out.png")), *keep = strdup(tmp_path(dir, "keep"));
    char *csv = strdup(tmp_path(dir, "out.csv"));
    write_text(scene, "background { rgb 1 }\n");
    const char *huge[] = {"--width", "20000", "--height", "20000", "--spp", "1000"};
    struct {
        const char *args[16];
    } cases[] = {
        {{"trace", DGAUSS, huge[0], huge[1], huge[2], huge[3], huge[4], huge[5], "-o", out}},
        {{"trace", DGAUSS, huge[0], huge[1], huge[2], huge[3], huge[4], huge[5], "-o", out,
          "--rays", csv}},
        {{"render", scene, DGAUSS, huge[0], huge[1], huge[2], huge[3], huge[4], huge[5], "-o",
          png}},
        {{"render", scene, DGAUSS, huge[0], huge[1], huge[2], huge[3], huge[4], huge[5], "-o",
          png, "--keep-temp", keep}},
        {{"render", scene, DGAUSS, "--width", "320", "--height", "240", "--spp", "100000", "-o",
          png}},
        {{"render", scene, DGAUSS, huge[0], huge[1], huge[2], huge[3], huge[4], huge[5], "-o",
          png, "--sampling", "field"}},
        {{"render", scene, DGAUSS, huge[0], huge[1], huge[2], huge[3], huge[4], huge[5], "-o",
          png, "--sampling", "field", "--rays", csv}},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *const *a = cases[i].args;
        char *errtext = NULL;
        struct timespec t0;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        const int st = run_lens2pov(NULL, &errtext, a[0], a[1], a[2], a[3], a[4], a[5], a[6], a[7],
                                    a[8], a[9], a[10], a[11], a[12], a[13], a[14], NULL);
        const double seconds = seconds_since(&t0);
        cr_expect_eq(st, 2, "case %zu: exit %d: %s", i, st, errtext);
        cr_expect(errtext && strstr(errtext, "--no-size-check") && strstr(errtext, "B of "),
                  "case %zu: %s", i, errtext);
        cr_expect_lt(seconds, 10.0, "case %zu took %.2f s", i, seconds);
        free(errtext);
        const char *const allowed[] = {"scene.pov", NULL};
        const char *first;
        cr_expect_eq(unexpected_files(dir, allowed, &first), 0, "case %zu wrote %s", i, first);
    }
    cr_expect_eq(run_lens2pov(NULL, NULL, "trace", DGAUSS, "--width", "20", "--height", "15",
                              "--spp", "2", "-o", out, "-q", NULL), 0);
    cr_expect_eq(run_lens2pov(NULL, NULL, "trace", DGAUSS, "--width", "20", "--height", "15",
                              "--spp", "2", "-o", out, "-q", "--no-size-check", NULL), 0);
    free(scene);
    free(out);
    free(png);
    free(keep);
    free(csv);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- all or nothing */

/* trace replaces its set (include, ini, map, CSV) whole or not at all: a --rays that is a
   folder, or a map or ini whose name is a folder, is refused before any work, and the
   previous run's four files are left as they were. */
Test(robustness, trace_replaces_its_set_whole_or_not_at_all)
{
    const char *dir = test_tmpdir();
    char *prefix = strdup(tmp_path(dir, "p")), *csv = strdup(tmp_path(dir, "p.csv"));
    char *folder = strdup(tmp_path(dir, "sub"));
    previous_run before = make_previous_run(dir);
    cr_assert_eq(mkdir(folder, 0755), 0);
    char *errtext = NULL;
    cr_expect_eq(run_lens2pov(NULL, &errtext, "trace", DGAUSS, "--width", "16", "--height", "12",
                              "--rays", folder, "-o", prefix, "-q", NULL), 2, "%s", errtext);
    cr_expect(errtext && strstr(errtext, folder), "%s", errtext);
    free(errtext);
    expect_previous_run(dir, &before, "--rays naming a folder");

    /* p.map a folder: the other three stay the previous run's. */
    before = make_previous_run(dir);
    char *map = strdup(tmp_path(dir, "p.map")), *saved = strdup(tmp_path(dir, "p.map.saved"));
    cr_assert_eq(rename(map, saved), 0);
    cr_assert_eq(mkdir(map, 0755), 0);
    cr_expect_eq(run_lens2pov(NULL, &errtext, "trace", DGAUSS, "--width", "16", "--height", "12",
                              "--rays", csv, "-o", prefix, "-q", NULL), 2, "%s", errtext);
    cr_expect(errtext && strstr(errtext, map), "%s", errtext);
    free(errtext);
    cr_assert_eq(rmdir(map), 0);
    cr_assert_eq(rename(saved, map), 0);
    expect_previous_run(dir, &before, "p.map being a folder");
    const char *const allowed[] = {"p.inc", "p.ini", "p.map", "p.csv", "sub", NULL};
    const char *first;
    cr_expect_eq(unexpected_files(dir, allowed, &first), 0, "left %s", first);
    free(prefix);
    free(csv);
    free(folder);
    free(map);
    free(saved);
    remove_tree(dir);
}

/* ---------------------------------------------------------------- info validates as trace */

/* A lens that forms no real image (a biconcave singlet; the double-Gauss with its second
   index typed 16.99, whose focal length comes out negative) is refused by info exactly as by trace. */
Test(robustness, info_refuses_the_lenses_trace_refuses_with_the_same_message)
{
    static const char *const lenses[] = {
        "-50 5 1.5 20\n0 5 0 10\n50 0 1 20\n",
        "29.475 3.76 1.67 25.2\n84.83 0.12 16.99 25.2\n19.275 4.025 1.67 23\n"
        "40.77 3.275 1.699 23\n12.75 5.705 1 18\n0 4.5 0 17.1\n-14.495 1.18 1.603 17\n"
        "40.77 6.065 1.658 20\n-20.385 0.19 1 20\n437.065 3.22 1.717 20\n-39.73 0 1 20\n",
    };
    for (size_t i = 0; i < sizeof lenses / sizeof lenses[0]; i++) {
        const char *dir = test_tmpdir();
        char *lens = strdup(tmp_path(dir, "bad.dat")), *out = strdup(tmp_path(dir, "p"));
        write_text(lens, lenses[i]);
        char *info_err = NULL, *trace_err = NULL, *info_out = NULL;
        const int si = run_lens2pov(&info_out, &info_err, "info", lens, NULL);
        const int st = run_lens2pov(NULL, &trace_err, "trace", lens, "-o", out, "-q", NULL);
        cr_expect_eq(si, 2, "lens %zu: info exit %d: %s", i, si, info_out);
        cr_expect_eq(st, 2, "lens %zu: trace exit %d", i, st);
        cr_expect_str_eq(info_err, trace_err, "lens %zu", i);
        cr_expect_not_null(strstr(info_err, "diverges light"), "lens %zu: %s", i, info_err);
        cr_expect_str_empty(info_out, "lens %zu", i);
        free(info_err);
        free(trace_err);
        free(info_out);
        free(lens);
        free(out);
        remove_tree(dir);
    }
}

/* A POV-Ray that fails with nothing in its log that says why: the workspace and its logs go
   with the render, so the message quotes the log's last line and says how to keep the logs;
   with --keep-temp it names the log, which is there. The stand-in prints what POV-Ray prints
   around such an end and exits with status 3. */
Test(robustness, a_povray_failure_without_a_reason_quotes_its_log)
{
    const char *dir = test_tmpdir();
    char *scene = strdup(tmp_path(dir, "scene.pov")), *fake = strdup(tmp_path(dir, "fakepov"));
    char *image = strdup(tmp_path(dir, "img.png")), *kept = strdup(tmp_path(dir, "kept"));
    write_text(scene, "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb 1 }\n");
    write_text(fake, "#!/bin/sh\necho 'Parsing 1K tokens'\necho 'Render failed'\nexit 3\n");
    cr_assert_eq(chmod(fake, 0755), 0);
    static const char *const samplings[] = {"pixel", "field"};
    for (int k = 0; k < 2; k++)
        for (int keep = 0; keep < 2; keep++) {
            cr_assert_eq(setenv("LENS2POV_POVRAY", fake, 1), 0);
            char *args[] = {"render", scene, DGAUSS, "--width", "16", "--height", "12", "--spp", "2",
                            "--sampling", (char *)samplings[k], "-o", image, "--quiet",
                            keep ? "--keep-temp" : NULL, kept, NULL};
            char *errtext = NULL;
            const int status = run_lens2pov_argv(NULL, &errtext, args);
            cr_assert_eq(unsetenv("LENS2POV_POVRAY"), 0);
            cr_expect_eq(status, 1, "%s: %s", samplings[k], errtext);
            cr_expect(errtext && strstr(errtext, "failed with status 3"), "%s", errtext);
            const char *log = errtext ? strstr(errtext, "log: ") : NULL;
            if (keep) {
                char path[4096] = "";
                if (log)
                    sscanf(log + 5, "%4095[^)]", path);
                cr_expect(log && strncmp(path, kept, strlen(kept)) == 0 && file_exists(path),
                          "%s: %s", samplings[k], errtext);
            } else {
                cr_expect(!log && strstr(errtext, "its log ends \"Render failed\"") &&
                              strstr(errtext, "--keep-temp"), "%s: %s", samplings[k], errtext);
            }
            cr_expect(!file_exists(image));
            free(errtext);
            if (keep)
                remove_tree(kept);
        }
    free(scene), free(fake), free(image), free(kept);
}
