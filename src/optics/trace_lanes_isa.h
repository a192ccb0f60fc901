/* The lane tracers of trace_lanes.h, one per instruction set (x86-64 only); trace_batch.c
   picks one at run time. Each traces rays 0 .. n-1 of b, n a multiple of its lane count, with
   the indices at each ray's 1 / lambda^2 in x (or the file's n_d when x is NULL), and leaves
   the directions of unit length. */
#ifndef LENS2POV_TRACE_LANES_ISA_H
#define LENS2POV_TRACE_LANES_ISA_H

#include "optics/trace_batch.h"

void trace_lanes_sse2(const lens *l, trace_batch *b, int n, const double *x);     /* 8 lanes */
void trace_lanes_avx2(const lens *l, trace_batch *b, int n, const double *x);     /* 16 lanes */
void trace_lanes_avx512(const lens *l, trace_batch *b, int n, const double *x);   /* 32 lanes */

#endif
