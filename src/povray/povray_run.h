/* The shared state of a POV-Ray run (povray.c's scheduler) and what sets it up
   (povray_run.c): the executable, the scene's paths, and each task's wrapper, ini and output.
   Internal to src/povray. */
#ifndef LENS2POV_POVRAY_RUN_H
#define LENS2POV_POVRAY_RUN_H

#include <stdbool.h>
#include <sys/types.h>
#include "base/progress.h"
#include "povray/povray.h"
#include "povray/povray_log.h"

typedef struct job {
    pid_t pid;                 /* 0: slot free */
    int task;                  /* a chunk, or a sequence of them */
    int frame;                 /* of a sequence: the frame POV-Ray is at (1-based; 0 before) */
    char *log_path;
    double parse_fraction, render_fraction;
    int retries;               /* times this chunk was started again (retried) */
} job;

typedef struct run {
    const povray_chunk *chunks;
    int count;
    /* What one process renders: a chunk (frames NULL, tasks == count), or sequence t, the
       frames[t] chunks from first[t] on, as the frames of one animation. */
    const int *frames;
    int *first;
    int tasks;
    const povray_options *opts;
    char *exe;
    char **env;                /* POV-Ray's environment (povray_env.h) */
    char *work_dir;
    char *chunk_prefix;        /* WORK/povray: the wrappers and logs are its chunk files */
    char *scene_real_dir;      /* the child's working folder */
    char *scene_for_povray, *scene_dir_for_povray;
    povray_path_link *links;
    int link_count;
    job *jobs;
    int job_slots;
    bool writing;              /* chunks still being written: their writer draws its own bar */
    bool *reported;            /* a chunk's picture is at its output_exr and was reported */
    int notify_fd;             /* inotify on work_dir for closed pictures; -1: none */
    progress bar;
} run;

static inline int task_first(const run *r, int t)
{
    return r->frames ? r->first[t] : t;
}

static inline int task_chunks(const run *r, int t)
{
    return r->frames ? r->frames[t] : 1;
}

/* The chunk a job is at: a sequence's current frame (its first before POV-Ray names one). */
static inline int job_chunk(const run *r, const job *j)
{
    const int k = j->frame > 1 ? j->frame - 1 : 0;
    return task_first(r, j->task) + (k < task_chunks(r, j->task) ? k : task_chunks(r, j->task) - 1);
}

/* A task's files: its wrapper scene, its ini and what +O names. */
typedef struct task_args {
    char *wrapper, *ini, *output;
} task_args;

/* Sets r up for count chunks, as tasks of one chunk (frames NULL) or as sequences of
   frames[t] chunks: the work folder, the scene (L2P_BAD_INPUT when unreadable) and the
   executable. r is always set; free it with povray_run_free. */
int povray_run_prepare(run *r, const povray_chunk *chunks, int count, const int *frames,
                       int tasks, const povray_options *opts, l2p_error *err);
void povray_run_free(run *r);

/* Task t's wrapper, ini and output, stale outputs removed; paths POV-Ray cannot read are
   linked from the work folder. */
int povray_task_prepare(run *r, int t, task_args *a, l2p_error *err);
void povray_task_args_free(task_args *a);

/* WORK/povray.cNNN.EXT, chunk NNN's wrapper and log; WORK/povray.sNNN.EXT, sequence NNN's. */
char *povray_task_file_name(const run *r, int t, const char *ext);

/* Where POV-Ray writes frame f of sequence t. */
char *povray_frame_output(const run *r, int t, int f);

int povray_out_of_memory(l2p_error *err);

/* Finished pictures (povray_pictures.c). Chunk k's picture is complete at written (its
   output_exr, or the frame POV-Ray wrote): moved to output_exr and reported to
   opts->picture_done, once. */
int povray_picture_finished(run *r, int k, const char *written, l2p_error *err);

/* Starts watching the work folder for closed pictures, unless the user gave POV-Ray options
   that might make it do more after them (nothing when inotify is not there: pictures are
   then found as their process ends). */
void povray_watch_pictures(run *r);

/* Finishes the pictures of running jobs that POV-Ray has closed since the last call. */
int povray_collect_pictures(run *r, l2p_error *err);

/* Waits ms milliseconds, less when a watched picture is closed. */
void povray_wait_ms(const run *r, int ms);

#endif
