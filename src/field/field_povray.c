/* The POV-Ray part of render --sampling field: a field's renders through POV-Ray, then each
   picture developed from the field map. A still without POV-Ray options runs each job's
   renders as the frames of one POV-Ray animation; with POV-Ray's options (the user's
   animation, Declare=, ...) every render of every frame is a POV-Ray run of its own, as pixel
   sampling runs its chunks. */
#include "field/field_render.h"

#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "field/field_develop.h"
#include "field/field_files.h"
#include "field/fieldpass.h"
#include "image/image_io.h"
#include "povray/povargs.h"
#include "povray/povray.h"
#include "povray/povray_env.h"

/* A POV-Ray process renders its job's renders as the frames of one animation
   (povray_render_sequences), paying POV-Ray's start-up and exit once a job, not once a
   render; pack gives them all one size, as a POV-Ray run needs. Renders go, those of the
   most sub-images first, to the job with the fewest sub-images so far. order gets the renders
   job by job (in render order within a job), frames each job's count; returns the number of
   jobs. */
static int assign_jobs(const field_render_plan *plans, int renders, int jobs, int *order, int *frames)
{
    const int n = jobs < renders ? jobs : renders;
    int *job_of = malloc(sizeof *job_of * (size_t)renders);
    long long *load = calloc((size_t)n, sizeof *load);
    if (!job_of || !load) {
        free(job_of), free(load);
        return -1;
    }
    for (int r = 0; r < renders; r++)
        job_of[r] = -1;
    for (int done = 0; done < renders; done++) {
        int r = -1, j = 0;
        for (int i = 0; i < renders; i++)
            if (job_of[i] < 0 && (r < 0 || plans[i].count > plans[r].count))
                r = i;
        for (int i = 1; i < n; i++)
            if (load[i] < load[j])
                j = i;
        job_of[r] = j;
        load[j] += plans[r].count;
    }
    int k = 0;
    for (int j = 0; j < n; j++) {
        frames[j] = 0;
        for (int r = 0; r < renders; r++)
            if (job_of[r] == j)
                order[k++] = r, frames[j]++;
    }
    free(job_of), free(load);
    return n;
}

/* Develops each render as soon as POV-Ray has closed its picture (povray_options'
   picture_done), so that developing overlaps the frames still rendering and POV-Ray's exit. */
typedef struct developing {
    field_developer *dev;
    const field_files *f;
    const int *order;   /* the run's chunk k is render order[k]; NULL: render k */
} developing;

static int picture_done(void *ctx, int k, l2p_error *err)
{
    developing *d = ctx;
    const int r = d->order ? d->order[k] : k;
    const int st = image_io_ready(err);
    return st ? st : field_develop_add(d->dev, r, d->f->chunk[r].output_exr, err);
}

int field_render_into(const field_files *f, int jobs, const povray_options *po,
                      field_developer *dev, l2p_error *err)
{
    developing d = {.dev = dev, .f = f};
    dev->remove_pictures = !po->work_dir_kept;
    povray_options with_pictures = *po;
    with_pictures.picture_done = picture_done;
    with_pictures.picture_ctx = &d;
    /* With POV-Ray's options (a still's: Declare=, +Q, ...) the animation loop is not
       lens2pov's to use: a run a render, in render order. */
    if (po->user_arg_count > 0)
        return povray_render_chunks(f->chunk, f->renders, &with_pictures, err);
    povray_chunk *by_job = calloc((size_t)f->renders + 1, sizeof *by_job);
    int *order = calloc((size_t)f->renders + 1, sizeof *order);
    int *frames = calloc((size_t)f->renders + 1, sizeof *frames);
    const int n = !by_job || !order || !frames
                      ? -1 : assign_jobs(f->plans, f->renders, jobs > 0 ? jobs : 1, order, frames);
    int st = n > 0 ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int k = 0; k < f->renders && !st; k++)
        by_job[k] = f->chunk[order[k]];
    d.order = order;
    if (!st)
        st = povray_render_sequences(by_job, frames, n, &with_pictures, err);
    free(by_job), free(order), free(frames);
    return st;
}

/* The renders of f, developed into the picture out. */
static int render_by_jobs(const field_files *f, int jobs, const povray_options *po,
                          const char *out, l2p_error *err)
{
    field_developer dev;
    int st = field_develop_start(&dev, &f->table, err);
    if (st)
        return st;
    st = field_render_into(f, jobs, po, &dev, err);
    if (!st)
        st = field_develop_finish(&dev, out, err);
    field_develop_free(&dev);
    return st;
}

static void free_frame_chunks(povray_chunk *pc, int n)
{
    for (int k = 0; pc && k < n; k++)
        if (pc[k].pov_output)   /* else output_exr is the render's own, freed with the files */
            free((char *)pc[k].output_exr);
    free(pc);
}

/* Render r of frame i is run k = i * renders + r: frame-major, so that frames finish in turn
   and each is developed as soon as its renders are in (an animation stopped midway keeps the
   frames it finished, as POV-Ray's own would); within a frame the largest renders first, as
   packed. An animation frame's picture is named as POV-Ray names it (+O with the frame's
   number added). NULL out of memory. */
