/* The full simulation for many rays at once, in structure-of-arrays form: one ray's work is a
   long chain of divisions and square roots, and only independent rays side by side keep the
   processor busy. Same formulas, in the same order, as trace_kernel.h (tests/test_trace.c
   checks that the two agree bit for bit). */
#include "trace_batch.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* The same threshold as trace_kernel.h. */
#define TRANSFER_RADII 4

/* Eight rays a step as four SSE2 pairs (SSE2 is part of every x86-64). Each helper below
   issues one instruction per pair, so the four pairs' chains of divisions and square roots
   interleave and the processor overlaps them: one ray at a time, a surface is a chain of
   some 200 cycles. The operations and their order are those of trace_kernel.h, so the
   results agree bit for bit. */
#if defined(__SSE2__)
#include <emmintrin.h>
#define PAIRS 4
#define LANES (2 * PAIRS)
typedef struct vd { __m128d p[PAIRS]; } vd;

#define UNROLL _Pragma("GCC unroll 4")
#define INLINE static inline __attribute__((always_inline))
#define BINARY(name, op)                                                                  \
    INLINE vd name(vd a, vd b)                                                            \
    {                                                                                     \
        vd r;                                                                             \
        UNROLL for (int i = 0; i < PAIRS; i++) r.p[i] = op(a.p[i], b.p[i]);               \
        return r;                                                                         \
    }
BINARY(add, _mm_add_pd)
BINARY(sub, _mm_sub_pd)
BINARY(mul, _mm_mul_pd)
BINARY(dvd, _mm_div_pd)
BINARY(and, _mm_and_pd)
BINARY(or, _mm_or_pd)
BINARY(andnot, _mm_andnot_pd)
BINARY(lt, _mm_cmplt_pd)
BINARY(le, _mm_cmple_pd)
BINARY(gt, _mm_cmpgt_pd)
BINARY(ge, _mm_cmpge_pd)
BINARY(ne, _mm_cmpneq_pd)
BINARY(vmax, _mm_max_pd)

INLINE vd splat(double x)
{
    vd r;
    UNROLL for (int i = 0; i < PAIRS; i++) r.p[i] = _mm_set1_pd(x);
    return r;
}

INLINE vd vsqrt(vd a)
{
    vd r;
    UNROLL for (int i = 0; i < PAIRS; i++) r.p[i] = _mm_sqrt_pd(a.p[i]);
    return r;
}

INLINE vd load(const double *x)
{
    vd r;
    UNROLL for (int i = 0; i < PAIRS; i++) r.p[i] = _mm_loadu_pd(x + 2 * i);
    return r;
}

INLINE void store(double *x, vd v)
{
    UNROLL for (int i = 0; i < PAIRS; i++) _mm_storeu_pd(x + 2 * i, v.p[i]);
}

INLINE int bits(vd mask)
{
    int r = 0;
    UNROLL for (int i = 0; i < PAIRS; i++) r |= _mm_movemask_pd(mask.p[i]) << (2 * i);
    return r;
}

INLINE vd pick(vd mask, vd a, vd b) { return or(and(mask, a), andnot(mask, b)); }
INLINE vd neg(vd x) { return sub(splat(0), x); }
INLINE vd vabs(vd x) { return andnot(splat(-0.0), x); }
INLINE vd vcopysign(vd x, vd y) { return or(andnot(splat(-0.0), x), and(splat(-0.0), y)); }
INLINE vd dot(vd ax, vd ay, vd az, vd bx, vd by, vd bz)
{
    return add(add(mul(ax, bx), mul(ay, by)), mul(az, bz));
}

INLINE vd root_ok(vd t0, vd t, vd pz, vd dz, vd c)
{
    const vd ahead = ge(add(t0, t), splat(0));
    const vd finite = le(vabs(t), splat(DBL_MAX));
    const vd cap = ge(add(splat(1), mul(c, add(pz, mul(t, dz)))), splat(0));
    return and(and(ahead, finite), cap);
}

/* Status per lane: missed, clipped, totally reflected, grazing, or still passing; returns the
   mask of lanes still passing. */
INLINE vd update_status(long long *status, int hit, int inside, int tir, int grazing)
{
    double ok[LANES];
    for (int i = 0; i < LANES; i++) {
        if (status[i] == TRACE_PASSED)
            status[i] = !(hit >> i & 1) ? TRACE_MISSED : !(inside >> i & 1) ? TRACE_CLIPPED
                      : (tir >> i & 1) ? TRACE_TIR : (grazing >> i & 1) ? TRACE_GRAZING
                      : TRACE_PASSED;
        const long long m = status[i] == TRACE_PASSED ? -1 : 0;
        memcpy(&ok[i], &m, sizeof m);
    }
    return load(ok);
}

