/* `lens2pov develop`: POV-Ray's renders of a ray table into the picture. */
#include "cli/commands.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include "base/outfile.h"
#include "field/field_develop.h"
#include "image/develop.h"
#include "image/samplemap.h"
#include "raytable/chunk_name.h"
#include "raytable/povmesh.h"

static bool exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* NAME.exr without its ".exr", with SUFFIX and ".exr" after it (malloc'd). */
static char *with_suffix(const char *name, const char *suffix)
{
    const size_t stem = strlen(name) - 4;
    char *s = malloc(stem + strlen(suffix) + 5);
    if (s)
        sprintf(s, "%.*s%s.exr", (int)stem, name, suffix);
    return s;
}

/* Whether every render has a picture NAME<suffix>.exr. */
static bool every_render_has(char *const *names, int count, const char *suffix)
{
    bool all = true;
    for (int r = 0; all && r < count; r++) {
        char *s = with_suffix(names[r], suffix);
        all = s && exists(s);
        free(s);
    }
    return all;
}

enum { MOST_FRAMES = 64 };

/* The frame numbers F (as POV-Ray wrote them, padded) for which every render has NAMEF.exr:
   the names in `frames` (malloc'd each); returns how many, at most MOST_FRAMES. */
static int frames_present(char *const *names, int count, char *frames[MOST_FRAMES])
{
    const char *slash = strrchr(names[0], '/');
    char *dir = slash ? strndup(names[0], (size_t)(slash - names[0] + 1)) : strdup(".");
    const char *base = slash ? slash + 1 : names[0];
    const size_t stem = strlen(base) - 4;
    DIR *d = dir ? opendir(dir) : NULL;
    int n = 0;
    for (struct dirent *e; d && n < MOST_FRAMES && (e = readdir(d));) {
        const char *rest = e->d_name + stem;
        const size_t digits = strncmp(e->d_name, base, stem) ? 0 : strspn(rest, "0123456789");
        if (!digits || strcmp(rest + digits, ".exr"))
            continue;
        char *frame = strndup(rest, digits);
        if (frame && every_render_has(names, count, frame))
            frames[n++] = frame;
        else
            free(frame);
    }
    if (d)
        closedir(d);
    free(dir);
    for (int i = 1; i < n; i++)   /* by number: an insertion sort of a few */
        for (int k = i; k > 0 && atoll(frames[k]) < atoll(frames[k - 1]); k--) {
            char *t = frames[k];
            frames[k] = frames[k - 1], frames[k - 1] = t;
        }
    return n;
}

/* POV-Ray numbers an animation's pictures by frame (povargs_frame_name): render NAME.exr of
   frame F is NAMEF.exr. When the first render's own name is not there, the frames whose
   pictures every render has: one (a frame with a table of its own) is developed; several are
   refused, with the command that develops one of them. */
static int frame_renders(const char *prefix, char **names, int count, l2p_error *err)
{
    if (count == 0 || exists(names[0]) || strlen(names[0]) < 4 ||
        strcmp(names[0] + strlen(names[0]) - 4, ".exr"))
        return L2P_OK;
    char *frames[MOST_FRAMES];
    const int n = frames_present(names, count, frames);
    int st = L2P_OK;
    if (n == 1) {
        for (int r = 0; !st && r < count; r++) {
            char *s = with_suffix(names[r], frames[0]);
            if (!s)
                st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
            else
                free(names[r]), names[r] = s;
        }
    } else if (n > 1) {
        char list[256] = "", example[1024] = "";
        for (int i = 0; i < n && strlen(list) < 200; i++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%lld", i ? ", " : "",
                     atoll(frames[i]));
        for (int r = 0; r < count && r < 3; r++) {
            char *s = with_suffix(names[r], frames[0]);
            snprintf(example + strlen(example), sizeof example - strlen(example), " %s",
                     s ? s : "");
            free(s);
        }
        st = l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s: the renders are an animation's, POV-Ray "
                      "numbering them by frame (frames %s): give one frame's %d render%s, as in "
                      "lens2pov develop %s%s%s -o IMAGE", prefix, list, count, count == 1 ? "" : "s",
                      prefix, example, count > 3 ? " ..." : "");
    }
    for (int i = 0; i < n; i++)
        free(frames[i]);
    return st;
}

