/* lens2pov: render POV-Ray scenes through real camera lenses. The command line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "cli/cli.h"
#include "image/develop.h"
#include "cli/framing.h"
#include "cli/info.h"
#include "base/outfile.h"
#include "raytable/raytable.h"
#include "cli/render.h"

#define LENS2POV_VERSION "0.4"

static const char usage[] =
    "usage:\n"
    "  lens2pov info LENS [--json] [camera options]\n"
    "  lens2pov trace LENS [camera options] -o PREFIX [--rays FILE.csv] [--memory-mb MB]\n"
    "  lens2pov develop PREFIX [RENDER.exr ...] -o IMAGE   (.png, .exr or .tif)\n"
    "  lens2pov render SCENE.pov LENS [camera options] -o IMAGE [--jobs N] [--keep-temp DIR]\n"
    "                  [-- POV-Ray options: +KFI1 +KFF10, Declare=N=V, +L, FILE.ini, ...]\n"
    "  lens2pov COMMAND --help      (its options and their defaults)\n"
    "  lens2pov --version\n"
    "See README.md and docs/ for the conventions.\n";

static const char camera_help[] =
    "camera options (defaults in brackets):\n"
    "  --width N --height N          film pixels [640 x 480]\n"
    "  --spp N                       samples per pixel [16]\n"
    "  --film-diagonal MM            [35]\n"
    "  --angle DEG|scene             film width for this horizontal field of view, traced\n"
    "                                (scene: the scene camera's angle) [--film-diagonal]\n"
    "  --crop X0,Y0,X1,Y1            a region of the film (X1, Y1 exclusive) [the whole film]\n"
    "  --film-distance MM | --focus-distance UNITS|inf\n"
    "                                [focus on the look-at point]\n"
    "  --aperture-diameter MM | --f-number N   [the stop's full opening]\n"
    "  --pupil stop-image|rear|stop  [stop-image; stop is a biased diagnostic]\n"
    "  --trace full|thick            [full]\n"
    "  --weighting normalized|physical   [normalized]\n"
    "  --location X,Y,Z [0,0,0]  --look-at X,Y,Z [0,0,1]  --sky X,Y,Z [0,1,0]\n"
    "                                [render, trace --scene: the scene's camera]\n"
    "  --unit-mm MM                  millimetres in a scene unit [1000]\n"
    "  --seed N                      the sample pattern's seed [0]\n";

/* What lens2pov COMMAND --help prints: the command's own lines, then the camera options where
   it takes them. */
static const struct {
    const char *name, *text;
    bool camera;
} command_help[] = {
    {"info", "usage: lens2pov info LENS [--json] [camera options]\n"
             "First-order properties of a lens; with camera options also of the camera.\n"
             "  --json                        JSON instead of text [text]\n", true},
    {"trace", "usage: lens2pov trace LENS [camera options] -o PREFIX\n"
              "Traces the film into PREFIX.inc (mesh_camera), PREFIX.ini and PREFIX.map.\n"
              "  -o, --output PREFIX           (required)\n"
              "  --rays FILE.csv               every ray sent to POV-Ray [none]\n"
              "  --scene SCENE.pov             place the lens as this scene's camera [none]\n"
              "  --memory-mb MB                split into chunks that fit a POV-Ray process of\n"
              "                                this size [one include]\n"
              "  -q, --quiet                   no progress or summary on stderr\n", true},
    {"develop", "usage: lens2pov develop PREFIX [RENDER.exr ...] -o IMAGE\n"
                "Weights and averages POV-Ray's renders of PREFIX's ray table into IMAGE\n"
                "(.png, .exr or .tif) [RENDER.exr: the names PREFIX's .ini files give].\n"
                "  -o, --output IMAGE            (required)\n", false},
    {"render", "usage: lens2pov render SCENE.pov LENS [camera options] -o IMAGE [-- POV-Ray options]\n"
               "trace, POV-Ray and develop in one, POV-Ray in parallel chunks.\n"
               "  -o, --output IMAGE            .png, .exr or .tif (required)\n"
               "  --jobs N                      POV-Ray processes at once [the cores]\n"
               "  --memory-mb MB                POV-Ray memory a process [1024]\n"
               "  --rays FILE.csv               every ray sent to POV-Ray [none]\n"
               "  --keep-temp DIR               keep the ray tables, renders and logs [removed]\n"
               "  -q, --quiet                   no progress on stderr\n"
               "  -- OPTIONS                    POV-Ray's own, for every run: animation (+KFI, +KFF,\n"
               "                                +KI, +KF, +KC, +K), Declare=, +L, +Q, FILE.ini;\n"
               "                                an animation gives IMAGE01.png, IMAGE02.png, ...\n", true},
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
            if (command_help[k].camera)
                fputs(camera_help, stdout);
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
    int st = lens_read(lens_path, &l, err);
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
    if (st || (st = lens_read(c->positional[0], &l, err)))
        return st;
    lens_info li;
    camera cam;
    bool with_camera = c->film_given;
    if (!(st = lens_info_of(&l, &li, err)) && with_camera) {
        lens copy;
        st = lens_copy(&copy, &l) ? l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory")
                                  : framing_camera_setup(&cam, &copy, c, err);
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

/* trace's outputs, checked before any work: PREFIX.inc stands for the set beside it. */
static int check_trace_outputs(const cli *c, l2p_error *err)
{
    char *inc = malloc(strlen(c->output) + 5);
    if (!inc)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    sprintf(inc, "%s.inc", c->output);
    int st = outfile_check_path(inc, err);
    free(inc);
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
    if (st || (st = check_trace_outputs(c, err)) ||
        (c->scene && (st = framing_from_scene(&placed, c->scene, err))) ||
        (st = load_camera(c, c->positional[0], &cam, err)))
        return st;
    cli_warn(c, &cam);
    raytable_stats stats;
    /* One include unless --memory-mb asks for chunks that fit a POV-Ray process each. */
    const long long chunk_faces = c->memory_mb > 0 ? raytable_faces_for_memory(c->memory_mb) : 0;
    const raytable_request q = {c->output, c->rays_csv, chunk_faces, !c->quiet, NULL, NULL};
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
    outfile_install_signal_cleanup();
    l2p_error err = {0, ""};
    cli c;
    int st = cli_parse(&c, argc, argv, 2, &err);
    if (st)
        return fail(&err);
    const char *cmd = argv[1];
    if (c.povray_args && strcmp(cmd, "render")) {
        l2p_fail(&err, L2P_BAD_INPUT, NULL, 0, "options after -- are POV-Ray's: only render takes them");
        return fail(&err);
    }
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
