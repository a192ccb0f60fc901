#include "cli/commands.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "base/cores.h"
#include "camera/camera.h"
#include "cli/framing.h"
#include "cli/lens_lookup.h"
#include "cli/frames.h"
#include "image/develop.h"
#include "image/image_io.h"
#include "base/outfile.h"
#include "povray/povargs.h"
#include "povray/povray.h"
#include "povray/scenecam.h"
#include "raytable/chunk_name.h"
#include "base/tempdir.h"
#include "cli/sizecheck.h"
#include "cli/workspace.h"
#include "field/field_render.h"
#include "field/fieldpass.h"
#include "raytable/raytable.h"

/* POV-Ray is given the workspace's files by name (the chunks' .ini and renders), so the
   workspace (--keep-temp, else under $TMPDIR) must have a name it reads as it is. */
static int check_workspace_path(const cli *c, l2p_error *err)
{
    const char *dir = c->keep_temp ? c->keep_temp : temp_root();
    char cwd[4096] = "";
    if (dir[0] != '/' && !getcwd(cwd, sizeof cwd))
        cwd[0] = '\0';
    if (povray_path_is_plain(cwd) && povray_path_is_plain(dir))
        return L2P_OK;
    return l2p_fail(err, L2P_BAD_INPUT, dir, 0, "POV-Ray 3.7 cannot use this folder for its "
                    "files (only plain ASCII without '\"' or '\\'): %s",
                    c->keep_temp ? "give another --keep-temp" : "set TMPDIR to another");
}

static int check_inputs(const cli *c, l2p_error *err)
{
    if (c->positional_count != 2)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "render takes SCENE.pov LENS (see --help)");
    if (!c->output)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "-o is required");
    const char *dot = strrchr(c->output, '.');
    if (!dot || (strcasecmp(dot, ".png") && strcasecmp(dot, ".exr") && strcasecmp(dot, ".tif") &&
                 strcasecmp(dot, ".tiff")))
        return l2p_fail(err, L2P_BAD_INPUT, c->output, 0, "unknown image type (use .png, .exr or .tif)");
    FILE *f = fopen(c->positional[0], "r");
    if (!f)
        return l2p_fail(err, L2P_BAD_INPUT, c->positional[0], 0, "cannot read: %s", strerror(errno));
    struct stat sb;
    const bool folder = fstat(fileno(f), &sb) == 0 && S_ISDIR(sb.st_mode);
    fclose(f);
    if (folder)
        return l2p_fail(err, L2P_BAD_INPUT, c->positional[0], 0, "is a folder, not a scene file");
    int st = povargs_check(c->povray_args, c->povray_arg_count, err);
    if (st)
        return st;
    /* Before any work: a render of minutes must not fail at its last step (a frame's
       picture is checked once its name is known). */
    if (!c->povray_args)
        st = outfile_check_path(c->output, err);
    if (!st && c->rays_csv)
        st = outfile_check_path(c->rays_csv, err);
    if (!st && c->keep_temp)
        st = outfile_check_dir(c->keep_temp, err);
    double weights_bytes;
    if (!st && c->field_sampling)
        st = field_weights_kept_bytes(&weights_bytes, err);
    if (!st && c->field_sampling && c->memory_mb > 0)
        fprintf(stderr, "lens2pov: warning: --memory-mb splits the ray tables of --sampling pixel; "
                        "a field render's POV-Ray processes are bounded by their faces and "
                        "pictures already: it changes nothing here\n");
    return st ? st : check_workspace_path(c, err);
}

/* Chunks small enough for the memory budget, as many as a multiple of the jobs and with the
   same number of faces, so that the parses, which POV-Ray does on one thread, run side by side
   and end together (3 chunks on 2 jobs would take two rounds for one and a half chunks' work).
   Returns the faces a chunk; *chunks gets their number (fewer when there are fewer faces). */
