/* The lane tracers of trace_lanes.h, one per instruction set (x86-64 only); trace_batch.c
   picks one at run time. Each traces rays 0 .. n-1 of b, n a multiple of its lane count, and
   leaves the directions of unit length. */
#ifndef LENS2POV_TRACE_LANES_ISA_H
#define LENS2POV_TRACE_LANES_ISA_H

#include "optics/trace_batch.h"

void trace_lanes_sse2(const lens *l, trace_batch *b, int n);     /* 8 lanes */
void trace_lanes_avx2(const lens *l, trace_batch *b, int n);     /* 16 lanes */
void trace_lanes_avx512(const lens *l, trace_batch *b, int n);   /* 32 lanes */

#endif
