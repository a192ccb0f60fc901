/* render --sampling field: sub-images built on worker threads, packed into POV-Ray renders of
   at most FIELD_FACES_PER_RENDER faces, rendered by the chunk runner as one animation a job,
   developed here. */
#include "field/field_render.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "field/fieldrays.h"
#include "field/subimage.h"
#include "image/develop.h"
#include "image/image_io.h"
#include "optics/pupil.h"
#include "povray/povray.h"
#include "raytable/povmesh.h"

typedef struct sub {
    field_mesh mesh;           /* for a render of the crop alone (field_render_size) */
    float *weights;            /* one a crop pixel, while building; then in its file */
    double colour[3];          /* its wavelength band's colour weights, with dispersion */
    field_stats stats;
    field_placement at;        /* where it is rendered */
} sub;

typedef struct render_plan {
    int width, height;         /* final picture (POV-Ray renders one more each way) */
    int first, count;          /* its sub-images */
    long long faces;
} render_plan;

typedef struct job {
    const camera *c;
    const char *work_dir;
    const field_tolerance *tol;
    sub *subs;
    int spp;
    atomic_int next;
    atomic_int status;
    l2p_error err;
    pthread_mutex_t lock;
} job;

/* ---------------------------------------------------------------- building */

/* WORK/field.fNNN.EXT: render NNN's include, ini and EXR, or sub-image NNN's weights. */
static char *name_of(const char *dir, int k, const char *ext)
{
    size_t n = strlen(dir) + 32;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s/field.f%03d.%s", dir, k, ext);
    return s;
}

/* A sub-image's weights go to the workspace (WORK/field.fNNN.weights, raw float32) until
   developing: spp of them in memory would be spp times the picture. */
static int save_weights(const job *j, int k, const float *weights, size_t n, l2p_error *e)
{
    char *path = name_of(j->work_dir, k, "weights");
    FILE *f = path ? fopen(path, "wb") : NULL;
    bool ok = f && fwrite(weights, sizeof *weights, n, f) == n;
    if (f && fclose(f) != 0)
        ok = false;
    int st = ok ? L2P_OK : l2p_fail(e, L2P_FAILED, path, 0, "cannot write");
    free(path);
    return st;
}

static int load_weights(const char *dir, int k, float *weights, size_t n, l2p_error *err)
{
    char *path = name_of(dir, k, "weights");
    FILE *f = path ? fopen(path, "rb") : NULL;
    bool ok = f && fread(weights, sizeof *weights, n, f) == n;
    if (f)
        fclose(f);
    int st = ok ? L2P_OK : l2p_fail(err, L2P_FAILED, path, 0, "cannot read");
    free(path);
    return st;
}

static void *build_worker(void *arg)
{
    job *j = arg;
    const size_t pixels = (size_t)(j->c->crop_x1 - j->c->crop_x0) * (j->c->crop_y1 - j->c->crop_y0);
    for (int k; atomic_load(&j->status) == L2P_OK && (k = atomic_fetch_add(&j->next, 1)) < j->spp;) {
        sub *s = &j->subs[k];
        l2p_error e;
        s->weights = malloc(pixels * sizeof *s->weights);
        const film_sample shared = field_shared_sample(j->c, k, s->colour);
        int st = s->weights ? field_build_subimage(j->c, shared, j->tol, FIELD_BASE_CELL, &s->mesh,
                                                   s->weights, &s->stats, &e)
                            : l2p_fail(&e, L2P_FAILED, NULL, 0, "out of memory");
        if (!st && !(s->stats.worst_pixels <= j->tol->pixels))
            st = l2p_fail(&e, L2P_BAD_INPUT, NULL, 0,
                          "--field-tolerance %g is finer than POV-Ray's float32 rays can hold "
                          "(sub-image %d): use a larger tolerance or --sampling pixel", j->tol->pixels, k);
        if (!st && (size_t)s->stats.faces > pixels)
            st = l2p_fail(&e, L2P_BAD_INPUT, NULL, 0,
                          "--field-tolerance %g needs %d faces for %zu pixels in sub-image %d: "
                          "use a larger tolerance or --sampling pixel", j->tol->pixels,
                          s->stats.faces, pixels, k);
        if (!st)
            st = save_weights(j, k, s->weights, pixels, &e);
        free(s->weights);
        s->weights = NULL;
        if (st) {
            pthread_mutex_lock(&j->lock);
            if (atomic_load(&j->status) == L2P_OK) {
                j->err = e;
                atomic_store(&j->status, st);
            }
            pthread_mutex_unlock(&j->lock);
        }
    }
    return NULL;
}

