/* The operations of trace_kernel.h for SSE2 and AVX: VECS registers of WIDTH doubles,
   masks kept as all-ones or all-zero doubles. The includer defines
     VECS, WIDTH, reg    register count, doubles a register, the register type
     R(op)               the intrinsic _mm_<op>_pd or _mm256_<op>_pd
     CMP_LT .. CMP_NE    the comparisons (ordered, but for != as in C), mask results
     INLINE              always inline, with the instruction set's target attribute */
#include <stdint.h>

#define LANES (VECS * WIDTH)
typedef struct vreal { reg p[VECS]; } vreal;
typedef vreal vmask;

#define UNROLL _Pragma("GCC unroll 4")
#define BINARY(name, expr)                                                                \
    INLINE vreal name(vreal a, vreal b)                                                            \
    {                                                                                     \
        vreal r;                                                                             \
        UNROLL for (int i = 0; i < VECS; i++) r.p[i] = expr(a.p[i], b.p[i]);              \
        return r;                                                                         \
    }
BINARY(add, R(add))
BINARY(sub, R(sub))
BINARY(mul, R(mul))
BINARY(divide, R(div))
BINARY(vand, R(and))
BINARY(vor, R(or))
BINARY(vandnot, R(andnot))
BINARY(vxor, R(xor))
BINARY(vmax, R(max))
BINARY(lt, CMP_LT)
BINARY(le, CMP_LE)
BINARY(gt, CMP_GT)
BINARY(ge, CMP_GE)
BINARY(ne, CMP_NE)

INLINE vreal splat(double x)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = R(set1)(x);
    return r;
}

INLINE vreal vsqrt(vreal a)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = R(sqrt)(a.p[i]);
    return r;
}

INLINE vreal load(const double *x)
{
    vreal r;
    UNROLL for (int i = 0; i < VECS; i++) r.p[i] = R(loadu)(x + WIDTH * i);
    return r;
}

INLINE void store(double *x, vreal v)
{
    UNROLL for (int i = 0; i < VECS; i++) R(storeu)(x + WIDTH * i, v.p[i]);
}

INLINE unsigned bits(vmask m)
{
    unsigned r = 0;
    UNROLL for (int i = 0; i < VECS; i++) r |= (unsigned)R(movemask)(m.p[i]) << (WIDTH * i);
    return r;
}

/* Row m: lane j all ones when bit j of m is set. */
static const uint64_t lane_masks[1 << WIDTH][WIDTH] __attribute__((aligned(32))) = {
#if WIDTH == 2
    {0, 0}, {~0ull, 0}, {0, ~0ull}, {~0ull, ~0ull}
#else
    {0, 0, 0, 0}, {~0ull, 0, 0, 0}, {0, ~0ull, 0, 0}, {~0ull, ~0ull, 0, 0},
    {0, 0, ~0ull, 0}, {~0ull, 0, ~0ull, 0}, {0, ~0ull, ~0ull, 0}, {~0ull, ~0ull, ~0ull, 0},
    {0, 0, 0, ~0ull}, {~0ull, 0, 0, ~0ull}, {0, ~0ull, 0, ~0ull}, {~0ull, ~0ull, 0, ~0ull},
    {0, 0, ~0ull, ~0ull}, {~0ull, 0, ~0ull, ~0ull}, {0, ~0ull, ~0ull, ~0ull}, {~0ull, ~0ull, ~0ull, ~0ull}
#endif
};

INLINE vmask mask_of(unsigned lanes)
{
    vmask r;
    UNROLL for (int i = 0; i < VECS; i++)
        r.p[i] = R(load)((const double *)lane_masks[lanes >> (WIDTH * i) & ((1 << WIDTH) - 1)]);
    return r;
}

INLINE vmask mand(vmask a, vmask b) { return vand(a, b); }
INLINE vmask mor(vmask a, vmask b) { return vor(a, b); }
INLINE vreal pick(vmask m, vreal a, vreal b) { return vor(vand(m, a), vandnot(m, b)); }
INLINE vreal neg(vreal x) { return vxor(x, splat(-0.0)); }   /* C's -x: flips the sign, also of 0 */
INLINE vreal vabs(vreal x) { return vandnot(splat(-0.0), x); }
INLINE vreal vcopysign(vreal x, vreal y) { return vor(vandnot(splat(-0.0), x), vand(splat(-0.0), y)); }