static bool newer(const struct stat *a, const struct stat *b)
{
    return a->st_mtim.tv_sec != b->st_mtim.tv_sec ? a->st_mtim.tv_sec > b->st_mtim.tv_sec
                                                  : a->st_mtim.tv_nsec > b->st_mtim.tv_nsec;
}

/* Which of PREFIX.EXT (0) and PREFIX.c000.EXT (1) is there, the newer when both are (an
   earlier trace of the same prefix left the other); -1 when neither is. */
static int chunked_file(const char *prefix, const char *ext)
{
    char *one = povmesh_chunk_file(prefix, false, 0, ext), *chunk = chunk_file_name(prefix, 0, ext);
    struct stat o, c;
    const bool has_one = one && stat(one, &o) == 0, has_chunk = chunk && stat(chunk, &c) == 0;
    free(one), free(chunk);
    if (has_one && has_chunk)
        return newer(&c, &o);
    return has_chunk ? 1 : has_one ? 0 : -1;
}

/* The render of a table of one chunk: PREFIX.exr, or PREFIX.c000.exr when the trace was asked
   for chunks (--memory-mb) and one was enough. The .ini the trace wrote beside the map says
   which; without one, the render that is there. */
static char *single_render_name(const char *prefix)
{
    int chunked = chunked_file(prefix, "ini");
    if (chunked < 0)
        chunked = chunked_file(prefix, "exr");
    return povmesh_chunk_file(prefix, chunked == 1, 0, "exr");
}

/* Whether NAME is, by the names the .ini files give POV-Ray, render K of kind KIND ('c' for a
   chunk, 'f' for a field render): ".c" and K in three digits or more, then the frame number POV-Ray
   adds in an animation, if any, then ".exr". */
static bool named_as_render(const char *name, char kind, int k)
{
    char tag[24];
    snprintf(tag, sizeof tag, ".%c%03d", kind, k);
    for (const char *p = strstr(name, tag); p; p = strstr(p + 1, tag)) {
        const char *rest = p + strlen(tag);
        if (!strcmp(rest + strspn(rest, "0123456789"), ".exr"))
            return true;
    }
    return false;
}

/* Given renders are taken in order, and nothing in a render tells its chunk: a name that is
   another place's and not its own is refused rather than developed into a wrong picture. */
static int check_given_order(char *const *names, int count, char kind, l2p_error *err)
{
    for (int r = 0; r < count; r++)
        for (int k = 0; k < count && !named_as_render(names[r], kind, r); k++)
            if (k != r && named_as_render(names[r], kind, k))
                return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s is given as render %d but named "
                                "as render %d: give the renders in the order of their numbers",
                                names[r], r, k);
    return L2P_OK;
}

/* The renders of the chunks: as given, or by the names the chunks' .ini files give POV-Ray
   (PREFIX.exr, or PREFIX.c000.exr, PREFIX.c001.exr, ...). */
static char **render_names(const cli *c, long long chunks, l2p_error *err)
{
    const char *prefix = c->positional[0];
    const long long given = c->positional_count - 1;
    if (given && given != chunks) {
        l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s.map has %lld chunk%s but %lld render%s given",
                 prefix, chunks, chunks == 1 ? "" : "s", given, given == 1 ? " was" : "s were");
        return NULL;
    }
    char **names = calloc((size_t)chunks, sizeof *names);
    for (long long k = 0; names && k < chunks; k++) {
        names[k] = given        ? strdup(c->positional[k + 1])
                   : chunks == 1 ? single_render_name(prefix)
                                 : chunk_file_name(prefix, (int)k, "exr");
        if (!names[k]) {
            l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
            for (long long i = 0; i < k; i++)
                free(names[i]);
            free(names);
            return NULL;
        }
    }
    if (names && (given ? check_given_order(names, (int)chunks, 'c', err)
                        : frame_renders(prefix, names, (int)chunks, err))) {
        for (long long k = 0; k < chunks; k++)
            free(names[k]);
        free(names);
        return NULL;
    }
    if (!names)
        l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    return names;
}

/* A render older than its map was made from an earlier trace of the same prefix, whose map the
   new one replaced: developing mixes the two. Said, not refused: a copy (cp without -p) can
   reorder the times of files that belong together. */
