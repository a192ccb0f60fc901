/* The probe's copy of a scene and of the files it includes. A camera statement in an included
   file runs where the #include stands, so such a file is copied too, its statements printing
   their items under the file's number (scene_camera_rewrite_file), and the #include that
   reads it is pointed at the copy; so is every file on the way to it. Files are found as
   POV-Ray finds them: in the scene's folder, where it runs, then on its library path, where
   standard includes such as screen.inc and stdcam.inc set cameras too (docs/povray.md). */
#include "povray/scenecam.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "base/readfile.h"

/* MAX_READS bounds the work a web of includes that include each other can make (results
   that reach an open file are not kept, so such a file may be read again). */
enum { MAX_DEPTH = 8, MAX_READS = 2000, NAME_MAX_BYTES = 1024 };

typedef struct seen {
    char *path;
    int file;                  /* its number in the copy, 0 when it needs none */
    bool open;                 /* being read: an #include of itself is not followed */
} seen;

typedef struct copier {
    const char *folder, *work;
    char *const *library;      /* POV-Ray's library folders, NULL-terminated */
    seen *seen;
    int seen_count, seen_cap, reads;
    bool partial;              /* the file being read reached an open file or MAX_DEPTH */
    scene_copy *out;
    l2p_error *err;
    int status;
} copier;

/* The #includes of one text whose files have copies: where each name stands, which copy. */
typedef struct swap {
    size_t at, len;
    int file;
} swap;

typedef struct swaps {
    const char *text;
    swap *swap;
    int count, cap, depth;
    copier *c;
} swaps;

static int out_of_memory(copier *c)
{
    if (!c->status)
        c->status = l2p_fail(c->err, L2P_FAILED, NULL, 0, "out of memory");
    return c->status;
}

/* A new file number for path, with no copy yet; -1 when out of memory. */
static int add_file(copier *c, const char *path)
{
    scene_copy *o = c->out;
    char **p = realloc(o->path, (size_t)(o->count + 1) * sizeof *p);
    if (p)
        o->path = p;
    char **q = p ? realloc(o->copy, (size_t)(o->count + 1) * sizeof *q) : NULL;
    if (q)
        o->copy = q;
    if (!p || !q || !(o->path[o->count] = strdup(path)))
        return out_of_memory(c), -1;
    o->copy[o->count] = NULL;
    return o->count++;
}

static char *copy_text(copier *c, const char *path, const char *text, size_t n, int depth,
                       int *file);

/* The file number of the copy of the file at path, 0 when it needs none. */
static int copy_of(copier *c, const char *path, int depth)
{
    for (int i = 0; i < c->seen_count; i++)
        if (!strcmp(c->seen[i].path, path)) {
            c->partial = c->partial || c->seen[i].open;
            return c->seen[i].open ? 0 : c->seen[i].file;
        }
    if (++c->reads > MAX_READS) {
        c->partial = true;
        return 0;
    }
    if (c->seen_count == c->seen_cap) {
        seen *grown = realloc(c->seen, (size_t)(c->seen_cap = 2 * c->seen_cap + 8) * sizeof *grown);
        if (!grown)
            return out_of_memory(c), 0;
        c->seen = grown;
    }
    const int at = c->seen_count;
    if (!(c->seen[at].path = strdup(path)))
        return out_of_memory(c), 0;
    c->seen[at].file = 0;
    c->seen[at].open = true;
    c->seen_count++;
    size_t n = 0;
    char *text = read_whole_file(path, &n);   /* unreadable: POV-Ray will say so */
    if (!text && errno == ENOMEM)
        out_of_memory(c);
    if (text && memchr(text, '\0', n)) {   /* not text: POV-Ray will say what it makes of it */
        free(text);
        text = NULL;
    }
    /* A result reached through a file still open (an #include cycle) or cut at MAX_DEPTH may
       miss a camera: it is not kept for a later #include of the same file. */
    const bool was_partial = c->partial;
    c->partial = false;
    int file = -1;
    char *copy = text ? copy_text(c, path, text, n, depth, &file) : NULL;
    free(text);
    if (copy) {
        char name[4200];
        snprintf(name, sizeof name, "%s/include-%d.inc", c->work, file);
        FILE *f = fopen(name, "wb");
        const bool ok = f && fputs(copy, f) >= 0;
        if ((f && fclose(f) != 0) || !ok) {
            c->status = l2p_fail(c->err, L2P_FAILED, name, 0, "cannot write: %s", strerror(errno));
            unlink(name);
        } else if (!(c->out->copy[file] = strdup(name))) {
            out_of_memory(c);
            unlink(name);
        } else {
            c->seen[at].file = file;
        }
    }
    free(copy);
    c->seen[at].open = false;
    const int result = c->seen[at].file;
    if (c->partial)
        c->seen[at].path[0] = '\0';   /* forgotten: found again by no name */
    c->partial = was_partial || c->partial;
    return result;
}

