/* The lane tracer with SSE2, part of every x86-64: eight rays a step as four pairs, so that
   four chains of divisions and square roots interleave. */
#include "optics/trace_lanes_isa.h"

#if defined(__x86_64__)
#include <float.h>
#include <immintrin.h>
#include <math.h>

#define VECS 4
#define WIDTH 2
typedef __m128d reg;
#define R(op) _mm_##op##_pd
#define CMP_LT _mm_cmplt_pd
#define CMP_LE _mm_cmple_pd
#define CMP_GT _mm_cmpgt_pd
#define CMP_GE _mm_cmpge_pd
#define CMP_NE _mm_cmpneq_pd
#define INLINE static inline __attribute__((always_inline))
#include "optics/trace_lanes_x86.h"
#define LANES_ENTRY void trace_lanes_sse2
#include "optics/trace_lanes.h"
#endif