/* The intersection: the point h on the vertex-side cap and whether there is one. */
INLINE vd intersect(const lens_surface *s, const vd o[3], const vd d[3], vd h[3])
{
    const double cs = s->curvature_per_mm;
    const vd c = splat(cs), zero = splat(0);
    const vd pz0 = sub(o[2], splat(s->vertex_z_mm));
    const vd transfer = and(gt(vabs(d[2]), splat(1e-6)), gt(vabs(mul(c, pz0)), splat(TRANSFER_RADII)));
    vd t0 = zero, px = o[0], py = o[1], pz = pz0;
    if (bits(transfer)) {
        t0 = pick(transfer, dvd(neg(pz0), d[2]), zero);
        px = add(px, mul(t0, d[0]));
        py = add(py, mul(t0, d[1]));
        pz = pick(transfer, zero, pz0);
    }
    const vd B = add(mul(c, dot(px, py, pz, d[0], d[1], d[2])), d[2]);
    const vd C = add(mul(c, dot(px, py, pz, px, py, pz)), mul(splat(2), pz));
    const vd disc = sub(mul(B, B), mul(c, C));
    const vd q = neg(add(B, vcopysign(vsqrt(vmax(disc, zero)), B)));
    const vd near = pick(ne(q, zero), dvd(C, q), splat(NAN));
    const vd far = mul(q, splat(cs != 0 ? s->radius_mm : NAN));
    const vd swap = lt(far, near);
    const vd lo = pick(swap, far, near), hi = pick(swap, near, far);
    const vd lo_ok = root_ok(t0, lo, pz, d[2], c), hi_ok = root_ok(t0, hi, pz, d[2], c);
    const vd t = pick(lo_ok, lo, hi);
    h[0] = add(px, mul(t, d[0]));
    h[1] = add(py, mul(t, d[1]));
    h[2] = add(pz, mul(t, d[2]));
    return and(ge(disc, zero), or(lo_ok, hi_ok));
}

static void cross_lanes(const lens_surface *s, double a2, double eta_s, double *o_at[3],
                        double *d_at[3], long long *status)
{
    const vd c = splat(s->curvature_per_mm), eta = splat(eta_s), one = splat(1);
    vd o[3], d[3], h[3];
    for (int j = 0; j < 3; j++) {
        o[j] = load(o_at[j]);
        d[j] = load(d_at[j]);
    }
    const vd hit = intersect(s, o, d, h);
    /* Refraction at the normal (c hx, c hy, 1 + c hz), oriented against the ray. */
    const vd nx0 = mul(c, h[0]), ny0 = mul(c, h[1]), nz0 = add(one, mul(c, h[2]));
    const vd cos_i0 = neg(dot(nx0, ny0, nz0, d[0], d[1], d[2]));
    const vd flip = pick(lt(cos_i0, splat(0)), splat(-1), one);
    const vd nx = mul(nx0, flip), ny = mul(ny0, flip), nz = mul(nz0, flip), cos_i = mul(cos_i0, flip);
    const vd sin2_t = mul(mul(eta, eta), sub(one, mul(cos_i, cos_i)));
    const vd cos_t = vsqrt(vmax(sub(one, sin2_t), splat(0)));
    const vd kk = sub(mul(eta, cos_i), cos_t);
    const vd graze = splat(TRACE_GRAZING_COS);
    const int refracts = eta_s != 1;
    const vd ok = update_status(status, bits(hit), bits(le(add(mul(h[0], h[0]), mul(h[1], h[1])), splat(a2))),
                                refracts ? bits(gt(sin2_t, one)) : 0,
                                refracts ? bits(or(lt(cos_i, graze), lt(cos_t, graze))) : 0);
    store(o_at[0], pick(ok, h[0], o[0]));
    store(o_at[1], pick(ok, h[1], o[1]));
    store(o_at[2], pick(ok, add(h[2], splat(s->vertex_z_mm)), o[2]));
    if (refracts) {
        store(d_at[0], pick(ok, add(mul(eta, d[0]), mul(kk, nx)), d[0]));
        store(d_at[1], pick(ok, add(mul(eta, d[1]), mul(kk, ny)), d[1]));
        store(d_at[2], pick(ok, add(mul(eta, d[2]), mul(kk, nz)), d[2]));
    }
}

static void cross_surface(const lens *l, int i, double eta, trace_soa *b, int n)
{
    const double a = lens_semi_aperture_mm(l, i);
    for (int k = 0; k < n; k += LANES) {
        double *o[3] = {b->ox + k, b->oy + k, b->oz + k}, *d[3] = {b->dx + k, b->dy + k, b->dz + k};
        cross_lanes(&l->surface[i], a * a, eta, o, d, b->status + k);
    }
}
#endif

void trace_soa_toward_scene(const lens *l, trace_soa *b, int n)
{
#if defined(__SSE2__)
    for (int k = n; k % LANES; k++) {   /* dead, finite rays pad the last step */
        b->ox[k] = b->oy[k] = b->oz[k] = b->dx[k] = b->dy[k] = 0;
        b->dz[k] = 1;
        b->status[k] = TRACE_MISSED;
    }
    for (int i = l->count - 1; i >= 0; i--)
        cross_surface(l, i, lens_ior_behind(l, i) / lens_ior_front(l, i), b, n);
    for (int k = 0; k < n; k++) {
        const double inv = 1 / sqrt(b->dx[k] * b->dx[k] + b->dy[k] * b->dy[k] + b->dz[k] * b->dz[k]);
        b->dx[k] *= inv;
        b->dy[k] *= inv;
        b->dz[k] *= inv;
    }
#else
    /* Elsewhere, the one-ray kernel, one ray after the other. */
    for (int k = 0; k < n; k++) {
        if (b->status[k] != TRACE_PASSED)
            continue;
        ray r = {v3(b->ox[k], b->oy[k], b->oz[k]), v3(b->dx[k], b->dy[k], b->dz[k])};
        b->status[k] = trace_toward_scene(l, 0, l->count - 1, &r, NULL);
        b->ox[k] = r.o.x; b->oy[k] = r.o.y; b->oz[k] = r.o.z;
        b->dx[k] = r.d.x; b->dy[k] = r.d.y; b->dz[k] = r.d.z;
    }
#endif
}
