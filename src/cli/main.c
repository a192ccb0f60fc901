/* lens2pov: render POV-Ray scenes through real camera lenses. The command line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/cleanup.h"
#include "cli/cli.h"
#include "cli/commands.h"

#define LENS2POV_VERSION "0.4"

static const char usage[] =
    "usage:\n"
    "  lens2pov info LENS [--json] [camera options]\n"
    "  lens2pov trace LENS [camera options] -o PREFIX [--rays FILE.csv] [--memory-mb MB]\n"
    "  lens2pov develop PREFIX [RENDER.exr ...] -o IMAGE   (.png, .exr or .tif)\n"
    "  lens2pov render SCENE.pov LENS [camera options] -o IMAGE [--jobs N] [--keep-temp DIR]\n"
    "                  [-- POV-Ray options: +KFI1 +KFF10, Declare=N=V, +L, FILE.ini, ...]\n"
    "  lens2pov diagram LENS [camera options] -o FILE.svg\n"
    "  lens2pov plot LENS --what distortion|vignetting [camera options] -o FILE.png\n"
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
    {"render", "usage: lens2pov render SCENE.pov LENS [camera options] -o IMAGE [-- POV-Ray options]\n"
               "trace, POV-Ray and develop in one, POV-Ray in parallel chunks.\n"
               "  -- OPTIONS                    POV-Ray's own, for every run: animation (+KFI, +KFF,\n"
               "                                +KI, +KF, +KC, +K), Declare=, +L, +Q, FILE.ini;\n"
               "                                an animation gives IMAGE01.png, IMAGE02.png, ...\n"},
    {"diagram", "usage: lens2pov diagram LENS [camera options] -o FILE.svg\n"
                "The lens in its meridional section, to scale: elements, stop, film, rays from\n"
                "the film's centre and edge traced through every surface, principal planes,\n"
                "focal points and pupils (full simulation, at the focus and aperture given).\n"},
    {"plot", "usage: lens2pov plot LENS --what distortion|vignetting [camera options] -o FILE.png\n"
             "A gnuplot chart against film radius: distortion, the chief ray's image height\n"
             "against the paraxial one (percent); vignetting, the relative illumination\n"
             "E(r)/E(0) at the aperture given and at f/4, f/8 and f/16 where the lens\n"
             "stops down to them. The table goes to stdout.\n"},
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

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? L2P_BAD_INPUT : L2P_OK;
    }
    if (!strcmp(argv[1], "--version")) {
        if (argc > 2) {
            fprintf(stderr, "lens2pov: --version takes nothing after it, got '%s'\n", argv[2]);
            return L2P_BAD_INPUT;
        }
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
    if (c.povray_args && strcmp(cmd, "render") && !(!strcmp(cmd, "trace") && c.scene)) {
        l2p_fail(&err, L2P_BAD_INPUT, NULL, 0, "options after -- are POV-Ray's: only render, and "
                 "trace --scene for reading the scene's camera, take them");
        return fail(&err);
    }
    if (!strcmp(cmd, "info"))
        st = info_command(&c, &err);
    else if (!strcmp(cmd, "trace"))
        st = trace_command(&c, &err);
    else if (!strcmp(cmd, "develop"))
        st = develop_command(&c, &err);
    else if (!strcmp(cmd, "render"))
        st = render_command(&c, &err);
    else if (!strcmp(cmd, "diagram"))
        st = diagram_command(&c, &err);
    else if (!strcmp(cmd, "plot"))
        st = plot_command(&c, &err);
    else
        st = l2p_fail(&err, L2P_BAD_INPUT, NULL, 0, "unknown command '%s' (see --help)", cmd);
    return st ? fail(&err) : L2P_OK;
}
