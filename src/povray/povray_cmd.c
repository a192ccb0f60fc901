/* One POV-Ray run's wrapper scene and command line. */
#include "povray/povray_cmd.h"
#include "povray/povray.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

char *str_printf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    const int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (s) {
        va_start(ap, fmt);
        vsnprintf(s, (size_t)n + 1, fmt, ap);
        va_end(ap);
    }
    return s;
}

char *absolute_path(const char *path)
{
    if (path[0] == '/')
        return strdup(path);
    char cwd[4096];
    if (!getcwd(cwd, sizeof cwd))
        return NULL;
    return str_printf("%s/%s", cwd, path);
}

char *folder_of(const char *abs_path)
{
    char *d = strdup(abs_path);
    char *slash = d ? strrchr(d, '/') : NULL;
    if (slash)
        slash[slash == d ? 1 : 0] = '\0';
    return d;
}

bool povray_path_is_plain(const char *path)
{
    for (const unsigned char *p = (const unsigned char *)path; *p; p++)
        if (*p < 0x20 || *p > 0x7e || *p == '"' || *p == '\\')
            return false;
    return true;
}

bool povray_ini_can_carry(const char *path)
{
    for (const unsigned char *p = (const unsigned char *)path; *p; p++)
        if (*p < 0x20 || *p > 0x7e || *p == '"')
            return false;
    return true;
}

bool povray_ini_needs_quotes(const char *path)
{
    return strpbrk(path, ";#',") != NULL;
}

/* The wrapper: the scene first, then the camera, so that the lens camera replaces the
   scene's own. Nothing about #version or gamma here: the camera include raises the language
   version only when it is below 3.7 and restores it (an unversioned scene must stay one).
   image_width and image_height are built-in identifiers that a #declare shadows (POV-Ray
   3.7.0.10): declared before the scene, they give it the film's size instead of the packed
   table's. */
int povray_write_wrapper(const char *path, const char *scene, const char *include, int index,
                         const povray_chunk *c, const povray_options *o, l2p_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return l2p_fail(err, L2P_FAILED, path, 0, "cannot write: %s", strerror(errno));
    fprintf(f,
            "// lens2pov: the scene seen through chunk %d of the lens camera. The camera is\n"
            "// declared after the scene, so it replaces the scene's own camera.\n", index);
    if (o->film_width > 0)
        fprintf(f, "#declare image_width = %d;\n#declare image_height = %d;\n", o->film_width,
                o->film_height);
    fprintf(f, "#include \"%s\"\n", scene);
    if (c->placement)
        fprintf(f, "%s\n", c->placement);
    fprintf(f, "#include \"%s\"\n", include);
    const bool bad = ferror(f) != 0;
    if (fclose(f) != 0 || bad)
        return l2p_fail(err, L2P_FAILED, path, 0, "cannot write: %s", strerror(errno));
    return L2P_OK;
}

/* A sequence's wrapper: each frame is a still of the scene through its own chunk's camera.
   POV-Ray's animation only takes the frames through one process: the clock stays 0 (+KI0
   +KF0 on the command line), the frame's number is kept as Lens2pov_Frame, and the other
   animation identifiers are declared, before the scene, with the values of a still (in
   3.7.0.10 a #declare shadows them, as it does image_width; clock and clock_on it refuses). */
