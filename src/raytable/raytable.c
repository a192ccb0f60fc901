#include "raytable/raytable.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "base/cores.h"
#include "base/progress.h"

long long raytable_faces_for_memory(double memory_mb)
{
    const double mb = memory_mb > 0 ? memory_mb : RAYTABLE_DEFAULT_MEMORY_MB;
    const long long faces = (long long)(mb * 1048576.0 / RAYTABLE_POVRAY_BYTES_PER_FACE);
    return faces > 0 ? faces : 1;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Rows of the film are traced and formatted by worker threads, one row each at a time, and
   appended to the outputs in row order by the calling thread: the files are the same bytes
   whatever the number of threads. */

/* One traced and formatted row. */
typedef struct row_out {
    formatted_faces faces;     /* the passed rays */
    long long samples;
} row_out;

static int row_reserve(row_out *o, long long rays, bool csv)
{
    const size_t n = (size_t)rays;
    formatted_faces *f = &o->faces;
    f->text = malloc(n * POVMESH_RAY_TEXT_MAX + 1);
    f->length = malloc(n * sizeof *f->length + 1);
    f->kind = malloc(n + 1);
    f->record = malloc(n * sizeof *f->record + 1);
    f->band = malloc(n * sizeof *f->band + 1);
    f->csv = malloc((csv ? n * POVMESH_CSV_MAX : 0) + 1);
    f->csv_length = malloc(n * sizeof *f->csv_length + 1);
    return f->text && f->length && f->kind && f->record && f->band && f->csv && f->csv_length
               ? 0 : -1;
}

static void row_free(row_out *o)
{
    formatted_faces *f = &o->faces;
    free(f->text);
    free(f->length);
    free(f->kind);
    free(f->record);
    free(f->band);
    free(f->csv);
    free(f->csv_length);
}

/* The samples of one film row, CAMERA_BATCH at a time, in pixel-then-sample order (the order
   of the faces, whatever the batch size). */
typedef struct batch {
    sample_batch s;
    emitted_ray r[CAMERA_BATCH];
} batch;

/* Traces the batch and formats its passed rays into o; with no emitter, only counts them. */
static void flush_batch(const camera *c, const povmesh_emitter *e, batch *b, row_out *o)
{
    sample_batch *s = &b->s;
    camera_trace_batch(c, s);
    o->samples += s->n;
    int n = 0;   /* the passed rays, moved to the front */
    for (int k = 0; k < s->n; k++) {
        if (!s->passed[k])
            continue;
        b->r[n] = b->r[k];
        b->r[n].out = s->out[k];
        b->r[n++].weight = s->weight[k];
    }
    if (e)
        povmesh_format_rays(e, b->r, n, &o->faces);
    else
        o->faces.count += n;
    s->n = 0;
}

static void trace_row(const camera *c, const povmesh_emitter *e, int py, batch *b, row_out *o)
{
    o->faces.text_len = o->faces.csv_len = 0;
    o->faces.count = o->samples = 0;
    for (int px = c->crop_x0; px < c->crop_x1; px++) {
        const sample_pixel pixel = sample_pattern_pixel(&c->samples, px, py);
        for (int k = 0; k < c->samples.spp; k++) {
            const film_sample s = sample_pattern_sample(&c->samples, pixel, k);
            const vec3 film_point = film_camera_from_raster(&c->film, px + s.offset_x,
                                                            py + s.offset_y);
            if (!pupil_reaches(&c->pupil, film_point))
                continue;   /* no ray from there gets through: not a sample to trace */
            const int n = b->s.n;
            b->r[n] = (emitted_ray){.px = px, .py = py, .offset_x = s.offset_x,
                                    .offset_y = s.offset_y, .film_point = film_point};
            b->s.film_point[n] = film_point;
            b->s.u[n] = s.pupil_u;
            b->s.v[n] = s.pupil_v;
            if (c->dispersion) {
                const wavelength_sample w = sample_pattern_wavelength(&c->samples, pixel, k);
                b->r[n].band = w.band;
                b->r[n].wavelength_nm = b->s.wavelength_nm[n] = w.nm;
            }
            if (++b->s.n == CAMERA_BATCH)
                flush_batch(c, e, b, o);
        }
    }
    flush_batch(c, e, b, o);
}

static int append_row(povmesh_emitter *e, const row_out *o, raytable_stats *stats, l2p_error *err)
{
    stats->samples += o->samples;
    stats->passed += o->faces.count;
    return povmesh_append(e, &o->faces, err);
}

/* The workers and the writer share a ring of row slots: row py uses slot
   (py - first_row) % slots, once the row before it in that slot is written. */
typedef struct shared {
    const camera *cam;
    const povmesh_emitter *emitter;
    pthread_mutex_t lock;
    pthread_cond_t changed;
    int next_row, end_row, first_row, slots;
    int written_row;           /* rows before it are written: their slots are free */
    bool abort;
    row_out *slot;
    int *ready_row;            /* of each slot: the row whose results it holds, -1 at first */
} shared;

static void *worker(void *arg)
{
    shared *sh = arg;
    batch *b = malloc(sizeof *b);
    pthread_mutex_lock(&sh->lock);
    while (b && !sh->abort && sh->next_row < sh->end_row) {
        const int py = sh->next_row++, k = (py - sh->first_row) % sh->slots;
        /* Row py takes slot k once row py - slots, its last user, is written; waiting only for
           the slot to be free would let a later row take it first and deadlock. */
        while (py >= sh->written_row + sh->slots && !sh->abort)
            pthread_cond_wait(&sh->changed, &sh->lock);
        if (sh->abort)
            break;
        pthread_mutex_unlock(&sh->lock);
        b->s.n = 0;
        trace_row(sh->cam, sh->emitter, py, b, &sh->slot[k]);
        pthread_mutex_lock(&sh->lock);
        sh->ready_row[k] = py;
        pthread_cond_broadcast(&sh->changed);
    }
    if (!b)
        sh->abort = true;   /* the writer sees a row that never comes and stops */
    pthread_cond_broadcast(&sh->changed);
    pthread_mutex_unlock(&sh->lock);
    free(b);
    return NULL;
}

/* The writer: rows in order as the workers finish them. */
static int write_rows(shared *sh, povmesh_emitter *e, const atomic_bool *stop, progress *bar,
                      raytable_stats *stats, l2p_error *err)
{
    int st = L2P_OK;
    for (int py = sh->first_row; py < sh->end_row && !st; py++) {
        if (stop && atomic_load(stop))
            return l2p_fail(err, L2P_FAILED, NULL, 0, "stopped");
        const int k = (py - sh->first_row) % sh->slots;
        pthread_mutex_lock(&sh->lock);
        while (sh->ready_row[k] != py && !sh->abort)
            pthread_cond_wait(&sh->changed, &sh->lock);
        const bool aborted = sh->abort;
        pthread_mutex_unlock(&sh->lock);
        if (aborted)
            return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
        st = append_row(e, &sh->slot[k], stats, err);
        pthread_mutex_lock(&sh->lock);
        sh->written_row = py + 1;
        pthread_cond_broadcast(&sh->changed);
        pthread_mutex_unlock(&sh->lock);
        progress_update(bar, (double)(py - sh->first_row + 1) / (sh->end_row - sh->first_row), NULL);
    }
    return st;
}

enum { MAX_WORKERS = 16 };

static int number_of_workers(void)
{
    const int n = cores_online();
    return n < MAX_WORKERS ? n : MAX_WORKERS;
}

static int trace_rows(const camera *c, povmesh_emitter *e, const atomic_bool *stop, progress *bar,
                      raytable_stats *stats, l2p_error *err)
{
    const int workers = number_of_workers();
    shared sh = {.cam = c, .emitter = e, .next_row = c->crop_y0, .end_row = c->crop_y1,
                 .first_row = c->crop_y0, .written_row = c->crop_y0, .slots = 2 * workers};
    sh.slot = calloc((size_t)sh.slots, sizeof *sh.slot);
    sh.ready_row = malloc((size_t)sh.slots * sizeof *sh.ready_row);
    const long long rays = (long long)(c->crop_x1 - c->crop_x0) * c->samples.spp;
    int st = sh.slot && sh.ready_row ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int k = 0; k < sh.slots && !st; k++)
        sh.ready_row[k] = -1;
    for (int k = 0; k < sh.slots && !st; k++)
        if (row_reserve(&sh.slot[k], rays, povmesh_wants_csv(e)))
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    pthread_t thread[MAX_WORKERS];
    int started = 0;
    pthread_mutex_init(&sh.lock, NULL);
    pthread_cond_init(&sh.changed, NULL);
    while (!st && started < workers && pthread_create(&thread[started], NULL, worker, &sh) == 0)
        started++;
    if (!st && started == 0)
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "cannot start a thread");
    if (!st)
        st = write_rows(&sh, e, stop, bar, stats, err);
    pthread_mutex_lock(&sh.lock);
    sh.abort = true;
    pthread_cond_broadcast(&sh.changed);
    pthread_mutex_unlock(&sh.lock);
    for (int i = 0; i < started; i++)
        pthread_join(thread[i], NULL);
    for (int k = 0; sh.slot && k < sh.slots; k++)
        row_free(&sh.slot[k]);
    free(sh.slot);
    free(sh.ready_row);
    pthread_mutex_destroy(&sh.lock);
    pthread_cond_destroy(&sh.changed);
    return st;
}

