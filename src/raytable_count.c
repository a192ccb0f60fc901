/* How many faces a ray table will have: every sample of the crop traced, none written. The
   renderer cuts the table into chunks of equal face counts from it, so that the POV-Ray
   processes parse equal shares (cutting by samples leaves the vignetted rows' chunks short). */
#include "raytable.h"

#include <pthread.h>
#include <stdatomic.h>
#include <unistd.h>

typedef struct counter {
    const camera *cam;
    atomic_int next_row;
    atomic_llong passed;
} counter;

static long long count_row(const camera *c, int py)
{
    vec3 film[CAMERA_BATCH];
    double u[CAMERA_BATCH], v[CAMERA_BATCH], weight[CAMERA_BATCH];
    ray out[CAMERA_BATCH];
    bool passed[CAMERA_BATCH];
    long long n = 0;
    int b = 0;
    for (int px = c->crop_x0; px < c->crop_x1; px++) {
        const sample_pixel pixel = sample_pattern_pixel(&c->samples, px, py);
        for (int k = 0; k < c->samples.spp; k++) {
            const film_sample s = sample_pattern_sample(&c->samples, pixel, k);
            film[b] = film_camera_from_raster(&c->film, px + s.offset_x, py + s.offset_y);
            u[b] = s.pupil_u;
            v[b] = s.pupil_v;
            const bool last = px == c->crop_x1 - 1 && k == c->samples.spp - 1;
            if (++b < CAMERA_BATCH && !last)
                continue;
            camera_trace_batch(c, film, u, v, b, out, weight, passed);
            for (int j = 0; j < b; j++)
                n += passed[j];
            b = 0;
        }
    }
    return n;
}

static void *count_rows(void *arg)
{
    counter *t = arg;
    long long n = 0;
    for (int py; (py = atomic_fetch_add(&t->next_row, 1)) < t->cam->crop_y1;)
        n += count_row(t->cam, py);
    atomic_fetch_add(&t->passed, n);
    return NULL;
}

long long raytable_count_faces(const camera *c)
{
    counter t = {.cam = c};
    atomic_init(&t.next_row, c->crop_y0);
    atomic_init(&t.passed, 0);
    const long cores = sysconf(_SC_NPROCESSORS_ONLN);
    const int helpers = cores < 1 ? 0 : cores > 16 ? 15 : (int)cores - 1;
    pthread_t thread[15];
    int started = 0;
    while (started < helpers && pthread_create(&thread[started], NULL, count_rows, &t) == 0)
        started++;
    count_rows(&t);   /* this thread is the last worker, and works alone if none starts */
    for (int i = 0; i < started; i++)
        pthread_join(thread[i], NULL);
    return atomic_load(&t.passed);
}
