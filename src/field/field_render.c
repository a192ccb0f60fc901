/* The files of render and trace --sampling field: sub-images built on worker threads, their
   weights into the field map's file (trace's, and render's kept work folder's) and kept for
   render's develop (fieldpass.h), packed into POV-Ray renders (fieldpack.c), each render's
   include and ini (field_povray.c runs and develops them). */
#include "field/field_files.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "field/fieldmap.h"
#include "field/fieldpack.h"
#include "field/fieldpass.h"
#include "field/fieldpixels.h"
#include "field/fieldrays.h"
#include "field/strata.h"
#include "field/subimage.h"
#include "base/workers.h"
#include "raytable/chunk_ini.h"
#include "optics/pupil.h"
#include "povray/povray.h"
#include "raytable/povmesh.h"

typedef struct sub {
    field_piece piece;         /* what it shows */
    field_mesh mesh;           /* for a render of the piece alone (field_render_size) */
    float *weights;            /* one a crop pixel, while building; then in the map's file and
                                  kept (field_pass) */
    uint32_t band;             /* its wavelength band, with dispersion */
    field_stats stats;
    field_placement at;        /* where it is rendered */
} sub;

typedef struct job {
    const camera *c;
    const outfile *map;        /* the field map, its weights written as sub-images are built;
                                  NULL: no file */
    const samplemap_header *header;
    field_pass *pass;          /* each sub-image's weights as kept until developed; NULL:
                                  not kept (trace) */
    bool keep_weights;         /* the weights themselves, not their runs */
    const field_tolerance *tol;
    field_strata strata;
    sub *subs;
    int spp;
    atomic_int next;
    atomic_int status;
    l2p_error err;
    bool too_fine;             /* the failure is a sub-image the tolerance cannot draw */
    pthread_mutex_t lock;
} job;

/* ---------------------------------------------------------------- building */

/* PREFIX.fNNN.EXT: render NNN's include, ini or picture. */
static char *name_of(const char *prefix, int k, const char *ext)
{
    size_t n = strlen(prefix) + 32;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s.f%03d.%s", prefix, k, ext);
    return s;
}

/* Builds sub-image k through camera `piece` (a copy of the camera, narrowed here to its
   piece), its weights into the map's file and kept; on failure *too_fine says whether the
   tolerance cannot draw it. */
static int build_one(job *j, int k, camera *piece, bool *too_fine, l2p_error *e)
{
    sub *s = &j->subs[k];
    const int id = s->piece.k;
    const size_t pixels = (size_t)s->piece.w * s->piece.h;
    field_piece_crop(j->c, &s->piece, piece);
    s->weights = malloc(pixels * sizeof *s->weights);
    film_sample shared = field_shared_sample(j->c, id, &s->band);
    const double scale = field_strata_place(&j->strata, &shared);
    int st = s->weights ? field_build_subimage(piece, shared, scale, j->tol, FIELD_COARSEST_CELL,
                                               &s->mesh, s->weights, &s->stats, e)
                        : l2p_fail(e, L2P_FAILED, NULL, 0, "out of memory");
    if (!st && !(s->stats.worst_pixels <= j->tol->pixels))
        st = l2p_fail(e, L2P_BAD_INPUT, NULL, 0,
                      "--field-tolerance %g is finer than POV-Ray's float32 rays can hold "
                      "(sub-image %d): use a larger tolerance or --sampling pixel", j->tol->pixels,
                      id);
    if (!st && (size_t)s->stats.faces > pixels)
        st = l2p_fail(e, L2P_BAD_INPUT, NULL, 0,
                      "--field-tolerance %g needs %d faces for %zu pixels in sub-image %d: "
                      "use a larger tolerance or --sampling pixel", j->tol->pixels,
                      s->stats.faces, pixels, id);
    *too_fine = st == L2P_BAD_INPUT;   /* the two refusals above */
    if (!st)
        field_mesh_shrink(&s->mesh);   /* kept until the renders are written */
    if (!st && j->map)
        st = field_map_put_weights(j->map, j->header, k, s->weights, e);
    if (!st && j->pass)
        st = field_pass_of(&s->weights, (long long)pixels, shared, scale, j->keep_weights,
                           &j->pass[k], e);
    free(s->weights);
    s->weights = NULL;
    return st;
}

