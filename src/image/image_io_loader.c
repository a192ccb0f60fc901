/* The functions of image_io.h, forwarded to lens2pov-image-io.so, which is loaded with dlopen()
   on the first call. Linking OpenImageIO into the executable made every start-up load some 260
   libraries (0.3 s and 130 MB), also for `info` and `trace`, which never touch an image.

   The library is looked for, in order:
   - at $LENS2POV_IMAGE_IO, a full path (tests, debugging); when it is set nothing else is tried,
     so that a test can make loading fail;
   - beside the executable: where the build puts it (build/, build-san/, with the test runner);
   - in ../lib/lens2pov/ from the executable's folder: where `make install` puts it. */
#include "image/image_io.h"
#include "image/image_io_impl.h"
#include "base/exe_dir.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Filled once by load_bridge: either all three functions, or why there are none. */
static struct {
    image_io_read_rgba_fn *read_rgba;
    image_io_write_rgb_fn *write_rgb;
    image_io_get_attribute_fn *get_attribute;
    char why[1024];   /* "PATH (reason); PATH (reason)" for every path tried */
} bridge;

static pthread_once_t bridge_once = PTHREAD_ONCE_INIT;

/* dlerror()'s text usually starts with the path, which the message names already. */
static const char *without_path(const char *text, const char *path)
{
    if (!text)
        return "unknown error";
    const size_t n = strlen(path);
    if (strncmp(text, path, n) == 0 && strncmp(text + n, ": ", 2) == 0)
        return text + n + 2;
    return text;
}

static void note_failure(const char *path, const char *reason)
{
    const size_t n = strlen(bridge.why);
    snprintf(bridge.why + n, sizeof bridge.why - n, "%s%s (%s)", n ? "; " : "", path,
             without_path(reason, path));
}

static void *symbol(void *library, const char *name, const char *path)
{
    void *p = dlsym(library, name);
    if (!p)
        note_failure(path, dlerror());
    return p;
}

/* Loads path and resolves the three functions; true when all of them are there. RTLD_NOW, so
   that a library that does not fit (a missing symbol) fails here, with dlerror's reason, rather
   than in the middle of a run. The library is never dlclose'd: OpenImageIO keeps threads and
   caches to the end of the process, and valgrind needs its symbols to report on them. */
static bool try_load(const char *path)
{
    void *library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!library) {
        note_failure(path, dlerror());
        return false;
    }
    void *read = symbol(library, "image_io_impl_read_rgba", path);
    void *write = read ? symbol(library, "image_io_impl_write_rgb", path) : NULL;
    void *get = write ? symbol(library, "image_io_impl_get_attribute", path) : NULL;
    if (!get)
        return false;
    /* POSIX guarantees that dlsym's void * converts to a function pointer. */
    bridge.read_rgba = (image_io_read_rgba_fn *)read;
    bridge.write_rgb = (image_io_write_rgb_fn *)write;
    bridge.get_attribute = (image_io_get_attribute_fn *)get;
    return true;
}

enum { CANDIDATES = 2 };

/* The paths the library is looked for at, in order (see the top); the count, or 0 with *why
   naming what went wrong. */
static int candidates(char path[CANDIDATES][PATH_MAX + 64], const char **where, const char **why)
{
    const char *forced = getenv("LENS2POV_IMAGE_IO");
    if (forced && *forced) {
        *where = forced;
        /* dlopen would search its library path for a bare name: say so rather than guess. */
        if (!strchr(forced, '/')) {
            *why = "LENS2POV_IMAGE_IO must be a path, with a '/'";
            return 0;
        }
        snprintf(path[0], sizeof path[0], "%s", forced);
        return 1;
    }
    char dir[PATH_MAX];
    *where = "/proc/self/exe";
    if (!exe_dir(dir, sizeof dir, why))
        return 0;
    snprintf(path[0], sizeof path[0], "%s/" IMAGE_IO_LIBRARY, dir);
    snprintf(path[1], sizeof path[1], "%s/../lib/lens2pov/" IMAGE_IO_LIBRARY, dir);
    return 2;
}

static void load_bridge(void)
{
    char path[CANDIDATES][PATH_MAX + 64];
    const char *where, *why;
    const int n = candidates(path, &where, &why);
    if (n == 0)
        note_failure(where, why);
    for (int i = 0; i < n && !try_load(path[i]); i++)
        continue;
}

static int cannot_load(l2p_error *err, const char *tried)
{
    return l2p_fail(err, L2P_FAILED, NULL, 0,
                    "cannot load the image library " IMAGE_IO_LIBRARY " (OpenImageIO): tried %s",
                    tried);
}

/* Loads the library on the first call from any thread; L2P_FAILED (err set, when given) when it
   cannot be loaded. */
static int bridge_ready(l2p_error *err)
{
    pthread_once(&bridge_once, load_bridge);
    return bridge.read_rgba ? L2P_OK : cannot_load(err, bridge.why);
}

int image_io_ready(l2p_error *err) { return bridge_ready(err); }

int image_io_present(l2p_error *err)
{
    char path[CANDIDATES][PATH_MAX + 64], why[CANDIDATES * (PATH_MAX + 64 + 256) + 1024] = "";
    const char *where, *reason;
    const int n = candidates(path, &where, &reason);
    if (n == 0)
        snprintf(why, sizeof why, "%s (%s)", where, reason);
    for (int i = 0; i < n; i++) {
        if (access(path[i], R_OK) == 0)
            return L2P_OK;
        const size_t len = strlen(why);
        snprintf(why + len, sizeof why - len, "%s%s (%s)", len ? "; " : "", path[i], strerror(errno));
    }
    return cannot_load(err, why);
}

int image_read_rgba(const char *path, int *width, int *height, float **pixels, l2p_error *err)
{
    const int st = bridge_ready(err);
    return st ? st : bridge.read_rgba(path, width, height, pixels, err);
}

int image_write_rgb(const char *path, int width, int height, const float *pixels,
                    const image_attribute *attributes, int attribute_count, l2p_error *err)
{
    const int st = bridge_ready(err);
    return st ? st
              : bridge.write_rgb(path, width, height, pixels, attributes, attribute_count, err);
}

int image_get_attribute(const char *path, const char *name, char *buf, size_t len)
{
    const int st = bridge_ready(NULL);
    return st ? st : bridge.get_attribute(path, name, buf, len);
}