static long long chunk_faces_for(const camera *cam, const cli *c, int jobs, int *chunks)
{
    const long long budget = raytable_faces_for_memory(c->memory_mb);
    long long faces = raytable_count_faces(cam);
    if (faces < 0)   /* out of memory to count: every sample, an upper bound */
        faces = (long long)(cam->crop_x1 - cam->crop_x0) * (cam->crop_y1 - cam->crop_y0) *
                cam->samples.spp;
    const long long needed = (faces + budget - 1) / budget;
    const long long count = needed < 1 ? jobs : (needed + jobs - 1) / jobs * jobs;
    const long long per_chunk = (faces + count - 1) / count;
    *chunks = (int)count;
    return per_chunk > 0 ? per_chunk : 1;
}

/* The image library (about 0.3 s of dlopen) loads on the main thread once the first POV-Ray
   processes run (povray_options.started), mostly while they start up. Not on a thread of its
   own: while dlopen held the dynamic loader's lock, glibc's pthread_create waited for it (the
   trace's threads waited out the whole load). Its failure is reported when develop needs it. */
static void load_image_library(void *unused)
{
    (void)unused;
    image_io_ready(NULL);
}

/* The ray table is written on a thread of its own, and POV-Ray starts on each chunk as soon as
   it is complete; the image library (0.3 s to load) loads meanwhile. The --rays CSV is
   written in the workspace and handed to the user only when the render succeeds. */
typedef struct writer {
    const camera *cam;
    const cli *c;
    char prefix[8192], csv[8300];
    bool with_csv;             /* --rays: the first table's */
    const char *placement;     /* the transform the table is moved by; NULL: none */
    long long chunk_faces;
    pthread_mutex_t lock;
    int ready, total;          /* chunks complete; their count once done (-1 before) */
    int frames;                /* rendered through each chunk: one POV-Ray job a frame */
    atomic_bool stop;          /* from the renderer: stop at the next row */
    int status;
    l2p_error err;
} writer;

static int chunk_done(void *ctx, int index)
{
    writer *w = ctx;
    pthread_mutex_lock(&w->lock);
    w->ready = index + 1;
    pthread_mutex_unlock(&w->lock);
    return atomic_load(&w->stop);
}

static void *write_table(void *arg)
{
    writer *w = arg;
    l2p_error err;
    const raytable_stream stream = {chunk_done, w, &w->stop};
    const raytable_request q = {w->prefix, w->c->rays_csv && w->with_csv ? w->csv : NULL,
                                w->chunk_faces, !w->c->quiet, &stream, w->placement};
    raytable_stats stats;
    const int st = raytable_write(w->cam, &q, &stats, &err);
    pthread_mutex_lock(&w->lock);
    w->status = st;
    if (st)
        w->err = err;
    w->total = st ? w->ready : stats.chunks;
    pthread_mutex_unlock(&w->lock);
    return NULL;
}

static int chunks_ready(void *ctx, int *ready, int *total, l2p_error *err)
{
    writer *w = ctx;
    pthread_mutex_lock(&w->lock);
    *ready = w->ready * w->frames;   /* jobs are chunk-major: a chunk's frames together */
    *total = w->total < 0 ? -1 : w->total * w->frames;
    const int st = w->status;
    if (st)
        *err = w->err;
    pthread_mutex_unlock(&w->lock);
    return st;
}

static void free_chunk_list(povray_chunk *pc, int count)
{
    for (int i = 0; pc && i < count; i++) {
        free((char *)pc[i].include_path);
        free((char *)pc[i].ini_path);
        free((char *)pc[i].output_exr);
        free((char *)pc[i].pov_output);
    }
    free(pc);
}

/* The frames seen through one table, and what their pictures are named by. */
typedef struct table_frames {
    const render_frame **frame;
    int count, digits;
} table_frames;

/* One POV-Ray job for every chunk the writer will write and every frame, by name, chunk-major
   (job k renders chunk k / frames): a chunk's frames can start as soon as it is written. An
   animation frame's render is named as POV-Ray names it (+O with the frame number added).
   NULL out of memory. */