static void *build_worker(void *arg)
{
    job *j = arg;
    camera *piece = malloc(sizeof *piece);
    if (piece)
        *piece = *j->c;
    for (int k; atomic_load(&j->status) == L2P_OK && (k = atomic_fetch_add(&j->next, 1)) < j->spp;) {
        l2p_error e;
        bool too_fine = false;
        const int st = piece ? build_one(j, k, piece, &too_fine, &e)
                             : l2p_fail(&e, L2P_FAILED, NULL, 0, "out of memory");
        if (st) {
            pthread_mutex_lock(&j->lock);
            if (atomic_load(&j->status) == L2P_OK) {
                j->err = e;
                j->too_fine = too_fine;
                atomic_store(&j->status, st);
            }
            pthread_mutex_unlock(&j->lock);
        }
    }
    free(piece);
    return NULL;
}

static int build_all(job *j, int threads, l2p_error *err)
{
    workers_run(build_worker, j, threads);
    if (atomic_load(&j->status))
        *err = j->err;
    return atomic_load(&j->status);
}

/* ---------------------------------------------------------------- packing */

/* The sub-images into renders (fieldpack.h): whole crops in a grid of w x h slots, pieces
   (w 0) on shelves across a render as wide as the crop's; each one's place into its at.
   Returns the number of renders, or -1 out of memory. */
