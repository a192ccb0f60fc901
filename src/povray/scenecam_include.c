/* Cameras the probe would miss: a statement in a file the scene includes from its folder. The
   probe copies and rewrites the scene's own text only; POV-Ray, run in the scene's folder,
   finds an #include there first (docs/povray.md), and a camera statement in such a file
   would run unseen. Standard includes (the library path) set no camera and are not read. */
#include "povray/scenecam.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_DEPTH = 8, NAME_MAX_BYTES = 1024 };

typedef struct walk {
    const char *scene;        /* for messages */
    const char *folder;       /* the scene's folder, where POV-Ray runs */
    int depth, scene_line;    /* the scene's #include line that led here */
    l2p_error *err;
    int status;
} walk;

static char *read_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *s = NULL;
    size_t cap = 0;
    *n = 0;
    for (;;) {
        if (*n + 4096 + 1 > cap) {
            char *grown = realloc(s, cap = 2 * cap + 8192);
            if (!grown)
                break;
            s = grown;
        }
        const size_t got = fread(s + *n, 1, 4096, f);
        *n += got;
        if (got == 0)
            break;
    }
    fclose(f);
    if (s)
        s[*n] = '\0';
    return s;
}

static void check_text(walk *w, const char *text, size_t n);

static bool visit(const char *name, size_t len, int line, void *ctx)
{
    walk *w = ctx;
    if (len == 0 || len >= NAME_MAX_BYTES)
        return true;
    char path[4096 + NAME_MAX_BYTES + 2];
    if (name[0] == '/')
        snprintf(path, sizeof path, "%.*s", (int)len, name);
    else
        snprintf(path, sizeof path, "%s/%.*s", w->folder, (int)len, name);
    size_t n;
    char *text = read_file(path, &n);
    if (!text)
        return true;   /* a library include, or one POV-Ray will report */
    const int scene_line = w->scene_line;
    if (w->depth == 0)
        w->scene_line = line;
    int at;
    if (scene_text_has_camera(text, n, &at))
        w->status = l2p_fail(w->err, L2P_BAD_INPUT, w->scene, w->scene_line,
                             "the camera is set in %s (line %d), a file the scene includes: "
                             "lens2pov reads only the scene's own camera statements; give "
                             "--location and --look-at", path, at);
    else if (w->depth < MAX_DEPTH) {
        w->depth++;
        check_text(w, text, n);
        w->depth--;
    }
    w->scene_line = scene_line;
    free(text);
    return w->status == L2P_OK;
}

static void check_text(walk *w, const char *text, size_t n)
{
    scene_text_includes(text, n, visit, w);
}

int scene_camera_check_includes(const char *scene_path, l2p_error *err)
{
    size_t n;
    char *text = read_file(scene_path, &n);
    if (!text)
        return L2P_OK;   /* the probe reports an unreadable scene */
    char folder[4096];
    snprintf(folder, sizeof folder, "%s", scene_path);
    char *slash = strrchr(folder, '/');
    if (slash)
        *slash = '\0';
    else
        snprintf(folder, sizeof folder, ".");
    walk w = {scene_path, folder, 0, 0, err, L2P_OK};
    check_text(&w, text, n);
    free(text);
    return w.status;
}