static povray_chunk *chunk_list(const writer *w, int count, long long faces,
                                const table_frames *tf)
{
    const int n = count * tf->count;
    povray_chunk *pc = calloc((size_t)n, sizeof *pc);
    for (int k = 0; pc && k < n; k++) {
        const int i = k / tf->count;
        const render_frame *f = tf->frame[k % tf->count];
        char *inc = chunk_file_name(w->prefix, i, "inc");
        char *ini = chunk_file_name(w->prefix, i, "ini");
        char *exr = chunk_file_name(w->prefix, i, "exr"), *named = exr, *pov = NULL;
        if (exr && f->number >= 0) {
            pov = exr;
            named = povargs_frame_name(exr, f->number, tf->digits);
        }
        pc[k] = (povray_chunk){inc, ini, named, faces, f->placement, f->number, pov};
        if (!inc || !ini || !named) {   /* pov, when set, is freed with the list */
            free_chunk_list(pc, k + 1);
            return NULL;
        }
    }
    return pc;
}

/* The workspace's CSV onto the temporary name beside --rays (opened at the start, so that a
   bad path fails at once): renamed, or copied when on another file system, and closed, so
   that a write that fails (a full disk) does so before any picture is replaced. */
static int stage_csv(const char *from, outfile *out, l2p_error *err)
{
    if (rename(from, out->temp_path) != 0) {
        if (errno != EXDEV)
            return l2p_fail(err, L2P_FAILED, out->final_path, 0, "cannot write: %s",
                            strerror(errno));
        FILE *in = fopen(from, "rb");
        if (!in)
            return l2p_fail(err, L2P_FAILED, from, 0, "cannot read: %s", strerror(errno));
        char buf[1 << 16];
        int st = L2P_OK;
        for (size_t n; !st && (n = fread(buf, 1, sizeof buf, in)) > 0;)
            if (fwrite(buf, 1, n, out->fp) != n)
                st = l2p_fail(err, L2P_FAILED, out->final_path, 0, "write failed: %s",
                              strerror(errno));
        if (!st && ferror(in))
            st = l2p_fail(err, L2P_FAILED, from, 0, "read failed");
        fclose(in);
        if (st)
            return st;
    }
    return outfile_finish(out, err);
}

/* The frames, each developed through the writer's sample map as soon as its chunks'
   pictures are in (povray_options' picture_done, on the calling thread) once the writer is
   done, since the map is complete only then: an animation stopped midway keeps the frames it
   finished. Frames whose pictures came in before are developed at the end. A developed
   frame's pictures go, unless the work folder is kept. */
typedef struct frames_developing {
    writer *w;
    const povray_chunk *pc;
    const table_frames *tf;
    samplemap map;
    bool have_map;
    int *done;                 /* a frame's pictures in */
    bool *developed;
    const char **exrs;         /* a frame's pictures, one a chunk */
    bool remove_pictures;      /* a frame's pictures are deleted once it is developed */
    outfile *csv;              /* --rays, staged before the first picture is written; NULL */
    bool csv_staged;
} frames_developing;

static int develop_frame(frames_developing *d, int f, int chunks, l2p_error *err)
{
    int st = image_io_ready(err);
    if (!st && !d->have_map) {
        char map_path[8300];
        snprintf(map_path, sizeof map_path, "%s.map", d->w->prefix);
        st = samplemap_read(map_path, &d->map, err);
        d->have_map = st == L2P_OK;
    }
    for (int i = 0; !st && i < chunks; i++)
        d->exrs[i] = d->pc[i * d->tf->count + f].output_exr;
    if (!st && d->csv && !d->csv_staged)
        d->csv_staged = !(st = stage_csv(d->w->csv, d->csv, err));
    if (!st)
        st = develop_files(&d->map, d->exrs, chunks, d->tf->frame[f]->output, err);
    for (int i = 0; !st && d->remove_pictures && i < chunks; i++)
        unlink(d->exrs[i]);
    d->developed[f] = st == L2P_OK;
    return st;
}

