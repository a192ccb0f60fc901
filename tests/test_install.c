/* make install into a temporary prefix: the man page renders without warnings, the installed
   lens2pov runs from another folder on an installed lens, and the installed batch script
   answers --help. */
#include <criterion/criterion.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "support.h"

/* The build folder of the binary under test (build, or build-san under the sanitizers). */
static const char *build_dir(void)
{
    static char dir[1024];
    const char *bin = getenv("LENS2POV");
    snprintf(dir, sizeof dir, "%s", bin && *bin ? bin : LENS2POV_SOURCE_DIR "/build/lens2pov");
    return dirname(dir);
}

static int shell(const char *fmt, const char *a, const char *b)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, fmt, a, b);
    return system(cmd);
}

Test(install, installs_man_page_script_lenses_and_docs_that_work)
{
    const char *prefix = test_tmpdir();
    char *p = strdup(prefix);
    cr_assert_eq(shell("make -s -C '" LENS2POV_SOURCE_DIR "' install PREFIX='%s' BUILD='%s' "
                       ">/dev/null", p, build_dir()), 0);
    static const char *const files[] = {
        "bin/lens2pov", "bin/lens2pov-render-all", "share/man/man1/lens2pov.1",
        "share/lens2pov/lenses/dgauss.50mm.dat", "share/doc/lens2pov/README.md",
        "share/doc/lens2pov/docs/contracts.md", "lib/lens2pov/lens2pov-image-io.so",
        "lib/lens2pov/lens2pov-povray-polls.so"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++)
        cr_expect_eq(access(tmp_path(p, files[i]), R_OK), 0, "%s not installed", files[i]);

    /* The man page: groff's warnings (-ww) on stderr would be the page's faults. */
    cr_expect_eq(shell("groff -man -Tutf8 -ww '%s/share/man/man1/lens2pov.1' >'%s/man.txt' "
                       "2>&1", p, p), 0);
    size_t n;
    char *man = read_text(tmp_path(p, "man.txt"), &n);
    cr_assert_not_null(man);
    cr_expect(n > 2000, "the page is %zu bytes", n);
    cr_expect_null(strstr(man, "warning"), "%s", man);
    free(man);

    /* The installed tool, from another folder, on an installed lens. */
    cr_expect_eq(shell("cd / && '%s/bin/lens2pov' info '%s/share/lens2pov/lenses/dgauss.50mm.dat' "
                       ">/dev/null", p, p), 0);
    /* ... and on a lens given by name, found in the installed lens folder. */
    cr_expect_eq(shell("cd / && '%s/bin/lens2pov' info dgauss.50mm >'%s/byname.txt'", p, p), 0);
    char *byname = read_text(tmp_path(p, "byname.txt"), NULL);
    char where[600];
    snprintf(where, sizeof where, "%s/share/lens2pov/lenses/dgauss.50mm.dat (", p);
    cr_expect(byname && strncmp(byname, where, strlen(where)) == 0, "%s", byname ? byname : "");
    free(byname);
    /* The batch script answers --help with its usage (exit 2, as for a wrong command line). */
    cr_expect_eq(shell("cd / && '%s/bin/lens2pov-render-all' --help 2>'%s/help.txt'; "
                       "test $? -eq 2", p, p), 0);
    char *help = read_text(tmp_path(p, "help.txt"), NULL);
    cr_expect(help && strstr(help, "SCENE OUTDIR"), "%s", help ? help : "(none)");
    free(help);
    shell("rm -rf '%s'%s", p, "");
    free(p);
}
