/* The lane tracer with AVX-512F: 32 rays a step as four registers of eight (two registers
   leave the square roots' latency exposed), masks in mask registers: the operations of
   trace_kernel.h, then the driver of trace_lanes.h. Chosen at run
   time (trace_batch.c); no FMA, as in trace_lanes_avx2.c. */
#include "optics/trace_lanes_isa.h"

#if defined(__x86_64__)
#include <float.h>
#include <immintrin.h>
#include <math.h>

#define VECS 4
#define WIDTH 8
#define LANES (VECS * WIDTH)
#define INLINE static inline __attribute__((always_inline, target("avx512f")))
#define UNROLL _Pragma("GCC unroll 4")
typedef struct vreal { __m512d p[VECS]; } vreal;
typedef struct vmask { __mmask8 k[VECS]; } vmask;

#define MAP2(name, result, type, expr)                                                    \
    INLINE result name(type a, type b)                                                    \
    {                                                                                     \
        result r;                                                                         \
        UNROLL for (int i = 0; i < VECS; i++) expr;                                       \
        return r;                                                                         \
    }
MAP2(add, vreal, vreal, r.p[i] = _mm512_add_pd(a.p[i], b.p[i]))
MAP2(sub, vreal, vreal, r.p[i] = _mm512_sub_pd(a.p[i], b.p[i]))
MAP2(mul, vreal, vreal, r.p[i] = _mm512_mul_pd(a.p[i], b.p[i]))
MAP2(divide, vreal, vreal, r.p[i] = _mm512_div_pd(a.p[i], b.p[i]))
MAP2(vmax, vreal, vreal, r.p[i] = _mm512_max_pd(a.p[i], b.p[i]))
MAP2(lt, vmask, vreal, r.k[i] = _mm512_cmp_pd_mask(a.p[i], b.p[i], _CMP_LT_OQ))
MAP2(le, vmask, vreal, r.k[i] = _mm512_cmp_pd_mask(a.p[i], b.p[i], _CMP_LE_OQ))
MAP2(gt, vmask, vreal, r.k[i] = _mm512_cmp_pd_mask(a.p[i], b.p[i], _CMP_GT_OQ))
MAP2(ge, vmask, vreal, r.k[i] = _mm512_cmp_pd_mask(a.p[i], b.p[i], _CMP_GE_OQ))
MAP2(ne, vmask, vreal, r.k[i] = _mm512_cmp_pd_mask(a.p[i], b.p[i], _CMP_NEQ_UQ))
MAP2(mand, vmask, vmask, r.k[i] = a.k[i] & b.k[i])
MAP2(mor, vmask, vmask, r.k[i] = a.k[i] | b.k[i])

INLINE vreal splat(double x)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = _mm512_set1_pd(x);
    return r;
}

INLINE vreal vsqrt(vreal a)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = _mm512_sqrt_pd(a.p[i]);
    return r;
}

INLINE vreal load(const double *x)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = _mm512_loadu_pd(x + WIDTH * i);
    return r;
}

INLINE void store(double *x, vreal v)
{
    UNROLL for (int i = 0; i < VECS; i++) _mm512_storeu_pd(x + WIDTH * i, v.p[i]);
}

INLINE unsigned bits(vmask m)
{
    unsigned r = 0;
    UNROLL for (int i = 0; i < VECS; i++) r |= (unsigned)m.k[i] << (WIDTH * i);
    return r;
}

INLINE vmask mask_of(unsigned lanes)
{
    vmask r;
    UNROLL for (int i = 0; i < VECS; i++) r.k[i] = (__mmask8)(lanes >> (WIDTH * i));
    return r;
}

INLINE vreal pick(vmask m, vreal a, vreal b)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = _mm512_mask_blend_pd(m.k[i], b.p[i], a.p[i]);
    return r;
}

INLINE vreal vabs(vreal x)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = _mm512_abs_pd(x.p[i]);
    return r;
}

/* Sign-bit logic on the integer view: AVX-512F has no and/or of doubles (that is AVX-512DQ). */
INLINE vreal vcopysign(vreal x, vreal y)
{
    const __m512i sign = _mm512_set1_epi64((long long)0x8000000000000000ull);
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++)
        r.p[i] = _mm512_castsi512_pd(_mm512_or_si512(
            _mm512_andnot_si512(sign, _mm512_castpd_si512(x.p[i])),
            _mm512_and_si512(sign, _mm512_castpd_si512(y.p[i]))));
    return r;
}

/* C's -x: flips the sign bit, also of 0 (0 - x would give +0 for +0). */
INLINE vreal neg(vreal x)
{
    const __m512i sign = _mm512_set1_epi64((long long)0x8000000000000000ull);
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++)
        r.p[i] = _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(x.p[i]), sign));
    return r;
}

#define LANES_ENTRY __attribute__((target("avx512f"))) void trace_lanes_avx512
#include "optics/trace_lanes.h"
#endif