/* The writer's chunks once it has written them all well, else -1. */
static int chunks_written(writer *w)
{
    pthread_mutex_lock(&w->lock);
    const int total = w->status ? -1 : w->total;
    pthread_mutex_unlock(&w->lock);
    return total;
}

static int frame_picture_done(void *ctx, int k, l2p_error *err)
{
    frames_developing *d = ctx;
    const int f = k % d->tf->count, total = chunks_written(d->w);
    return ++d->done[f] == total ? develop_frame(d, f, total, err) : L2P_OK;
}

static int develop_rest(frames_developing *d, l2p_error *err)
{
    int st = L2P_OK;
    for (int f = 0; !st && f < d->tf->count; f++)
        if (!d->developed[f])
            st = develop_frame(d, f, d->w->total, err);
    return st;
}

/* Writes one table and renders its chunks for each of its frames side by side, developing
   each frame as it comes in. */
static int trace_and_render(const cli *c, const camera *cam, const workspace *ws, int jobs,
                            outfile *csv, const table_frames *tf, int table, l2p_error *err)
{
    writer w = {.cam = cam, .c = c, .total = -1, .frames = tf->count, .with_csv = table == 0};
    char runs[32];   /* the POV-Ray runs' files of a table after the first */
    snprintf(runs, sizeof runs, "povray.t%d", table);
    if (table == 0)
        snprintf(w.prefix, sizeof w.prefix, "%s/rays", ws->dir);
    else
        snprintf(w.prefix, sizeof w.prefix, "%s/rays.t%d", ws->dir, table);
    snprintf(w.csv, sizeof w.csv, "%s/rays.csv", ws->dir);
    w.placement = tf->frame[0]->placement ? "Lens2pov_Placement" : NULL;
    atomic_init(&w.stop, false);
    int count;
    /* Each frame is a job of its own: chunks beyond the jobs would only add parses. */
    const int chunk_jobs = (jobs + tf->count - 1) / tf->count;
    w.chunk_faces = chunk_faces_for(cam, c, chunk_jobs, &count);
    povray_chunk *pc = chunk_list(&w, count, w.chunk_faces, tf);
    frames_developing d = {.w = &w, .pc = pc, .tf = tf, .remove_pictures = !ws->keep,
                           .csv = c->rays_csv && table == 0 ? csv : NULL};
    d.done = calloc((size_t)tf->count, sizeof *d.done);
    d.developed = calloc((size_t)tf->count, sizeof *d.developed);
    d.exrs = calloc((size_t)count + 1, sizeof *d.exrs);
    if (!pc || !d.done || !d.developed || !d.exrs) {
        free(d.done), free(d.developed), free(d.exrs);
        free_chunk_list(pc, count * tf->count);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    pthread_mutex_init(&w.lock, NULL);
    pthread_t thread;
    int st = cleanup_start_thread(&thread, write_table, &w) == 0
                 ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "cannot start a thread");
    if (!st) {
        /* The image library must be there before POV-Ray runs (a file check); it loads once
           POV-Ray runs. */
        st = image_io_present(err);
        /* Every process may use every core: the chunks cost the same to parse but not to shade
           (sky against floor), and a process left shading alone then gets the idle cores. */
        const povray_options po = {c->positional[0], ws->dir, jobs, cores_online(),
                                   !c->quiet, NULL, chunks_ready, &w, c->povray_args,
                                   c->povray_arg_count, c->cam.width, c->cam.height,
                                   load_image_library, NULL, frame_picture_done, &d, ws->keep,
                                   table ? runs : NULL};
        if (!st)
            st = povray_render_chunks(pc, count * tf->count, &po, err);
        if (st)
            atomic_store(&w.stop, true);
        pthread_join(thread, NULL);
        if (!st && w.status)   /* failed after its last chunk: the map or the CSV */
            st = l2p_fail(err, w.status, NULL, 0, "%s", w.err.text);
        if (!st)
            st = image_io_ready(err);
        if (!st)
            st = develop_rest(&d, err);
        if (!st && d.csv && !d.csv_staged)
            st = stage_csv(w.csv, csv, err);
        if (!st && d.csv)
            st = outfile_commit(csv, err);
    }
    pthread_mutex_destroy(&w.lock);
    if (d.have_map)
        samplemap_free(&d.map);
    free(d.done), free(d.developed), free(d.exrs);
    free_chunk_list(pc, count * tf->count);
    return st;
}

