/* Which renders `lens2pov develop PREFIX` takes: renders given in another order than their
   chunks are refused, and a render an earlier trace of the same prefix left is not taken for
   the new trace's. No POV-Ray: the names are checked before any picture is read. */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include "support.h"

#define DGAUSS LENS_DIR "dgauss.50mm.dat"

/* A pixel trace of PREFIX in chunks; returns how many (its .ini files). */
static int chunked_trace(const char *dir, const char *prefix)
{
    run_lens2pov_ok("chunked trace", "trace", DGAUSS, "--sampling", "pixel", "--width", "64",
                    "--height", "48", "--spp", "64", "--memory-mb", "8", "-o",
                    tmp_path(dir, prefix), "--quiet", NULL);
    int chunks = 0;
    char name[64];
    for (;; chunks++) {
        snprintf(name, sizeof name, "%s.c%03d.ini", prefix, chunks);
        if (!file_exists(tmp_path(dir, name)))
            return chunks;
    }
}

/* develop PREFIX with the renders named (printf formats of the chunk number k, in the order
   given by `order`); returns the exit status, *errtext its messages. */
static int develop_given(const char *dir, const char *format, const int *order, int n,
                         char **errtext)
{
    char *args[40] = {"develop", strdup(tmp_path(dir, "t"))};
    int a = 2;
    for (int k = 0; k < n; k++) {
        char name[64];
        snprintf(name, sizeof name, format, order[k]);
        args[a++] = strdup(tmp_path(dir, name));
    }
    args[a++] = "-o";
    args[a++] = strdup(tmp_path(dir, "out.png"));
    args[a] = NULL;
    const int st = run_lens2pov_argv(NULL, errtext, args);
    for (int k = 1; k < a; k++)
        if (strcmp(args[k], "-o"))
            free(args[k]);
    return st;
}

/* Two chunks' renders swapped, by their own names or with an animation's frame number after
   them, are refused naming the render and both places; in their order they are taken (and,
   not rendered, reported missing). */
Test(develop_names, renders_given_out_of_order_are_refused)
{
    const char *dir = test_tmpdir();
    const int n = chunked_trace(dir, "t");
    cr_assert(n >= 3 && n <= 30, "%d chunks", n);
    int order[30];
    for (int k = 0; k < n; k++)
        order[k] = k;
    char *errtext = NULL;
    cr_assert_eq(develop_given(dir, "t.c%03d.exr", order, n, &errtext), 2);
    cr_expect(strstr(errtext, "t.c000.exr") && strstr(errtext, "cannot read"), "%s", errtext);
    free(errtext);
    order[1] = 2, order[2] = 1;
    cr_assert_eq(develop_given(dir, "t.c%03d.exr", order, n, &errtext), 2);
    cr_expect(strstr(errtext, "t.c002.exr is given as render 1 but named as render 2"), "%s",
              errtext);
    free(errtext);
    cr_assert_eq(develop_given(dir, "t.c%03d07.exr", order, n, &errtext), 2);
    cr_expect(strstr(errtext, "t.c00207.exr is given as render 1 but named as render 2"), "%s",
              errtext);
    free(errtext);
    cr_expect_not(file_exists(tmp_path(dir, "out.png")));
}

/* A trace in one chunk of its own (--memory-mb) names its render PREFIX.c000.exr; traced
   again without, PREFIX.exr. The earlier render left beside the new trace is not developed
   in the new one's place: develop says the new render is missing. */
Test(develop_names, an_earlier_traces_render_is_not_taken)
{
    const char *dir = test_tmpdir();
    const char *prefix = tmp_path(dir, "t");
    run_lens2pov_ok("one chunk", "trace", DGAUSS, "--sampling", "pixel", "--width", "8",
                    "--height", "6", "--spp", "1", "--memory-mb", "8", "-o", prefix, "--quiet",
                    NULL);
    cr_assert(file_exists(tmp_path(dir, "t.c000.ini")));
    write_text(tmp_path(dir, "t.c000.exr"), "an earlier render");
    const struct timespec pause = {0, 20000000};
    nanosleep(&pause, NULL);   /* the new trace's files are newer */
    run_lens2pov_ok("no chunks", "trace", DGAUSS, "--sampling", "pixel", "--width", "8",
                    "--height", "6", "--spp", "1", "-o", prefix, "--quiet", NULL);
    cr_assert(file_exists(tmp_path(dir, "t.ini")));
    char *errtext = NULL;
    cr_assert_eq(run_lens2pov(NULL, &errtext, "develop", prefix, "-o", tmp_path(dir, "out.png"),
                              NULL), 2);
    cr_expect(strstr(errtext, "t.exr: cannot read") && !strstr(errtext, "c000"), "%s", errtext);
    free(errtext);
    cr_expect_not(file_exists(tmp_path(dir, "out.png")));
}