static int build_all(job *j, int threads, l2p_error *err)
{
    pthread_t t[64];
    int started = 0;
    if (threads > 64)
        threads = 64;
    for (int i = 0; i < threads; i++)
        if (pthread_create(&t[started], NULL, build_worker, j) == 0)
            started++;
    if (started == 0)
        build_worker(j);
    for (int i = 0; i < started; i++)
        pthread_join(t[i], NULL);
    if (atomic_load(&j->status))
        *err = j->err;
    return atomic_load(&j->status);
}

/* ---------------------------------------------------------------- packing */

/* n sub-images of w x h in a grid of nx columns: the render's final size. */
static void grid_size(int n, int nx, int w, int h, int *rw, int *rh)
{
    *rw = field_render_size(nx * w);
    *rh = field_render_size((n + nx - 1) / nx * h);
}

/* Groups consecutive sub-images into renders: as many as the face budget takes, at most
   most_per_render (so that every POV-Ray job gets a share). The first render takes the count
   and grid whose render wastes the fewest pixels (its sides are 2^a - 1: every UV a short
   binary fraction); every later one has its grid and size, with as many sub-images as the
   budget and the grid take, since a POV-Ray process renders all its renders at one size
   (assign_jobs). Returns the number of renders. */
static int pack(sub *subs, int spp, int w, int h, int most_per_render, render_plan *plans)
{
    int renders = 0, grid_n = 1, grid_nx = 1;
    for (int first = 0; first < spp; renders++) {
        double best = INFINITY;
        int best_n = 1, best_nx = 1;
        long long faces = 0;
        for (int n = 1; first + n <= spp; n++) {
            faces += subs[first + n - 1].stats.faces;
            if (n > 1 && (faces > FIELD_FACES_PER_RENDER || n > most_per_render ||
                          (renders > 0 && n > grid_n)))
                break;
            for (int nx = 1; nx <= n && renders == 0; nx++) {
                int rw, rh;
                grid_size(n, nx, w, h, &rw, &rh);
                double cost = (double)(rw + 1) * (rh + 1) / n;
                if (cost <= best)
                    best = cost, best_n = n, best_nx = nx;
            }
            if (renders > 0)
                best_n = n, best_nx = grid_nx;
        }
        if (renders == 0)
            grid_n = best_n, grid_nx = best_nx;
        render_plan *p = &plans[renders];
        grid_size(grid_n, grid_nx, w, h, &p->width, &p->height);
        p->first = first, p->count = best_n, p->faces = 0;
        for (int i = 0; i < best_n; i++) {
            sub *s = &subs[first + i];
            s->at = (field_placement){renders, i % best_nx * w, i / best_nx * h};
            p->faces += s->stats.faces;
        }
        first += best_n;
    }
    return renders;
}

/* A POV-Ray process renders its job's renders as the frames of one animation
   (povray_render_sequences), paying POV-Ray's start-up and exit once a job, not once a
   render; pack gives them all one size, as a POV-Ray run needs. Renders go, those of the
   most sub-images first, to the job with the fewest sub-images so far. order gets the renders
   job by job (in render order within a job), frames each job's count; returns the number of
   jobs. */
static int assign_jobs(const render_plan *plans, int renders, int jobs, int *order, int *frames)
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

/* ---------------------------------------------------------------- files */

/* Mesh space (camera space less the front vertex, mm) to the world: POV-Ray's matrix rows are
   the images of x, y and z, then the translation. */
static void world_matrix(const camera *c, double m[12])
{
    vec3 axis[3] = {camera_world_from_camera_offset(c, v3(1, 0, 0)),
                    camera_world_from_camera_offset(c, v3(0, 1, 0)),
                    camera_world_from_camera_offset(c, v3(0, 0, 1))};
    vec3 t = camera_world_from_camera_point(c, v3(0, 0, c->lens.surface[0].vertex_z_mm));
    for (int i = 0; i < 3; i++)
        m[3 * i] = axis[i].x, m[3 * i + 1] = axis[i].y, m[3 * i + 2] = axis[i].z;
    m[9] = t.x, m[10] = t.y, m[11] = t.z;
}