/* Whether --adaptive can take this still (fieldtiles.h): its first round needs 4 samples at
   least, dispersion deals its wavelength bands over all spp samples, which a tile's first
   samples would not cover evenly, and blades post-stratify all spp samples (strata.c). Else
   a note, and the still is rendered uniformly. */
static bool adaptive_fits(const cli *c, const camera *cam)
{
    const char *why = cam->samples.spp < 16   ? "it needs --spp 16 or more"
                      : cam->dispersion      ? "the lens has dispersion"
                      : cam->lens.blades.count ? "the stop has blades, whose exposure needs "
                                                 "all the samples at once"
                                             : NULL;
    if (why && !c->quiet)
        fprintf(stderr, "lens2pov: note: rendering every pixel with %d samples, since "
                        "--adaptive cannot take this picture (%s)\n", cam->samples.spp, why);
    return !why;
}

/* --sampling field: src/field does the rest for the table's frames, --rays included, which is
   renamed into place once the pictures are. By default (neither --sampling nor
   --field-tolerance), a picture whose sub-images the tolerance cannot draw (a small film:
   more faces than pixels) is rendered with pixel sampling instead, with a note. */
static int field_and_render(const cli *c, const camera *cam, const workspace *ws, int jobs,
                            outfile *csv, const table_frames *tf, int table, l2p_error *err)
{
    field_frame *fr = calloc((size_t)tf->count, sizeof *fr);
    if (!fr)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int i = 0; i < tf->count; i++)
        fr[i] = (field_frame){tf->frame[i]->output, tf->frame[i]->placement, tf->frame[i]->number};
    char prefix[8192], runs[32];
    if (table == 0)
        snprintf(prefix, sizeof prefix, "%s/field", ws->dir);
    else
        snprintf(prefix, sizeof prefix, "%s/field.t%d", ws->dir, table);
    snprintf(runs, sizeof runs, "povray.t%d", table);
    const bool with_csv = c->rays_csv && table == 0;
    bool too_fine = false;
    const field_render_options fo = {c->positional[0], ws->dir, prefix, fr, tf->count, tf->digits,
                                     c->povray_args, c->povray_arg_count, jobs, cores_online(),
                                     !c->quiet, c->field_tolerance,
                                     c->adaptive && adaptive_fits(c, cam),
                                     with_csv ? csv : NULL, &too_fine, load_image_library,
                                     ws->keep, table ? runs : NULL};
    const int st = field_render(cam, &fo, err);
    free(fr);
    if (st == L2P_BAD_INPUT && too_fine && !c->sampling_chosen) {
        if (!c->quiet)
            fprintf(stderr, "lens2pov: note: rendering with --sampling pixel, since field "
                            "sampling cannot draw this picture (%s)\n", err->text);
        return trace_and_render(c, cam, ws, jobs, csv, tf, table, err);
    }
    return !st && with_csv ? outfile_commit(csv, err) : st;
}

/* A table of an animation that cannot be set up says for which frames: the frames before it
   are rendered by then. */
static void name_frames(l2p_error *err, const table_frames *tf)
{
    char prefix[96];
    const int n = snprintf(prefix, sizeof prefix, "frame %d%s: ", tf->frame[0]->number,
                           tf->count > 1 ? " and those it shares a table with" : "");
    const size_t keep = strnlen(err->text, sizeof err->text - 1 - (size_t)n);
    memmove(err->text + n, err->text, keep);
    err->text[n + keep] = '\0';
    memcpy(err->text, prefix, (size_t)n);
}

