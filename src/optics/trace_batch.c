/* The full simulation for many rays at once: the lane tracer of the best instruction set this
   processor has (trace_lanes.h), or the one-ray kernel one ray after the other. All of them
   give the same rays bit for bit (tests/test_trace.c). */
#include "optics/trace_batch.h"

#include <pthread.h>
#include <string.h>
#include "optics/trace_lanes_isa.h"

typedef struct isa {
    const char *name;
    int lanes;                   /* 1: the one-ray kernel, trace NULL */
    void (*trace)(const lens *l, trace_batch *b, int n, const double *inverse_square_nm);
} isa;

/* The one-ray kernel over the batch; wavelength_nm NULL for the file's indices. */
static void trace_one_by_one(const lens *l, trace_batch *b, int n, const double *wavelength_nm)
{
    for (int k = 0; k < n; k++) {
        if (b->status[k] != TRACE_PASSED)
            continue;
        ray r = {v3(b->ox[k], b->oy[k], b->oz[k]), v3(b->dx[k], b->dy[k], b->dz[k])};
        b->status[k] = trace_toward_scene_at(l, 0, l->count - 1,
                                             wavelength_nm ? wavelength_nm[k] : 0.0, &r, NULL);
        b->ox[k] = r.o.x; b->oy[k] = r.o.y; b->oz[k] = r.o.z;
        b->dx[k] = r.d.x; b->dy[k] = r.d.y; b->dz[k] = r.d.z;
    }
}

/* Best first. */
static const isa isas[] = {
#if defined(__x86_64__)
    {"avx512", 32, trace_lanes_avx512},
    {"avx2", 16, trace_lanes_avx2},
    {"sse2", 8, trace_lanes_sse2},
#endif
    {"scalar", 1, NULL},
};
enum { ISA_COUNT = sizeof isas / sizeof isas[0] };

static bool supported(const isa *s)
{
#if defined(__x86_64__)
    __builtin_cpu_init();
    if (strcmp(s->name, "avx512") == 0)
        return __builtin_cpu_supports("avx512f");
    if (strcmp(s->name, "avx2") == 0)
        return __builtin_cpu_supports("avx2");
#endif
    (void)s;
    return true;
}

static const isa *in_use;
static pthread_once_t chosen = PTHREAD_ONCE_INIT;

static void choose_best(void)
{
    for (int i = 0; i < ISA_COUNT && !in_use; i++)
        if (supported(&isas[i]))
            in_use = &isas[i];
}

const char *trace_batch_isa(void)
{
    pthread_once(&chosen, choose_best);
    return in_use->name;
}

int trace_batch_use_isa(const char *name)
{
    pthread_once(&chosen, choose_best);
    for (int i = 0; i < ISA_COUNT; i++)
        if (strcmp(isas[i].name, name) == 0 && supported(&isas[i])) {
            in_use = &isas[i];
            return 0;
        }
    return -1;
}

void trace_batch_toward_scene_at(const lens *l, trace_batch *b, int n,
                                 const double *wavelength_nm)
{
    pthread_once(&chosen, choose_best);
    const isa *s = in_use;
    if (!s->trace) {
        trace_one_by_one(l, b, n, wavelength_nm);
        return;
    }
    int padded = n;
    for (; padded % s->lanes; padded++) {   /* dead, finite rays fill the last step */
        b->ox[padded] = b->oy[padded] = b->oz[padded] = b->dx[padded] = b->dy[padded] = 0;
        b->dz[padded] = 1;
        b->status[padded] = TRACE_MISSED;
    }
    double x[TRACE_BATCH_MAX];
    if (wavelength_nm)
        for (int k = 0; k < padded; k++)
            x[k] = lens_inverse_square(k < n ? wavelength_nm[k] : WAVELENGTH_D_NM);
    s->trace(l, b, padded, wavelength_nm ? x : NULL);
}

void trace_batch_toward_scene(const lens *l, trace_batch *b, int n)
{
    trace_batch_toward_scene_at(l, b, n, NULL);
}