/* The render's include (its sub-images moved into place) and its ini: (W+1) x (H+1) pixels,
   rows 2.. and columns ..W only (FS#261, docs/povray.md). */
static int write_render(const camera *c, const sub *subs, const render_plan *p, const povray_chunk *ch,
                        l2p_error *err)
{
    field_mesh m;
    field_mesh_init(&m, p->width, p->height);
    int st = L2P_OK;
    for (int i = 0; i < p->count && !st; i++) {
        const sub *s = &subs[p->first + i];
        if (field_mesh_append(&m, &s->mesh, s->at.dx, s->at.dy) < 0)
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    double world[12];
    world_matrix(c, world);
    FILE *f = st ? NULL : fopen(ch->include_path, "w");
    if (!st && (!f || field_mesh_write_include(f, &m, "Lens2pov_Field", world) < 0))
        st = l2p_fail(err, L2P_FAILED, ch->include_path, 0, "cannot write");
    if (f && fclose(f) != 0 && !st)
        st = l2p_fail(err, L2P_FAILED, ch->include_path, 0, "cannot write");
    field_mesh_free(&m);
    f = st ? NULL : fopen(ch->ini_path, "w");
    if (!st && !f)
        return l2p_fail(err, L2P_FAILED, ch->ini_path, 0, "cannot write");
    if (f) {
        const bool q = povray_ini_needs_quotes(ch->output_exr);
        fprintf(f, "; lens2pov: a ray-field render, final pixel (x, y) at image pixel (x, y + 1)\n"
                   "Width=%d\nHeight=%d\nStart_Row=2\nEnd_Column=%d\nAntialias=Off\n"
                   "Output_File_Type=E\nOutput_To_File=On\nOutput_File_Name=%s%s%s\nDisplay=Off\n",
                p->width + 1, p->height + 1, p->width, q ? "\"" : "", ch->output_exr, q ? "\"" : "");
        if (fclose(f) != 0)
            st = l2p_fail(err, L2P_FAILED, ch->ini_path, 0, "cannot write");
    }
    return st;
}

/* --rays: written once the sub-images have their renders, before POV-Ray runs, so that a
   disk too full for it fails the render at once; the caller renames it into place when the
   render succeeds. */
static int write_rays(const camera *c, const sub *subs, int spp, outfile *csv, l2p_error *err)
{
    field_placement *at = malloc(sizeof *at * (size_t)spp);
    if (!at)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int k = 0; k < spp; k++)
        at[k] = subs[k].at;
    int st = field_rays_write(csv->fp, csv->final_path, c, at, spp, err);
    free(at);
    return st ? st : outfile_finish(csv, err);
}

/* ---------------------------------------------------------------- developing */

static int develop_render(const render_plan *p, const sub *subs, const char *exr, const char *dir,
                          int w, int h, size_t stride, double *sums, l2p_error *err)
{
    int iw, ih;
    float *rgba, *weights = malloc(sizeof *weights * (size_t)w * h);
    if (!weights)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    int st = image_read_rgba(exr, &iw, &ih, &rgba, err);
    if (st) {
        free(weights);
        return st;
    }
    if (iw != p->width + 1 || ih != p->height + 1) {
        free(rgba), free(weights);
        return l2p_fail(err, L2P_FAILED, exr, 0, "is %dx%d, not %dx%d", iw, ih, p->width + 1, p->height + 1);
    }
    for (int i = 0; i < p->count && !st; i++) {
        const sub *s = &subs[p->first + i];
        if ((st = load_weights(dir, p->first + i, weights, (size_t)w * h, err)))
            break;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                const float wt = weights[(size_t)y * w + x];
                if (wt <= 0)
                    continue;   /* blocked: no face, black */
                const float *px = rgba + 4 * ((size_t)(s->at.dy + y + 1) * iw + s->at.dx + x);
                develop_add(sums + stride * ((size_t)y * w + x), stride > 3 ? s->colour : NULL,
                            (double)wt, px);
            }
    }
    free(rgba), free(weights);
    return st;
}

/* ---------------------------------------------------------------- the whole */