int raytable_write(const camera *c, const raytable_request *q, raytable_stats *stats,
                   l2p_error *err)
{
    const double start = now_seconds();
    raytable_stats local = {0, 0, 0, 0};
    povmesh_emitter *e;
    int st = povmesh_open(&e, c, q->prefix, q->csv_path, q->chunk_faces, err);
    if (st)
        return st;
    if (q->stream)
        povmesh_set_chunk_hook(e, q->stream->chunk_done, q->stream->ctx);
    if (q->placement)
        povmesh_set_placement(e, q->placement);
    progress bar;
    progress_start(&bar, "tracing", q->progress);
    st = trace_rows(c, e, q->stream ? q->stream->stop : NULL, &bar, &local, err);
    progress_finish(&bar);
    int close_st = povmesh_close(e, st == L2P_OK, &local.chunks, err);
    local.seconds = now_seconds() - start;
    if (stats)
        *stats = local;
    return st ? st : close_st;
}

/* How many faces the table will have: every sample of the crop traced, none formatted. The
   renderer cuts the table into chunks of equal face counts from it, so that the POV-Ray
   processes parse equal shares (cutting by samples leaves the vignetted rows' chunks short). */
typedef struct counter {
    const camera *cam;
    atomic_int next_row;
    atomic_llong passed;
} counter;

static void *count_rows(void *arg)
{
    counter *t = arg;
    batch *b = malloc(sizeof *b);
    row_out o;
    memset(&o, 0, sizeof o);
    long long passed = 0;
    for (int py; b && (py = atomic_fetch_add(&t->next_row, 1)) < t->cam->crop_y1;) {
        b->s.n = 0;
        trace_row(t->cam, NULL, py, b, &o);
        passed += o.faces.count;
    }
    atomic_fetch_add(&t->passed, passed);
    free(b);   /* without it this worker took no row: the others take them */
    return NULL;
}

long long raytable_count_faces(const camera *c)
{
    counter t = {.cam = c};
    atomic_init(&t.next_row, c->crop_y0);
    atomic_init(&t.passed, 0);
    const int helpers = number_of_workers() - 1;
    pthread_t thread[MAX_WORKERS];
    int started = 0;
    while (started < helpers && pthread_create(&thread[started], NULL, count_rows, &t) == 0)
        started++;
    count_rows(&t);   /* this thread is the last worker, and works alone if none starts */
    for (int i = 0; i < started; i++)
        pthread_join(thread[i], NULL);
    return atomic_load(&t.next_row) >= c->crop_y1 ? atomic_load(&t.passed) : -1;
}