static povray_chunk *frame_chunks(const field_files *f, const field_render_options *o)
{
    const int n = f->renders * o->frame_count;
    povray_chunk *pc = calloc((size_t)n + 1, sizeof *pc);
    for (int k = 0; pc && k < n; k++) {
        const field_frame *fr = &o->frames[k / f->renders];
        pc[k] = f->chunk[k % f->renders];
        pc[k].placement = fr->placement;
        if (fr->number >= 0) {
            pc[k].frame = fr->number;
            pc[k].pov_output = pc[k].output_exr;
            pc[k].output_exr = povargs_frame_name(pc[k].pov_output, fr->number, o->frame_digits);
            if (!pc[k].output_exr) {
                free_frame_chunks(pc, k);
                return NULL;
            }
        }
    }
    return pc;
}

/* The frames, each developed from the map once its renders are in (povray_options'
   picture_done, on the calling thread). */
typedef struct frames_developing {
    const field_files *f;
    const povray_chunk *pc;
    const field_render_options *o;
    int *done;                 /* a frame's renders in */
    const char **exr;          /* a frame's pictures, one a render */
    bool remove_pictures;      /* a frame's pictures are deleted once it is developed */
} frames_developing;

/* Frame i's picture from its renders' pictures, which then go unless the work folder is kept:
   an animation's renders would otherwise fill the disk frame by frame. */
static int develop_frame(frames_developing *d, int i, l2p_error *err)
{
    for (int r = 0; r < d->f->renders; r++)
        d->exr[r] = d->pc[i * d->f->renders + r].output_exr;
    int st = image_io_ready(err);
    if (!st)
        st = field_develop(&d->f->table, d->exr, d->f->renders, d->o->frames[i].output, err);
    for (int r = 0; r < d->f->renders && !st && d->remove_pictures; r++)
        unlink(d->exr[r]);
    return st;
}

static int frame_picture_done(void *ctx, int k, l2p_error *err)
{
    frames_developing *d = ctx;
    const int i = k / d->f->renders;
    return ++d->done[i] == d->f->renders ? develop_frame(d, i, err) : L2P_OK;
}

/* Every run of every frame (frame_chunks), each frame developed as it comes in. */
static int render_frames(const field_files *f, const povray_chunk *pc,
                         const field_render_options *o, const povray_options *po, l2p_error *err)
{
    frames_developing d = {.f = f, .pc = pc, .o = o, .remove_pictures = !po->work_dir_kept};
    int st = L2P_OK;
    d.done = calloc((size_t)o->frame_count, sizeof *d.done);
    d.exr = malloc(sizeof *d.exr * ((size_t)f->renders + 1));
    if (!d.done || !d.exr)
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    povray_options with_frames = *po;
    with_frames.picture_done = frame_picture_done;
    with_frames.picture_ctx = &d;
    if (!st)
        st = povray_render_chunks(pc, f->renders * o->frame_count, &with_frames, err);
    free(d.done);
    free(d.exr);
    return st;
}

int field_render(const camera *c, const field_render_options *o, l2p_error *err)
{
    double weights_bytes;
    int st = field_weights_kept_bytes(&weights_bytes, err);
    if (st)
        return st;
    char library[PATH_MAX + 64];
    const field_files_request q = {.prefix = o->prefix, .jobs = o->jobs,
                                   .tolerance_px = o->tolerance_px,
                                   .placement = o->frames[0].placement ? "Lens2pov_Placement"
                                                                       : NULL,
                                   .rays_csv = o->rays_csv,
                                   .frame_s = povray_polls_library(library, sizeof library)
                                                  ? FIELD_FRAME_POLLS_S : FIELD_FRAME_S,
                                   .map_file = o->work_dir_kept,
                                   .weights_kept_bytes = weights_bytes, .develops = true};
    /* The image library must be there before POV-Ray runs (a file check); render loads it
       once POV-Ray runs (povray_started). */
    st = image_io_present(err);
    /* The scene sees the film's size as image_width and image_height, as in pixel renders. */
    const povray_options po = {.scene_path = o->scene_path, .work_dir = o->work_dir,
                               .jobs = o->jobs, .threads_per_job = o->threads_per_job,
                               .show_progress = o->progress, .user_args = o->povray_args,
                               .user_arg_count = o->povray_arg_count,
                               .started = o->povray_started, .work_dir_kept = o->work_dir_kept,
                               .film_width = c->film.width, .film_height = c->film.height,
                               .file_name = o->povray_file_name};
    const bool still = o->frame_count == 1 && o->frames[0].number < 0;
    const bool one_run_a_job = !o->povray_args && still;
    bool too_fine = false;
    if (!st && o->adaptive && still) {
        st = field_render_adaptive(c, &q, &po, o->frames[0].output, &too_fine, err);
        if (o->too_fine)
            *o->too_fine = too_fine;
        return st;
    }
    field_files f = {0};
    if (!st)
        st = field_files_make(c, &q, &f, err);
    if (o->too_fine)
        *o->too_fine = f.too_fine;
    povray_chunk *pc = st || one_run_a_job ? NULL : frame_chunks(&f, o);
    if (!st && !one_run_a_job && !pc)
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    if (!st && one_run_a_job)
        st = render_by_jobs(&f, o->jobs, &po, o->frames[0].output, err);
    else if (!st)
        st = render_frames(&f, pc, o, &po, err);
    free_frame_chunks(pc, f.renders * o->frame_count);
    field_files_free(&f);
    return st;
}