static int pack(sub *subs, int spp, int w, int h, int crop_w, int jobs, double frame_s,
                field_render_plan *plans)
{
    field_packed *slots = malloc(sizeof *slots * (size_t)spp);
    if (!slots)
        return -1;
    for (int k = 0; k < spp; k++)
        slots[k] = (field_packed){subs[k].piece, subs[k].stats.faces, {0, 0, 0}};
    const int renders = w ? field_pack_grid(slots, spp, w, h, jobs, frame_s, plans)
                          : field_pack_shelves(slots, spp, crop_w, jobs, frame_s, plans);
    for (int k = 0; k < spp; k++)
        subs[k].at = slots[k].at;
    free(slots);
    return renders;
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

/* The include of render p: its sub-images moved into place, the camera by placement last. */
static int write_include(const camera *c, const sub *subs, const field_render_plan *p,
                         const char *placement, outfile *f, l2p_error *err)
{
    field_mesh m;
    field_mesh_init(&m, p->width, p->height);
    int st = L2P_OK;
    for (int i = 0; i < p->count && !st; i++) {
        const sub *s = &subs[p->first + i];
        if (field_mesh_append(&m, &s->mesh, s->at.dx, s->at.dy) < 0)
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    if (!st && field_mesh_sort_faces_by_area(&m) < 0)
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    double world[12];
    world_matrix(c, world);
    if (!st && field_mesh_write_include(f->fp, &m, "Lens2pov_Field", world, placement) < 0)
        st = l2p_fail(err, L2P_FAILED, f->final_path, 0, "cannot write");
    field_mesh_free(&m);
    return st ? st : outfile_finish(f, err);
}

/* The includes, written on worker threads, each opened, written and closed in turn: with a
   render a sub-image there can be thousands, more than a process may hold open. The table of
   temporary files to remove on a signal is not thread-safe: opening takes the lock. */
typedef struct writing {
    const camera *c;
    const sub *subs;
    const field_render_plan *plans;
    const char *placement;
    const povray_chunk *chunk;
    outfile *inc;
    int renders;
    atomic_int next;
    atomic_int status;
    l2p_error err;
    pthread_mutex_t lock;
} writing;

static void *write_worker(void *arg)
{
    writing *w = arg;
    for (int r; atomic_load(&w->status) == L2P_OK && (r = atomic_fetch_add(&w->next, 1)) < w->renders;) {
        l2p_error e;
        pthread_mutex_lock(&w->lock);
        int st = outfile_open(&w->inc[r], w->chunk[r].include_path, &e);
        pthread_mutex_unlock(&w->lock);
        if (!st)
            st = write_include(w->c, w->subs, &w->plans[r], w->placement, &w->inc[r], &e);
        if (st) {
            pthread_mutex_lock(&w->lock);
            if (atomic_load(&w->status) == L2P_OK) {
                w->err = e;
                atomic_store(&w->status, st);
            }
            pthread_mutex_unlock(&w->lock);
        }
    }
    return NULL;
}

static int write_includes(writing *w, int threads, l2p_error *err)
{
    atomic_init(&w->next, 0);
    atomic_init(&w->status, L2P_OK);
    pthread_mutex_init(&w->lock, NULL);
    workers_run(write_worker, w, threads < w->renders ? threads : w->renders);
    pthread_mutex_destroy(&w->lock);
    const int st = atomic_load(&w->status);
    if (st)
        *err = w->err;
    return st;
}

/* Its ini: (W+1) x (H+1) pixels, rows 2.. and columns ..W only (FS#261, docs/povray.md), and
   of those only the grid's (POV-Ray still searches the faces for a pixel no face covers, at
   about the cost of a pixel that one does), the picture named by its absolute path. */
static int write_ini(const camera *c, const field_render_plan *p, const char *exr, outfile *f,
                     l2p_error *err)
{
    char *path = chunk_ini_absolute(exr);
    if (!path)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    if (!povray_ini_can_carry(path)) {
        free(path);
        return l2p_fail(err, L2P_BAD_INPUT, exr, 0, "POV-Ray's .ini cannot name this file: choose "
                        "another name");
    }
    const char *q = povray_ini_needs_quotes(path) ? "\"" : "";
    fprintf(f->fp, "; lens2pov: a ray-field render, final pixel (x, y) at image pixel (x, y + 1)\n"
                   "Width=%d\nHeight=%d\nStart_Row=2\nEnd_Row=%d\nStart_Column=0.0\n"
                   "End_Column=%d\nAntialias=Off\n"
                   "Output_File_Type=E\nOutput_To_File=On\nOutput_File_Name=%s%s%s\nDisplay=Off\n",
            p->width + 1, p->height + 1, p->used_height + 1, p->used_width, q, path, q);
    chunk_ini_as_render(f->fp, c->film.width, c->film.height);
    free(path);
    return outfile_finish(f, err);
}

/* --rays: written once the sub-images have their renders, before POV-Ray runs, so that a
   disk too full for it fails at once; the caller renames it into place on success. */
static int write_rays(const camera *c, const sub *subs, int spp, int strata_samples,
                      const field_piece *pieces, outfile *csv, l2p_error *err)
{
    field_placement *at = malloc(sizeof *at * (size_t)spp);
    if (!at)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int k = 0; k < spp; k++)
        at[k] = subs[k].at;
    int st = field_rays_write(csv->fp, csv->final_path, c, strata_samples, pieces, NULL, at, spp,
                              err);
    free(at);
    return st ? st : outfile_finish(csv, err);
}

/* Sub-image k's weights for f's map (its weights_of), as kept. */
static int weights_again(const void *ctx, int k, float *weights, l2p_error *err)
{
    const field_files *f = ctx;
    if (!f->pieces)
        return field_pass_weights(f->camera, &f->pass[k], weights, err);
    field_piece_crop(f->camera, &f->pieces[k], f->piece_camera);
    return field_pass_weights(f->piece_camera, &f->pass[k], weights, err);
}

/* The map's tables: each render's size, each sub-image's place and band; into the file too
   when there is one. */
static int finish_map(const camera *c, const sub *subs, const field_render_plan *plans, int renders,
                      field_files *f, l2p_error *err)
{
    const int spp = f->subimages;
    field_map *m = &f->table;
    *m = (field_map){.renders = renders, .weights_of = f->pass ? weights_again : NULL,
                     .weights_ctx = f};
    povmesh_camera_header(c, &m->header);
    m->header.spp = m->subimages = spp;
    m->width = malloc(sizeof *m->width * (size_t)renders);
    m->height = malloc(sizeof *m->height * (size_t)renders);
    m->at = malloc(sizeof *m->at * (size_t)spp);
    m->band = malloc(sizeof *m->band * (size_t)spp);
    m->piece = f->pieces ? malloc(sizeof *m->piece * (size_t)spp) : NULL;
    int st = m->width && m->height && m->at && m->band && (m->piece || !f->pieces) ? L2P_OK
             : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; !st && r < renders; r++)
        m->width[r] = plans[r].width, m->height[r] = plans[r].height;
    for (int k = 0; !st && k < spp; k++)
        m->at[k] = subs[k].at, m->band[k] = subs[k].band;
    for (int k = 0; !st && m->piece && k < spp; k++)
        m->piece[k] = subs[k].piece;
    if (!st && f->map_path)
        st = field_map_finish(&f->map, m, err);
    return st;
}

