/* What one POV-Ray run of a chunk is given: the wrapper scene and the command line; and the
   small path helpers the runner shares with them. Internal to src/povray/. */
#ifndef LENS2POV_POVRAY_CMD_H
#define LENS2POV_POVRAY_CMD_H

#include <stdbool.h>
#include "base/error.h"
#include "povray/povray.h"

char *str_printf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* The child runs in the scene's folder, so every path it gets must be absolute. */
char *absolute_path(const char *path);
char *folder_of(const char *abs_path);

/* The wrapper at path: the film's size as image_width and image_height, the scene, the
   chunk's placement, then its camera include. */
int povray_write_wrapper(const char *path, const char *scene, const char *include, int index,
                         const povray_chunk *c, const povray_options *o, l2p_error *err);

/* The wrapper of a sequence of n chunks rendered as one animation (povray_render_sequences):
   frame f includes includes[f - 1]. */
int povray_write_sequence_wrapper(const char *path, const char *scene,
                                  const char *const *includes, int n, int index,
                                  const povray_options *o, l2p_error *err);

/* The files and folders of one run, as POV-Ray reads them; frames: the chunks of a sequence
   (0: one chunk, no animation of lens2pov's own). */
typedef struct povray_cmd {
    const char *exe, *ini, *wrapper, *output, *scene_dir;
    int frames;
} povray_cmd;

/* The command line (NULL-terminated, malloc'd; NULL out of memory). */
char **povray_argv(const povray_cmd *cmd, const povray_chunk *c, const povray_options *o);
void povray_free_argv(char **argv);

#endif