/* Table t: its camera, then its frames. */
static int render_table(const render_frames *rf, int t, const workspace *ws, int jobs,
                        outfile *csv, l2p_error *err)
{
    table_frames tf = {calloc((size_t)rf->count, sizeof *tf.frame), 0, 1};
    if (!tf.frame)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int i = 0; i < rf->count; i++)
        if (rf->frame[i].table == t)
            tf.frame[tf.count++] = &rf->frame[i];
    tf.digits = rf->digits;
    const cli *c = &tf.frame[0]->table_cli;
    lens l;
    camera cam;
    int st = lens_read_named(c->positional[1], &l, err);
    if (!st) {
        if (!(st = framing_camera_setup(&cam, &l, c, err))) {
            if (t == 0)
                cli_warn(c, &cam, true);
            st = c->field_sampling ? field_and_render(c, &cam, ws, jobs, csv, &tf, t, err)
                                   : trace_and_render(c, &cam, ws, jobs, csv, &tf, t, err);
        } else if (rf->animated) {
            name_frames(err, &tf);
        }
        camera_free(&cam);   /* also after a failed setup, as it always was */
    }
    free(tf.frame);
    return st;
}

/* Before any work: every frame's picture can be written (without POV-Ray's options the one
   picture was checked with the other inputs), and --adaptive has a still, since its tiles
   follow one picture's error. */
static int check_frames(const cli *c, const render_frames *rf, l2p_error *err)
{
    if (c->adaptive && (rf->count > 1 || rf->frame[0].number >= 0))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--adaptive renders a still, but POV-Ray's "
                        "options after -- make an animation of %d frame%s: leave out --adaptive "
                        "or the animation options", rf->count, rf->count == 1 ? "" : "s");
    int st = L2P_OK;
    for (int i = 0; !st && c->povray_args && i < rf->count; i++)
        st = outfile_check_path(rf->frame[i].output, err);
    return st;
}

int render_command(const cli *given, l2p_error *err)
{
    const int jobs = given->jobs > 0 ? given->jobs : cores_online();
    int st = check_inputs(given, err);
    if (!st)
        st = size_check_render(given, given->keep_temp ? given->keep_temp : temp_root(), jobs,
                               err);
    if (st)
        return st;
    cli resolved = *given;   /* POV-Ray's options with paths that hold in the scene's folder */
    const cli *c = &resolved;
    char **args = given->povray_args ? povargs_resolve(given->povray_args,
                                                       given->povray_arg_count) : NULL;
    if (given->povray_args && !args)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    resolved.povray_args = args;
    /* An ini may make POV-Ray animate or move the clock without options: the render then
       takes the path of POV-Ray's options (frames as POV-Ray numbers them, a run a render, no
       animation loop of lens2pov's, which holds the clock at 0), "+V", which lens2pov gives
       anyway, standing for them. */
    static char *const ini_settings[] = {"+V"};
    if (!given->povray_args && scene_inis_set_frames(given->positional[0])) {
        resolved.povray_args = ini_settings;
        resolved.povray_arg_count = 1;
    }
    render_frames rf;
    if ((st = render_frames_plan(c, &rf, err)) || (st = check_frames(c, &rf, err)) ||
        (st = size_check_frames(c, c->keep_temp ? c->keep_temp : temp_root(), jobs, rf.count,
                                rf.tables, err))) {
        render_frames_free(&rf);
        povargs_free(args);
        return st;
    }
    workspace w;
    outfile csv = {0};
    if (!(st = c->rays_csv ? outfile_open(&csv, c->rays_csv, err) : L2P_OK) &&
        !(st = workspace_make(&w, c->keep_temp, err))) {
        for (int t = 0; !st && t < rf.tables; t++)
            st = render_table(&rf, t, &w, jobs, &csv, err);
        workspace_remove(&w);
    }
    outfile_discard(&csv);   /* nothing when committed */
    render_frames_free(&rf);
    povargs_free(args);
    return st;
}