/* ---------------------------------------------------------------- the whole */

void field_files_free(field_files *f)
{
    outfile_discard(&f->map);
    field_map_free(&f->table);
    for (int k = 0; f->pass && k < f->subimages; k++)
        field_pass_free(&f->pass[k]);
    free(f->pass);
    for (int r = 0; r < f->renders; r++) {
        outfile_discard(&f->inc[r]), outfile_discard(&f->ini[r]);
        free((char *)f->chunk[r].include_path), free((char *)f->chunk[r].ini_path);
        free((char *)f->chunk[r].output_exr);
    }
    free(f->inc), free(f->ini), free(f->chunk), free(f->map_path), free(f->plans);
    free(f->piece_camera);
    memset(f, 0, sizeof *f);
}

static int files_commit(field_files *f, l2p_error *err)
{
    int st = f->map_path ? outfile_commit(&f->map, err) : L2P_OK;
    for (int r = 0; r < f->renders && !st; r++)
        if (!(st = outfile_commit(&f->inc[r], err)))
            st = outfile_commit(&f->ini[r], err);
    return st;
}

/* Builds the sub-images (weights into the map's file, if any, and kept in out), packs them
   and writes every render's include and ini and the map, under temporary names. */
static int build_files(const camera *c, const field_files_request *q, field_files *out,
                       sub **subs_out, l2p_error *err)
{
    const double tolerance_px = q->tolerance_px;
    if (!(tolerance_px > 0) || !isfinite(tolerance_px))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--field-tolerance must be a number of pixels "
                        "above 0 (for exact rays, use --sampling pixel)");
    const int spp = q->pieces ? q->count : c->samples.spp;
    if (q->pieces && q->map_file)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "a field map file takes whole crops alone");
    const int jobs = q->jobs > 0 ? q->jobs : 1;
    const char *prefix = q->prefix;
    field_tolerance tol;
    field_tolerance_of(c, tolerance_px, &tol);
    samplemap_header header;
    povmesh_camera_header(c, &header);
    sub *subs = calloc((size_t)spp, sizeof *subs);
    field_render_plan *plans = calloc((size_t)spp, sizeof *plans);
    char *map_path = q->map_file ? malloc(strlen(prefix) + 8) : NULL;
    out->camera = c;
    out->subimages = spp;
    out->pieces = q->pieces;
    out->piece_camera = q->pieces ? malloc(sizeof *out->piece_camera) : NULL;
    if (out->piece_camera)
        *out->piece_camera = *c;
    out->pass = q->develops ? calloc((size_t)spp, sizeof *out->pass) : NULL;
    *subs_out = subs;
    if (!subs || !plans || (q->develops && !out->pass) || (q->map_file && !map_path) ||
        (q->pieces && !out->piece_camera)) {
        free(plans), free(map_path);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    /* every sub-image has a slot of the largest piece's size in its render */
    const int crop_w = c->crop_x1 - c->crop_x0, crop_h = c->crop_y1 - c->crop_y0;
    int w = 1, h = 1;
    double pixels = 0;   /* the sub-images' in all */
    for (int k = 0; k < spp; k++) {
        subs[k].piece = q->pieces ? q->pieces[k] : (field_piece){k, 0, 0, crop_w, crop_h};
        pixels += (double)subs[k].piece.w * subs[k].piece.h;
        w = subs[k].piece.w > w ? subs[k].piece.w : w;
        h = subs[k].piece.h > h ? subs[k].piece.h : h;
        field_mesh_init(&subs[k].mesh, field_render_size(subs[k].piece.w),
                        field_render_size(subs[k].piece.h));
    }
    int st = L2P_OK;
    if (map_path) {
        sprintf(map_path, "%s.map", prefix);
        out->map_path = map_path;
        if (!(st = outfile_open(&out->map, map_path, err)))
            st = field_map_begin(&out->map, &header, err);
    }
    job j = {.c = c, .map = map_path ? &out->map : NULL, .header = &header, .pass = out->pass,
             .keep_weights = 4.0 * pixels <= q->weights_kept_bytes, .tol = &tol,
             .subs = subs, .spp = spp};
    field_strata_count(c, q->strata_samples > 0 ? q->strata_samples : c->samples.spp, &j.strata);
    atomic_init(&j.next, 0);
    atomic_init(&j.status, L2P_OK);
    pthread_mutex_init(&j.lock, NULL);
    if (!st)
        st = build_all(&j, jobs, err);
    out->too_fine = st && j.too_fine;
    pthread_mutex_destroy(&j.lock);
    int renders = st ? 0 : pack(subs, spp, q->pieces ? 0 : w, h, crop_w, jobs, q->frame_s, plans);
    if (renders < 0)
        renders = 0, st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    if (!st)
        st = finish_map(c, subs, plans, renders, out, err);
    if (!st)
        st = outfile_finish(&out->map, err);
    out->inc = calloc((size_t)renders + 1, sizeof *out->inc);
    out->ini = calloc((size_t)renders + 1, sizeof *out->ini);
    out->chunk = calloc((size_t)renders + 1, sizeof *out->chunk);
    if (!st && (!out->inc || !out->ini || !out->chunk))
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; r < renders && !st; r++, out->renders++) {
        povray_chunk *ch = &out->chunk[r];
        const int named = q->render_base + r;
        *ch = (povray_chunk){.include_path = name_of(prefix, named, "inc"),
                             .ini_path = name_of(prefix, named, "ini"),
                             .output_exr = name_of(prefix, named, "exr"), .faces = plans[r].faces};
        if (!ch->include_path || !ch->ini_path || !ch->output_exr)
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
        if (!st && !(st = outfile_open(&out->ini[r], ch->ini_path, err)))
            st = write_ini(c, &plans[r], ch->output_exr, &out->ini[r], err);
    }
    if (!st) {
        writing w = {.c = c, .subs = subs, .plans = plans, .placement = q->placement,
                     .chunk = out->chunk, .inc = out->inc, .renders = renders};
        st = write_includes(&w, jobs, err);
    }
    out->plans = plans;
    return st;
}