static int render_and_develop(const camera *c, const field_render_options *o, sub *subs,
                              const render_plan *plans, int renders, l2p_error *err)
{
    const int w = c->crop_x1 - c->crop_x0, h = c->crop_y1 - c->crop_y0;
    povray_chunk *ch = calloc((size_t)renders, sizeof *ch), *by_job = calloc((size_t)renders, sizeof *by_job);
    int *order = calloc((size_t)renders, sizeof *order), *frames = calloc((size_t)renders, sizeof *frames);
    const int jobs = !ch || !by_job || !order || !frames
                         ? -1 : assign_jobs(plans, renders, o->jobs > 0 ? o->jobs : 1, order, frames);
    int st = jobs > 0 ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; r < renders && !st; r++) {
        ch[r] = (povray_chunk){.include_path = name_of(o->work_dir, r, "inc"),
                               .ini_path = name_of(o->work_dir, r, "ini"),
                               .output_exr = name_of(o->work_dir, r, "exr"),
                               .faces = plans[r].faces};
        if (!ch[r].include_path || !ch[r].ini_path || !ch[r].output_exr)
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
        else
            st = write_render(c, subs, &plans[r], &ch[r], err);
    }
    /* The scene sees the film's size as image_width and image_height, as in pixel renders. */
    const povray_options po = {.scene_path = o->scene_path, .work_dir = o->work_dir,
                               .jobs = o->jobs, .threads_per_job = o->threads_per_job,
                               .show_progress = o->progress, .film_width = c->film.width,
                               .film_height = c->film.height};
    for (int k = 0; k < renders && !st; k++)
        by_job[k] = ch[order[k]];
    if (!st)
        st = povray_render_sequences(by_job, frames, jobs, &po, err);
    samplemap map = {.records = NULL};
    povmesh_camera_header(c, &map.header);
    const size_t stride = develop_sums_per_pixel(&map.header);
    double *sums = st ? NULL : calloc(stride * (size_t)w * h, sizeof *sums);
    if (!st && !sums)
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; r < renders && !st; r++)
        st = develop_render(&plans[r], subs, ch[r].output_exr, o->work_dir, w, h, stride, sums, err);
    if (!st)
        st = develop_write_picture(&map, sums, o->output, err);
    free(sums);
    for (int r = 0; ch && r < renders; r++)
        free((char *)ch[r].include_path), free((char *)ch[r].ini_path), free((char *)ch[r].output_exr);
    free(ch), free(by_job), free(order), free(frames);
    return st;
}

int field_render(const camera *c, const field_render_options *o, l2p_error *err)
{
    if (!(o->tolerance_px > 0) || !isfinite(o->tolerance_px))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--field-tolerance must be a number of pixels above 0 (for exact rays, use --sampling pixel)");
    const int spp = c->samples.spp, w = c->crop_x1 - c->crop_x0, h = c->crop_y1 - c->crop_y0;
    field_tolerance tol;
    field_tolerance_of(c, o->tolerance_px, &tol);
    sub *subs = calloc((size_t)spp, sizeof *subs);
    render_plan *plans = calloc((size_t)spp, sizeof *plans);
    if (!subs || !plans) {
        free(subs), free(plans);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    for (int k = 0; k < spp; k++)
        field_mesh_init(&subs[k].mesh, field_render_size(w), field_render_size(h));
    job j = {.c = c, .work_dir = o->work_dir, .tol = &tol, .subs = subs, .spp = spp};
    atomic_init(&j.next, 0);
    atomic_init(&j.status, L2P_OK);
    pthread_mutex_init(&j.lock, NULL);
    int st = build_all(&j, o->jobs > 0 ? o->jobs : 1, err);
    pthread_mutex_destroy(&j.lock);
    /* the image library, loading on render's thread meanwhile: fail before POV-Ray runs when
       it cannot be loaded, and never leave while it is half loaded */
    l2p_error lib_err;
    const int lib = image_io_ready(&lib_err);
    if (!st && lib)
        st = l2p_fail(err, lib, NULL, 0, "%s", lib_err.text);
    if (!st) {
        const int jobs = o->jobs > 0 ? o->jobs : 1;
        int renders = pack(subs, spp, w, h, (spp + jobs - 1) / jobs, plans);
        if (o->rays_csv)
            st = write_rays(c, subs, spp, o->rays_csv, err);
        if (!st)
            st = render_and_develop(c, o, subs, plans, renders, err);
    }
    for (int k = 0; k < spp; k++)
        field_mesh_free(&subs[k].mesh), free(subs[k].weights);
    free(subs), free(plans);
    return st;
}