static void warn_older(const char *map_path, char *const *renders, long long count)
{
    struct stat map, r;
    if (stat(map_path, &map) != 0)
        return;
    for (long long k = 0; k < count; k++)
        if (renders[k] && stat(renders[k], &r) == 0 && newer(&map, &r))
            fprintf(stderr, "lens2pov: warning: %s is older than %s: was it rendered from an earlier "
                    "trace? (render the trace's .ini again)\n", renders[k], map_path);
}

/* POV-Ray's other formats (+FN, +FT, +FJ, ...) clip values above 1, the highlights a lens
   spreads into bokeh, and quantize the rest: said, not refused (a user may know the scene
   has neither). The trace's .ini asks for EXR. */
static void warn_not_exr(char *const *renders, long long count)
{
    for (long long k = 0; k < count; k++) {
        const size_t n = renders[k] ? strlen(renders[k]) : 0;
        if (n && (n < 4 || strcasecmp(renders[k] + n - 4, ".exr") != 0))
            fprintf(stderr, "lens2pov: warning: %s is not an OpenEXR render: POV-Ray's other "
                    "formats clip values above 1 and round the rest (the trace's .ini asks for "
                    "EXR)\n", renders[k]);
    }
}

/* The picture must not replace the map or a render it is developed from; a render older than
   the map, or not an EXR, is warned of. */
static int check_inputs(const cli *c, const char *map_path, char *const *renders, long long count,
                        l2p_error *err)
{
    int st = outfile_check_not_input(c->output, map_path, "the sample map", err);
    for (long long k = 0; !st && k < count; k++)
        st = outfile_check_not_input(c->output, renders[k], "a render to develop", err);
    if (!st) {
        warn_older(map_path, renders, count);
        warn_not_exr(renders, count);
    }
    return st;
}

/* A field map's renders: as given, or PREFIX.f000.exr, PREFIX.f001.exr, ... (the names its
   .ini files give POV-Ray). */
static int develop_field(const cli *c, const char *map_path, l2p_error *err)
{
    field_map m;
    int st = field_map_read(map_path, &m, err);
    if (st)
        return st;
    const char *prefix = c->positional[0];
    const int given = c->positional_count - 1;
    char **names = calloc((size_t)m.renders, sizeof *names);
    for (int r = 0; names && r < m.renders; r++) {
        if (given) {
            names[r] = r < given ? strdup(c->positional[r + 1]) : strdup("");
        } else if ((names[r] = malloc(strlen(prefix) + 16))) {
            sprintf(names[r], "%s.f%03d.exr", prefix, r);
        }
        if (!names[r])
            break;
    }
    if (!names || (m.renders && !names[m.renders - 1]))
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    else
        st = given ? check_given_order(names, given, 'f', err)
                   : frame_renders(prefix, names, m.renders, err);
    if (!st && !(st = check_inputs(c, map_path, names, m.renders, err)))
        st = field_develop(&m, (const char *const *)names, given ? given : m.renders, c->output,
                           err);
    for (int r = 0; names && r < m.renders; r++)
        free(names[r]);
    free(names);
    field_map_free(&m);
    return st;
}

int develop_command(const cli *c, l2p_error *err)
{
    if (c->positional_count < 1 || !c->output)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "develop takes PREFIX [RENDER.exr ...] -o IMAGE");
    int st = outfile_check_path(c->output, err);
    if (st)
        return st;
    char *map_path = malloc(strlen(c->positional[0]) + 8);
    if (!map_path)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    sprintf(map_path, "%s.map", c->positional[0]);
    if (field_map_is_one(map_path)) {
        st = develop_field(c, map_path, err);
        free(map_path);
        return st;
    }
    samplemap map;
    st = samplemap_read(map_path, &map, err);
    if (st) {
        free(map_path);
        return st;
    }
    const long long chunks = samplemap_chunk_count(&map.header);
    char **names = render_names(c, chunks, err);
    if (!names)
        st = err->status;
    else if (!(st = check_inputs(c, map_path, names, chunks, err)))
        st = develop_files(&map, (const char *const *)names, (int)chunks, c->output, err);
    free(map_path);
    for (long long k = 0; names && k < chunks; k++)
        free(names[k]);
    free(names);
    samplemap_free(&map);
    return st;
}
