#include "raytable.h"

#include <time.h>
#include "progress.h"

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int trace_pixel(const camera *c, povmesh_emitter *e, int px, int py,
                       raytable_stats *stats, l2p_error *err)
{
    for (int k = 0; k < c->samples.spp; k++) {
        const film_sample s = sample_pattern_get(&c->samples, px, py, k);
        emitted_ray r = {.px = px, .py = py, .offset_x = s.offset_x, .offset_y = s.offset_y};
        r.film_point = film_camera_from_raster(&c->film, px + s.offset_x, py + s.offset_y);
        stats->samples++;
        if (!camera_trace(c, r.film_point, s.pupil_u, s.pupil_v, &r.out, &r.weight))
            continue;
        stats->passed++;
        int st = povmesh_add(e, &r, err);
        if (st)
            return st;
    }
    return L2P_OK;
}

int raytable_write(const camera *c, const char *prefix, const char *csv_path,
                   long long chunk_faces, bool progress, povmesh_chunk_info **chunks,
                   int *chunk_count, raytable_stats *stats, l2p_error *err)
{
    const double start = now_seconds();
    raytable_stats local = {0, 0, 0};
    povmesh_emitter *e;
    int st = povmesh_open(&e, c, prefix, csv_path, chunk_faces, err);
    if (st)
        return st;
    progress_bar bar;
    progress_begin(&bar, "tracing", progress);
    const int rows = c->crop_y1 - c->crop_y0;
    for (int py = c->crop_y0; py < c->crop_y1 && !st; py++) {
        for (int px = c->crop_x0; px < c->crop_x1 && !st; px++)
            st = trace_pixel(c, e, px, py, &local, err);
        progress_update(&bar, (double)(py - c->crop_y0 + 1) / rows);
    }
    progress_end(&bar);
    int close_st = povmesh_close(e, st == L2P_OK, chunks, chunk_count, err);
    local.seconds = now_seconds() - start;
    if (stats)
        *stats = local;
    return st ? st : close_st;
}
