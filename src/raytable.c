#include "raytable.h"

#include <stdlib.h>
#include <time.h>
#include "progress.h"

long long raytable_faces_for_memory(double memory_mb)
{
    const double mb = memory_mb > 0 ? memory_mb : RAYTABLE_DEFAULT_MEMORY_MB;
    const long long faces = (long long)(mb * 1048576.0 / 265.0);
    return faces > 0 ? faces : 1;
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The samples of one film row, CAMERA_BATCH at a time, in pixel-then-sample order (the order
   of the faces, whatever the batch size). */
typedef struct batch {
    int n;
    emitted_ray r[CAMERA_BATCH];
    vec3 film[CAMERA_BATCH];
    double u[CAMERA_BATCH], v[CAMERA_BATCH], weight[CAMERA_BATCH];
    ray out[CAMERA_BATCH];
    bool passed[CAMERA_BATCH];
} batch;

static int flush_batch(const camera *c, povmesh_emitter *e, batch *b, raytable_stats *stats,
                       l2p_error *err)
{
    camera_trace_batch(c, b->film, b->u, b->v, b->n, b->out, b->weight, b->passed);
    stats->samples += b->n;
    for (int k = 0; k < b->n; k++) {
        if (!b->passed[k])
            continue;
        stats->passed++;
        b->r[k].out = b->out[k];
        b->r[k].weight = b->weight[k];
        int st = povmesh_add(e, &b->r[k], err);
        if (st)
            return st;
    }
    b->n = 0;
    return L2P_OK;
}

static int trace_row(const camera *c, povmesh_emitter *e, int py, batch *b, raytable_stats *stats,
                     l2p_error *err)
{
    for (int px = c->crop_x0; px < c->crop_x1; px++)
        for (int k = 0; k < c->samples.spp; k++) {
            const film_sample s = sample_pattern_get(&c->samples, px, py, k);
            emitted_ray *r = &b->r[b->n];
            r->px = px;
            r->py = py;
            r->offset_x = s.offset_x;
            r->offset_y = s.offset_y;
            r->film_point = b->film[b->n] =
                film_camera_from_raster(&c->film, px + s.offset_x, py + s.offset_y);
            b->u[b->n] = s.pupil_u;
            b->v[b->n] = s.pupil_v;
            if (++b->n == CAMERA_BATCH) {
                int st = flush_batch(c, e, b, stats, err);
                if (st)
                    return st;
            }
        }
    return flush_batch(c, e, b, stats, err);
}

int raytable_write(const camera *c, const char *prefix, const char *csv_path,
                   long long chunk_faces, bool show_progress, povmesh_chunk_info **chunks,
                   int *chunk_count, raytable_stats *stats, l2p_error *err)
{
    const double start = now_seconds();
    raytable_stats local = {0, 0, 0};
    povmesh_emitter *e;
    int st = povmesh_open(&e, c, prefix, csv_path, chunk_faces, err);
    if (st)
        return st;
    progress bar;
    progress_start(&bar, "tracing", show_progress);
    const int rows = c->crop_y1 - c->crop_y0;
    batch *b = malloc(sizeof *b);
    if (!b)
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    else
        b->n = 0;
    for (int py = c->crop_y0; py < c->crop_y1 && !st; py++) {
        st = trace_row(c, e, py, b, &local, err);
        progress_update(&bar, (double)(py - c->crop_y0 + 1) / rows, NULL);
    }
    free(b);
    progress_finish(&bar);
    int close_st = povmesh_close(e, st == L2P_OK, chunks, chunk_count, err);
    local.seconds = now_seconds() - start;
    if (stats)
        *stats = local;
    return st ? st : close_st;
}
