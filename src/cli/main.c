/* lens2pov: render POV-Ray scenes through real camera lenses. The command line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "base/cleanup.h"
#include "cli/cli.h"
#include "cli/lens_lookup.h"
#include "image/develop.h"
#include "cli/framing.h"
#include "cli/info.h"
#include "base/outfile.h"
#include "raytable/raytable.h"
#include "cli/render.h"
#include "cli/sizecheck.h"

#define LENS2POV_VERSION "0.4"

static const char usage[] =
    "usage:\n"
    "  lens2pov info LENS [--json] [camera options]\n"
    "  lens2pov trace LENS [camera options] -o PREFIX [--rays FILE.csv] [--memory-mb MB]\n"
    "  lens2pov develop PREFIX [RENDER.exr ...] -o IMAGE   (.png, .exr or .tif)\n"
    "  lens2pov render SCENE.pov LENS [camera options] -o IMAGE [--jobs N] [--keep-temp DIR]\n"
    "  lens2pov COMMAND --help      (its options and their defaults)\n"
    "  lens2pov --version\n"
    "See README.md and docs/ for the conventions.\n";

/* What lens2pov COMMAND --help prints: the command's own lines, then its options from the
   parser's table (cli_print_options). */
static const struct {
    const char *name, *text;
} command_help[] = {
    {"info", "usage: lens2pov info LENS [--json] [camera options]\n"
             "First-order properties of a lens; with camera options also of the camera.\n"},
    {"trace", "usage: lens2pov trace LENS [camera options] -o PREFIX\n"
              "Traces the film into PREFIX.inc (mesh_camera), PREFIX.ini and PREFIX.map.\n"},
    {"develop", "usage: lens2pov develop PREFIX [RENDER.exr ...] -o IMAGE\n"
                "Weights and averages POV-Ray's renders of PREFIX's ray table into IMAGE\n"
                "(.png, .exr or .tif) [RENDER.exr: the names PREFIX's .ini files give].\n"},
    {"render", "usage: lens2pov render SCENE.pov LENS [camera options] -o IMAGE\n"
               "trace, POV-Ray and develop in one, POV-Ray in parallel chunks.\n"},
};

/* lens2pov COMMAND ... --help (or -h anywhere after the command): true when printed. */
static bool print_command_help(int argc, char **argv)
{
    bool asked = false;
    for (int i = 2; i < argc; i++)
        asked |= !strcmp(argv[i], "--help") || !strcmp(argv[i], "-h");
    for (size_t k = 0; asked && k < sizeof command_help / sizeof command_help[0]; k++)
        if (!strcmp(argv[1], command_help[k].name)) {
            fputs(command_help[k].text, stdout);
            cli_print_options(stdout, command_help[k].name);
            return true;
        }
    return false;
}

static int fail(const l2p_error *err)
{
    fprintf(stderr, "lens2pov: %s\n", err->text);
    return err->status ? err->status : L2P_FAILED;
}

static int need(const cli *c, int positional, bool output, l2p_error *err)
{
    if (c->positional_count != positional)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "expected %d argument%s, got %d (see --help)",
                        positional, positional == 1 ? "" : "s", c->positional_count);
    if (output && !c->output)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "-o is required");
    return L2P_OK;
}

static int load_camera(const cli *c, const char *lens_path, camera *cam, l2p_error *err)
{
    lens l;
    int st = lens_read_named(lens_path, &l, err);
    if (st)
        return st;
    st = framing_camera_setup(cam, &l, c, err);
    if (st)
        camera_free(cam);
    return st;
}

static int cmd_info(const cli *c, l2p_error *err)
{
    int st = need(c, 1, false, err);
    lens l;
    if (st || (st = lens_read_named(c->positional[0], &l, err)))
        return st;
    lens_info li;
    camera cam;
    bool with_camera = c->film_given;
    if (!(st = lens_info_of(&l, &li, err)) && with_camera) {
        lens copy;
        /* info prints no weights: none to normalize, nothing to refuse for it. */
        cli physical = *c;
        physical.cam.weighting = WEIGHTING_PHYSICAL;
        st = lens_copy(&copy, &l) ? l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory")
                                  : framing_camera_setup(&cam, &copy, &physical, err);
        if (st)
            camera_free(&cam);
    }
    if (!st && with_camera)
        cli_warn(c, &cam);
    if (!st)
        info_print(stdout, &l, &li, with_camera ? &cam : NULL, c->json);
    if (with_camera && !st)
        camera_free(&cam);
    lens_free(&l);
    return st;
}

