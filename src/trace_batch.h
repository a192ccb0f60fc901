/* Full simulation of many rays at once (see trace_batch.c). */
#ifndef LENS2POV_TRACE_BATCH_H
#define LENS2POV_TRACE_BATCH_H

#include "lens.h"
#include "trace.h"

enum { TRACE_SOA_MAX = 64 };

/* Room past TRACE_SOA_MAX: a count that is not a multiple of the vector width is padded. */

typedef struct trace_soa {
    double ox[TRACE_SOA_MAX + 8], oy[TRACE_SOA_MAX + 8], oz[TRACE_SOA_MAX + 8];
    double dx[TRACE_SOA_MAX + 8], dy[TRACE_SOA_MAX + 8], dz[TRACE_SOA_MAX + 8];
    long long status[TRACE_SOA_MAX + 8];   /* a trace_status, as wide as a double for vector code;
                                          TRACE_PASSED on entry for the rays to trace */
} trace_soa;

/* Traces rays 0 .. n-1 (n <= TRACE_SOA_MAX) through the whole lens toward the scene. */
void trace_soa_toward_scene(const lens *l, trace_soa *b, int n);

#endif
