#include "cli/lens_lookup.h"

#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "base/exe_dir.h"

static bool is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && !S_ISDIR(st.st_mode);
}

/* DIR/NAME, then DIR/NAME.dat, into path. */
static bool find_in(const char *dir, const char *name, char *path, size_t size)
{
    snprintf(path, size, "%s/%s", dir, name);
    if (is_file(path))
        return true;
    snprintf(path, size, "%s/%s.dat", dir, name);
    return is_file(path);
}

int lens_lookup(const char *name, char **path, l2p_error *err)
{
    /* The executable's parent: PREFIX when installed (PREFIX/bin/lens2pov), the source tree
       when built there (build/lens2pov). */
    char found[PATH_MAX + 64], prefix[PATH_MAX], installed[PATH_MAX + 32] = "",
         source[PATH_MAX + 16] = "";
    const char *why;
    if (exe_dir(prefix, sizeof prefix, &why) && strrchr(prefix, '/')) {
        *strrchr(prefix, '/') = '\0';
        snprintf(installed, sizeof installed, "%s/share/lens2pov/lenses", prefix);
        snprintf(source, sizeof source, "%s/lenses", prefix);
    }
    /* A name with a '/' is a path: it is looked for nowhere else. */
    bool ok = is_file(name);
    if (ok)
        snprintf(found, sizeof found, "%s", name);
    else if (!strchr(name, '/'))
        ok = find_in("lenses", name, found, sizeof found) ||
             (*installed && find_in(installed, name, found, sizeof found)) ||
             (*source && find_in(source, name, found, sizeof found));
    if (!ok && !strchr(name, '/'))
        return l2p_fail(err, L2P_BAD_INPUT, name, 0,
                        "no such lens file, nor a lens of that name in ./lenses%s%s%s%s",
                        *installed ? ", " : "", installed, *source ? " or " : "", source);
    if (!ok)
        snprintf(found, sizeof found, "%s", name);
    *path = strdup(found);
    return *path ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
}

/* A lens whose surfaces cross cannot be made, but its rays can be traced (each surface is met
   in the file's order): a warning, not a refusal. */
static void warn_crossing(const lens *l)
{
    double rho, gap;
    const int i = lens_crossing(l, &rho, &gap);
    if (i >= 0)
        fprintf(stderr, "lens2pov: warning: %s:%d: this surface and the next (line %d) cross "
                "inside their clear apertures: %.4g mm from the axis the next stands %.4g mm in "
                "front of it; the rays are traced as if they did not\n", l->path,
                l->surface[i].line, l->surface[i + 1].line, rho, -gap);
}

/* The last row's index is the medium the film sits in: a film in glass or oil is possible (an
   immersion lens), but far more often the row was copied from the surface above, and every
   focal length and f-number is then n times too long. */
static void warn_film_medium(const lens *l)
{
    const lens_surface *rear = &l->surface[l->count - 1];
    if (rear->ior != 1.0)
        fprintf(stderr, "lens2pov: warning: %s:%d: the last row's index %g is the medium between "
                "the rear surface and the film: the film sits in it, not in air (a lens in air "
                "ends with index 1)\n", l->path, rear->line, rear->ior);
}

int lens_read_named(const char *name, lens *l, l2p_error *err)
{
    char *path;
    int st = lens_lookup(name, &path, err);
    if (st)
        return st;
    st = lens_read(path, l, err);
    free(path);
    if (!st) {
        warn_crossing(l);
        warn_film_medium(l);
    }
    return st;
}
