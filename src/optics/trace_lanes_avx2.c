/* The lane tracer with AVX2: sixteen rays a step as four registers of four. Chosen at run
   time (trace_batch.c); the rest of the program stays baseline x86-64. No FMA: a fused
   multiply-add rounds once where the one-ray kernel rounds twice (and the Makefile builds
   with -ffp-contract=off, so the compiler fuses none either). */
#include "optics/trace_lanes_isa.h"

#if defined(__x86_64__)
#include <float.h>
#include <immintrin.h>
#include <math.h>

#define VECS 4
#define WIDTH 4
typedef __m256d reg;
#define R(op) _mm256_##op##_pd
#define CMP_LT(a, b) _mm256_cmp_pd(a, b, _CMP_LT_OQ)
#define CMP_LE(a, b) _mm256_cmp_pd(a, b, _CMP_LE_OQ)
#define CMP_GT(a, b) _mm256_cmp_pd(a, b, _CMP_GT_OQ)
#define CMP_GE(a, b) _mm256_cmp_pd(a, b, _CMP_GE_OQ)
#define CMP_NE(a, b) _mm256_cmp_pd(a, b, _CMP_NEQ_UQ)
#define INLINE static inline __attribute__((always_inline, target("avx2")))
#include "optics/trace_lanes_x86.h"
#define LANES_ENTRY __attribute__((target("avx2"))) void trace_lanes_avx2
#include "optics/trace_lanes.h"
#endif