/* trace's outputs, checked before any work: PREFIX.inc, .ini and .map (a chunked table's
   files are checked again before the first is renamed into place). */
static int check_trace_outputs(const cli *c, l2p_error *err)
{
    char *path = malloc(strlen(c->output) + 5);
    if (!path)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    static const char *const ext[] = {"inc", "ini", "map"};
    int st = L2P_OK;
    for (int i = 0; i < 3 && !st; i++) {
        sprintf(path, "%s.%s", c->output, ext[i]);
        st = outfile_check_path(path, err);
    }
    free(path);
    if (!st)
        st = povmesh_check_prefix(c->output, err);
    if (!st && c->rays_csv)
        st = outfile_check_path(c->rays_csv, err);
    return st;
}

static int cmd_trace(const cli *given, l2p_error *err)
{
    camera cam;
    cli placed = *given;   /* with --scene's camera placement */
    const cli *c = &placed;
    int st = need(c, 1, true, err);
    if (st || (st = check_trace_outputs(c, err)) || (st = size_check_trace(c, err)) ||
        (c->scene && (st = framing_from_scene(&placed, c->scene, err))) ||
        (st = load_camera(c, c->positional[0], &cam, err)))
        return st;
    cli_warn(c, &cam);
    raytable_stats stats;
    /* One include unless --memory-mb asks for chunks that fit a POV-Ray process each. */
    const long long chunk_faces = c->memory_mb > 0 ? raytable_faces_for_memory(c->memory_mb) : 0;
    const raytable_request q = {c->output, c->rays_csv, chunk_faces, !c->quiet, NULL};
    st = raytable_write(&cam, &q, &stats, err);
    if (!st && !c->quiet)
        fprintf(stderr, "lens2pov: %lld of %lld rays pass the lens (%.1f%%), %.2f s\n",
                stats.passed, stats.samples,
                stats.samples ? 100.0 * (double)stats.passed / (double)stats.samples : 0.0,
                stats.seconds);
    camera_free(&cam);
    return st;
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
        names[k] = malloc(strlen(prefix) + 32);
        if (!names[k])
            break;
        if (given)
            strcpy(names[k], c->positional[k + 1]);
        else if (chunks == 1)
            sprintf(names[k], "%s.exr", prefix);
        else
            sprintf(names[k], "%s.c%03lld.exr", prefix, k);
    }
    return names;
}

static int cmd_develop(const cli *c, l2p_error *err)
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
    samplemap map;
    st = samplemap_read(map_path, &map, err);
    free(map_path);
    if (st)
        return st;
    const long long chunks = samplemap_chunk_count(&map.header);
    char **names = render_names(c, chunks, err);
    if (names)
        st = develop_files(&map, (const char *const *)names, (int)chunks, c->output, err);
    else
        st = err->status;
    for (long long k = 0; names && k < chunks; k++)
        free(names[k]);
    free(names);
    samplemap_free(&map);
    return st;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? L2P_BAD_INPUT : L2P_OK;
    }
    if (!strcmp(argv[1], "--version")) {
        puts("lens2pov " LENS2POV_VERSION);
        return L2P_OK;
    }
    if (print_command_help(argc, argv))
        return L2P_OK;
    cleanup_install();
    l2p_error err = {0, ""};
    cli c;
    int st = cli_parse(&c, argc, argv, 2, &err);
    if (st)
        return fail(&err);
    const char *cmd = argv[1];
    if (!strcmp(cmd, "info"))
        st = cmd_info(&c, &err);
    else if (!strcmp(cmd, "trace"))
        st = cmd_trace(&c, &err);
    else if (!strcmp(cmd, "develop"))
        st = cmd_develop(&c, &err);
    else if (!strcmp(cmd, "render"))
        st = render_command(&c, &err);
    else
        st = l2p_fail(&err, L2P_BAD_INPUT, NULL, 0, "unknown command '%s' (see --help)", cmd);
    return st ? fail(&err) : L2P_OK;
}