static void subs_free(sub *subs, int spp)
{
    for (int k = 0; subs && k < spp; k++)
        field_mesh_free(&subs[k].mesh), free(subs[k].weights);
    free(subs);
}

int field_files_make(const camera *c, const field_files_request *q, field_files *out,
                     l2p_error *err)
{
    sub *subs = NULL;
    memset(out, 0, sizeof *out);   /* also when build_files refuses the tolerance first */
    int st = build_files(c, q, out, &subs, err);
    if (!st && q->rays_csv)
        st = write_rays(c, subs, out->subimages,
                        q->strata_samples > 0 ? q->strata_samples : c->samples.spp, q->pieces,
                        q->rays_csv, err);
    if (!st)
        st = files_commit(out, err);
    out->stats.renders = out->renders;
    for (int k = 0; !st && k < out->subimages; k++) {
        out->stats.faces += subs[k].stats.faces;
        out->stats.passed += subs[k].stats.passed;
        out->stats.pixels += subs[k].stats.passed + subs[k].stats.blocked;
    }
    subs_free(subs, out->subimages);
    return st;
}

int field_trace(const camera *c, const field_trace_options *o, field_trace_stats *stats,
                l2p_error *err)
{
    /* the renders are for the user's POV-Ray, whose polls are as they are */
    const field_files_request q = {.prefix = o->prefix, .jobs = o->jobs,
                                   .tolerance_px = o->tolerance_px, .rays_csv = o->rays_csv,
                                   .frame_s = FIELD_FRAME_S, .map_file = true};
    field_files f;
    const int st = field_files_make(c, &q, &f, err);
    *stats = f.stats;
    field_files_free(&f);
    return st;
}
