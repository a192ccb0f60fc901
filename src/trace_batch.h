/* Full simulation of many rays at once (see trace_batch.c). */
#ifndef LENS2POV_TRACE_BATCH_H
#define LENS2POV_TRACE_BATCH_H

#include "lens.h"
#include "trace.h"

enum { TRACE_SOA_MAX = 64 };

typedef struct trace_soa {
    double ox[TRACE_SOA_MAX], oy[TRACE_SOA_MAX], oz[TRACE_SOA_MAX];
    double dx[TRACE_SOA_MAX], dy[TRACE_SOA_MAX], dz[TRACE_SOA_MAX];
    long long status[TRACE_SOA_MAX];   /* a trace_status, as wide as a double for vector code;
                                          TRACE_PASSED on entry for the rays to trace */
} trace_soa;

/* Traces rays 0 .. n-1 (n <= TRACE_SOA_MAX) through the whole lens toward the scene. */
void trace_soa_toward_scene(const lens *l, trace_soa *b, int n);

#endif
