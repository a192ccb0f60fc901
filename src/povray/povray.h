/* Running POV-Ray on the chunks of a ray table: the wrapper scene, the flags, parallel
   processes, progress and POV-Ray's own error lines. */
#ifndef LENS2POV_POVRAY_H
#define LENS2POV_POVRAY_H

#include <stdbool.h>
#include "base/error.h"

/* POV-Ray 3.7 reads paths (options and SDL strings alike) as ASCII: other bytes become
   spaces, and a '"' cannot be quoted. Backslashes are escapes in SDL strings. True when path
   can be given to POV-Ray as it is. */
bool povray_path_is_plain(const char *path);

/* An .ini value (Output_File_Name=PATH) loses the rest of the line at ';' and '#' and cannot
   hold '\'' or ',' unquoted; quoted it holds them, but never a '"', and other bytes than
   printable ASCII are turned into spaces or end the value. True when an .ini can name path,
   quoted where povray_ini_needs_quotes says so. */
bool povray_ini_can_carry(const char *path);
bool povray_ini_needs_quotes(const char *path);

typedef struct povray_chunk {
    const char *include_path;  /* the chunk's camera include (PREFIX.cNNN.inc) */
    const char *ini_path;      /* its settings (Width, Height, -A, +FE, ...) */
    const char *output_exr;    /* where POV-Ray writes the chunk's render */
    long long faces;           /* for progress and memory estimates */
    /* The wrapper's text between the scene and the include (an animation frame's placement),
       NULL: none. An animation frame also has pov_output, what +O names, to which POV-Ray
       adds the frame number, writing output_exr; and the frame rendered (+SF, +EF). NULL:
       not an animation, +O is output_exr. */
    const char *placement;
    int frame;
    const char *pov_output;
} povray_chunk;

typedef struct povray_options {
    const char *scene_path;    /* the user's scene, never modified */
    const char *work_dir;      /* folder for the wrapper files and POV-Ray's logs */
    int jobs;                  /* POV-Ray processes at once */
    int threads_per_job;       /* +WTn for each process; 0: POV-Ray's default */
    int show_progress;         /* draw a progress bar on stderr */
    const char *povray;        /* the executable; NULL: "povray" (or $LENS2POV_POVRAY) */
    /* Chunks still being written (NULL: all are ready): how many are ready now, in order, and
       in *total the final count once the writer is done (-1 before; at most the count given to
       povray_render_chunks). Nonzero: the writer failed, with err set. */
    int (*chunks_ready)(void *ctx, int *ready, int *total, l2p_error *err);
    void *ctx;
    char *const *user_args;    /* POV-Ray's own options from the command line, before ours */
    int user_arg_count;
    int film_width, film_height;   /* image_width, image_height in the scene; 0: not declared */
    /* Called once on the calling thread, with started_ctx, as soon as the first POV-Ray
       processes run (work that can overlap their start-up); NULL: none. */
    void (*started)(void *ctx);
    void *started_ctx;
    /* Called on the calling thread, with picture_ctx, once chunk k's picture is complete at
       its output_exr: as soon as POV-Ray has closed it (a sequence's process may still fail
       in a later frame), or, without inotify, when its process has ended well. Nonzero stops
       the run, with err set. NULL: none. */
    int (*picture_done)(void *ctx, int k, l2p_error *err);
    void *picture_ctx;
    bool work_dir_kept;        /* work_dir outlives the run (--keep-temp): a message may name a
                                  log there; else it quotes the log's last line */
    /* The run's files in work_dir: NAME.sNNN.pov, NAME.sNNN.log, ...; NULL: "povray". Runs
       into one folder take names of their own, so that a kept folder holds every log. */
    const char *file_name;
} povray_options;

/* Writes, for every chunk, a wrapper that includes the scene and then the chunk's camera, and
   renders them, opts->jobs at a time, each as soon as it is ready (opts->chunks_ready). A
   process whose pictures have all been closed is killed rather than waited for (it only
   winds down), unless opts has user_args. On a POV-Ray failure stops the other processes,
   returns L2P_FAILED and puts POV-Ray's own error lines (file, line, message) in err. */
int povray_render_chunks(const povray_chunk *chunks, int count, const povray_options *opts,
                         l2p_error *err);

/* The same with one POV-Ray process a sequence: sequence s, the frames[s] (at least 1) chunks
   after those of the sequences before it, is rendered as the frames of one POV-Ray animation,
   each frame's wrapper including its own chunk's camera (chosen by frame_number), so that the
   process's start-up and exit are paid once. The first chunk's ini gives every frame's size:
   POV-Ray renders all frames of a run at one Width and Height. Each frame's picture is moved
   to its chunk's output_exr as soon as POV-Ray has closed it (without inotify, when its
   process has ended). The scene sees clock 0 and
   frame_number, initial_frame, final_frame, initial_clock, final_clock and clock_delta as in
   a still, but clock_on true (POV-Ray lets no scene redeclare it). Chunks take no placement
   or pov_output, opts no user_args (POV-Ray's animation is lens2pov's here) and no
   chunks_ready. opts->jobs sequences at a time; failures as povray_render_chunks, POV-Ray's
   error lines those of the frame that failed. */
int povray_render_sequences(const povray_chunk *chunks, const int *frames, int sequences,
                            const povray_options *opts, l2p_error *err);

#endif
