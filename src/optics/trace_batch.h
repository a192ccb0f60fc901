/* Full simulation of many rays at once (see trace_batch.c). */
#ifndef LENS2POV_TRACE_BATCH_H
#define LENS2POV_TRACE_BATCH_H

#include "optics/lens.h"
#include "optics/trace.h"

/* A multiple of every lane count (trace_lanes_isa.h): a short batch is padded up to the next
   multiple of the lane count in place, never past TRACE_BATCH_MAX. */
enum { TRACE_BATCH_MAX = 64 };

typedef struct trace_batch {
    double ox[TRACE_BATCH_MAX], oy[TRACE_BATCH_MAX], oz[TRACE_BATCH_MAX];
    double dx[TRACE_BATCH_MAX], dy[TRACE_BATCH_MAX], dz[TRACE_BATCH_MAX];
    long long status[TRACE_BATCH_MAX];   /* a trace_status; TRACE_PASSED on entry for the rays
                                          to trace */
} trace_batch;

/* Traces rays 0 .. n-1 (n <= TRACE_BATCH_MAX) through the whole lens toward the scene, with the
   best instruction set this processor has. Unit directions out. */
void trace_batch_toward_scene(const lens *l, trace_batch *b, int n);

/* The same with each ray's wavelength (nm; NULL: the file's indices), every medium's index
   n(lambda) of lens_index_at. Bit for bit what trace_toward_scene_at gives one ray. */
void trace_batch_toward_scene_at(const lens *l, trace_batch *b, int n,
                                 const double *wavelength_nm);

/* The instruction set in use ("avx512", "avx2", "sse2" or "scalar", the one-ray kernel). */
const char *trace_batch_isa(void);

/* Uses the named instruction set from now on (tests and benchmarks; call it before tracing
   starts). Returns -1, changing nothing, when the name is unknown or this processor lacks it. */
int trace_batch_use_isa(const char *name);

#endif
