#include "cli/traceset.h"

#include <ctype.h>
#include <dirent.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The first lines lens2pov gives its includes and inis (povmesh.c, fieldmesh.c, chunk_ini.c,
   field_render.c). */
static bool written_by_lens2pov(const char *path, bool include)
{
    char head[32] = {0};
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    const size_t n = fread(head, 1, sizeof head - 1, f);
    fclose(f);
    head[n] = '\0';
    return strncmp(head, include ? "// lens2pov ray " : "; lens2pov: ", include ? 16 : 12) == 0;
}

/* Whether rest (a name after "BASE.") is a file of the set: "inc" or "ini" (layout one), or a
   layout letter, three digits or more, then ".inc" or ".ini"; *kind, *index and *include tell
   which. */
static bool in_set(const char *rest, int *kind, long *index, bool *include)
{
    *kind = TRACE_LAYOUT_ONE, *index = 0;
    if (strcmp(rest, "inc") == 0 || strcmp(rest, "ini") == 0) {
        *include = rest[2] == 'c';
        return true;
    }
    if (rest[0] != TRACE_LAYOUT_CHUNKS && rest[0] != TRACE_LAYOUT_FIELD)
        return false;
    const char *p = rest + 1;
    while (isdigit((unsigned char)*p))
        p++;
    if (p - rest < 4 || (strcmp(p, ".inc") != 0 && strcmp(p, ".ini") != 0))
        return false;
    *kind = rest[0];
    *index = strtol(rest + 1, NULL, 10);
    *include = p[3] == 'c';
    return true;
}

int trace_set_remove_stale(const char *prefix, trace_layout layout, int count)
{
    const char *slash = strrchr(prefix, '/');
    const char *base = slash ? slash + 1 : prefix;
    char *dir = slash ? strndup(prefix, (size_t)(slash - prefix + 1)) : strdup("./");
    DIR *d = dir ? opendir(dir) : NULL;
    int removed = 0;
    const size_t base_len = strlen(base);
    for (struct dirent *e; d && (e = readdir(d));) {
        int kind;
        long index;
        bool include;
        if (strncmp(e->d_name, base, base_len) != 0 || e->d_name[base_len] != '.' ||
            !in_set(e->d_name + base_len + 1, &kind, &index, &include))
            continue;
        if (kind == (int)layout && (layout == TRACE_LAYOUT_ONE || index < count))
            continue;   /* written by this trace */
        char *path = malloc(strlen(dir) + strlen(e->d_name) + 1);
        if (path) {
            sprintf(path, "%s%s", dir, e->d_name);
            if (written_by_lens2pov(path, include) && unlink(path) == 0)
                removed++;
        }
        free(path);
    }
    if (d)
        closedir(d);
    free(dir);
    return removed;
}
