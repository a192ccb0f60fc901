/* render's frames: one, or an animation's (POV-Ray's options after "--"), each with its
   picture, its camera placement and the ray table it is seen through. Frames that differ only
   in where the camera stands share one table, traced once in camera axes and moved by each
   frame's transform (Lens2pov_Placement); a frame whose focus, mirroring or --angle scene
   differs gets a table of its own. */
#ifndef LENS2POV_FRAMES_H
#define LENS2POV_FRAMES_H

#include <stdbool.h>
#include "cli/cli.h"
#include "base/error.h"

typedef struct render_frame {
    int number;            /* POV-Ray's frame number; -1: not an animation */
    char *output;          /* the developed picture */
    char *placement;       /* the wrapper's #declare of Lens2pov_Placement; NULL: none */
    int table;             /* the ray table it is seen through */
    cli table_cli;         /* the options that table is traced with */
} render_frame;

typedef struct render_frames {
    render_frame *frame;
    int count, tables;
    bool animated;
    int digits;            /* POV-Ray pads frame numbers to this many */
} render_frames;

/* The frames of c's render: POV-Ray evaluates the scene's camera for each one (with the
   options after "--"); without an animation, one frame placed as today (the table in world
   axes). L2P_BAD_INPUT for a frame whose placement cannot be used. */
int render_frames_plan(const cli *c, render_frames *out, l2p_error *err);
void render_frames_free(render_frames *f);

#endif