int povray_write_sequence_wrapper(const char *path, const char *scene,
                                  const char *const *includes, int n, int index,
                                  const povray_options *o, l2p_error *err)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return l2p_fail(err, L2P_FAILED, path, 0, "cannot write: %s", strerror(errno));
    fprintf(f,
            "// lens2pov: sequence %d, %d chunks of the lens camera as the frames of one POV-Ray\n"
            "// run, each a still of the scene through its chunk's camera, declared after the scene\n"
            "// so that it replaces the scene's own camera.\n"
            "#declare Lens2pov_Frame = frame_number;\n", index, n);
    static const char *const still[] = {"frame_number", "initial_frame", "final_frame",
                                        "initial_clock", "final_clock", "clock_delta"};
    for (size_t i = 0; i < sizeof still / sizeof still[0]; i++)
        fprintf(f, "#declare %s = 0;\n", still[i]);
    if (o->film_width > 0)
        fprintf(f, "#declare image_width = %d;\n#declare image_height = %d;\n", o->film_width,
                o->film_height);
    fprintf(f, "#include \"%s\"\n#switch (Lens2pov_Frame)\n", scene);
    for (int i = 0; i < n; i++)
        fprintf(f, "  #case (%d) #include \"%s\" #break\n", i + 1, includes[i]);
    fprintf(f, "#end\n#undef Lens2pov_Frame\n");
    const bool bad = ferror(f) != 0;
    if (fclose(f) != 0 || bad)
        return l2p_fail(err, L2P_FAILED, path, 0, "cannot write: %s", strerror(errno));
    return L2P_OK;
}

/* The command line. POV-Ray's own options from the user come first, so that everything after
   them overrides what they (or an .ini they name) set: the chunk's ini (its size), then no
   display, no pause, no continuing an old render, no alpha (it zeroes the background), no
   antialiasing (it mixes neighbouring rays), +GA for POV-Ray's messages (a user's -GA or
   All_Console=Off would hide its errors), +V for the progress lines, -GS -GR for no
   statistics, EXR, and Display_Gamma=sRGB, which sets how a scene without gamma handling
   is decoded into the linear EXR. An animation frame is rendered alone as a subset (+SF,
   +EF) of the user's animation, so that the scene sees POV-Ray's own clock, frame_number
   and the rest. A sequence of n chunks is frames 1 to n of an animation whose clock stays 0;
   POV-Ray renders a one-frame animation as a still, so one chunk is frame 1 of 2. Paths are
   quoted for spaces. */
char **povray_argv(const povray_cmd *cmd, const povray_chunk *c, const povray_options *o)
{
    enum { OWN = 28 };
    const int n_all = o->user_arg_count + OWN;
    char **argv = calloc((size_t)n_all, sizeof *argv);
    if (!argv)
        return NULL;
    int n = 0;
    argv[n++] = strdup(cmd->exe);
    for (int i = 0; i < o->user_arg_count; i++)
        argv[n++] = strdup(o->user_args[i]);
    argv[n++] = str_printf("\"%s\"", cmd->ini);
    argv[n++] = str_printf("+I\"%s\"", cmd->wrapper);
    argv[n++] = str_printf("+O\"%s\"", cmd->output);
    argv[n++] = str_printf("+L\"%s\"", cmd->scene_dir);
    const char *fixed[] = {"-D", "-P", "-C", "-UA", "-A", "+GA", "+V", "-GS", "-GR", "+FE",
                           "Display_Gamma=sRGB"};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
        argv[n++] = strdup(fixed[i]);
    if (o->threads_per_job > 0)
        argv[n++] = str_printf("+WT%d", o->threads_per_job);
    if (c->pov_output) {
        argv[n++] = str_printf("+SF%d", c->frame);
        argv[n++] = str_printf("+EF%d", c->frame);
    }
    if (cmd->frames > 0) {
        argv[n++] = strdup("+KFI1");
        argv[n++] = str_printf("+KFF%d", cmd->frames > 1 ? cmd->frames : 2);
        argv[n++] = strdup("+KI0");
        argv[n++] = strdup("+KF0");
        if (cmd->frames == 1) {
            argv[n++] = strdup("+SF1");
            argv[n++] = strdup("+EF1");
        }
    }
    for (int i = 0; i < n; i++)
        if (!argv[i]) {
            for (int k = 0; k < n; k++)
                free(argv[k]);
            free(argv);
            return NULL;
        }
    return argv;
}

void povray_free_argv(char **argv)
{
    for (int i = 0; argv && argv[i]; i++)
        free(argv[i]);
    free(argv);
}