/* The file an #include of name (len bytes) reads, into path, as POV-Ray 3.7 looks for it
   (SceneData::FindFile): a name ending in ".inc" or ".INC" as it is, then with ".inc" and
   ".INC" appended, then any other name as it is; each relative one in the scene's folder,
   then in each library folder. */
static bool find_include(const copier *c, const char *name, size_t len, char *path,
                         size_t size)
{
    const bool standard = len > 4 && (!memcmp(name + len - 4, ".inc", 4) ||
                                      !memcmp(name + len - 4, ".INC", 4));
    const char *const suffixes[] = {standard ? "" : ".inc", standard ? ".inc" : ".INC",
                                    standard ? ".INC" : ""};
    for (int k = 0; k < 3; k++)
        for (int d = -1; d < 0 || (name[0] != '/' && c->library[d]); d++) {
            const char *dir = d < 0 ? c->folder : c->library[d];
            if (name[0] == '/' || (d < 0 && !strcmp(dir, ".")))
                snprintf(path, size, "%.*s%s", (int)len, name, suffixes[k]);
            else
                snprintf(path, size, "%s/%.*s%s", dir, (int)len, name, suffixes[k]);
            if (access(path, F_OK) == 0)
                return true;
        }
    return false;
}

static bool collect(const char *name, size_t len, int line, void *ctx)
{
    (void)line;
    swaps *s = ctx;
    copier *c = s->c;
    if (len == 0 || len >= NAME_MAX_BYTES)
        return true;
    if (s->depth >= MAX_DEPTH) {
        c->partial = true;
        return true;
    }
    char path[4096 + NAME_MAX_BYTES + 8];
    const bool found = find_include(c, name, len, path, sizeof path);
    c->out->unresolved = c->out->unresolved || !found;
    const int file = found ? copy_of(c, path, s->depth + 1) : 0;
    if (file > 0 && s->count == s->cap) {
        swap *grown = realloc(s->swap, (size_t)(s->cap = 2 * s->cap + 8) * sizeof *grown);
        if (!grown)
            return out_of_memory(c), false;
        s->swap = grown;
    }
    if (file > 0)
        s->swap[s->count++] = (swap){(size_t)(name - s->text), len, file};
    return c->status == L2P_OK;
}

/* text with each #include name that has a copy replaced by the copy's path. */
static char *swap_names(const swaps *s, size_t n, const scene_copy *o)
{
    size_t size = n + 1;
    for (int i = 0; i < s->count; i++)
        size += strlen(o->copy[s->swap[i].file]);
    char *out = malloc(size), *p = out;
    size_t from = 0;
    for (int i = 0; out && i < s->count; i++) {
        const swap *w = &s->swap[i];
        memcpy(p, s->text + from, w->at - from);
        p += w->at - from;
        p += sprintf(p, "%s", o->copy[w->file]);
        from = w->at + w->len;
    }
    if (out) {
        memcpy(p, s->text + from, n - from);
        p[n - from] = '\0';
    }
    return out;
}

/* The copy of text, the file at path: its includes' copies swapped in, its camera statements
   rewritten as file *file, for which a negative *file asks a new number. NULL when text needs
   no copy (no camera statement in it nor in what it includes, and a new number asked for) or
   on failure (c->status). */
static char *copy_text(copier *c, const char *path, const char *text, size_t n, int depth,
                       int *file)
{
    swaps s = {text, NULL, 0, 0, depth, c};
    scene_text_includes(text, n, collect, &s);
    int line;
    char *swapped = NULL, *copy = NULL;
    if (!c->status && (*file >= 0 || s.count > 0 || scene_text_has_camera(text, n, &line))) {
        if (*file < 0)
            *file = add_file(c, path);
        swapped = *file >= 0 ? swap_names(&s, n, c->out) : NULL;
        copy = swapped ? scene_camera_rewrite_file(swapped, strlen(swapped), *file) : NULL;
        if (!copy)
            out_of_memory(c);
    }
    free(swapped);
    free(s.swap);
    return copy;
}

int scene_copy_make(const char *scene, const char *text, size_t n, const char *work,
                    char *const *library, scene_copy *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    char folder[4096];
    snprintf(folder, sizeof folder, "%s", scene);
    char *slash = strrchr(folder, '/');
    if (slash)
        *slash = '\0';
    else
        snprintf(folder, sizeof folder, ".");
    copier c = {folder, work, library, NULL, 0, 0, 0, false, out, err, L2P_OK};
    int file = add_file(&c, scene);
    if (file == 0)
        out->text = copy_text(&c, scene, text, n, 0, &file);
    for (int i = 0; i < c.seen_count; i++)
        free(c.seen[i].path);
    free(c.seen);
    if (!c.status && !out->text)
        out_of_memory(&c);
    if (c.status)
        scene_copy_free(out);
    return c.status;
}

void scene_copy_free(scene_copy *c)
{
    for (int k = 0; k < c->count; k++) {
        if (c->copy[k])
            unlink(c->copy[k]);
        free(c->copy[k]);
        free(c->path[k]);
    }
    free(c->path);
    free(c->copy);
    free(c->text);
    memset(c, 0, sizeof *c);
}
