/* The full simulation over lanes of rays side by side: the text of trace_kernel.h, operation
   for operation and in the same order, written over vectors so that the results agree bit for
   bit (tests/test_trace.c). One ray alone is a chain of divisions and square roots of some
   200 cycles a surface; independent rays side by side keep the processor busy.

   The includer (one file per instruction set) defines:
     LANES           rays a step, a divisor of TRACE_SOA_MAX
     vd, vm          a vector of LANES doubles and a mask of LANES lanes
     INLINE          the attributes of every helper (always inlined, the instruction set)
     add sub mul dvd vmax vsqrt splat load store          vd arithmetic, memory
     lt le gt ge ne  ordered comparisons (ne unordered, as C's !=), giving a vm
     mand mor        mask logic;  bits(vm) -> unsigned, bit i = lane i;  mask_of(unsigned) -> vm
     pick(m, a, b)   a where m, else b;  vabs, vcopysign, neg
   and names the entry point with LANES_ENTRY. */

_Static_assert(TRACE_SOA_MAX % LANES == 0 && LANES <= 32,
               "lane masks are unsigned ints, and a batch is whole steps");

INLINE vd dot(vd ax, vd ay, vd az, vd bx, vd by, vd bz)
{
    return add(add(mul(ax, bx), mul(ay, by)), mul(az, bz));
}

INLINE vm root_ok(vd t0, vd t, vd pz, vd dz, vd c)
{
    const vm ahead = ge(add(t0, t), splat(0));
    const vm finite = le(vabs(t), splat(DBL_MAX));
    const vm cap = ge(add(splat(1), mul(c, add(pz, mul(t, dz)))), splat(0));
    return mand(mand(ahead, finite), cap);
}

/* The intersection (trace_kernel.h's intersect): the point h on the vertex-side cap and the
   mask of lanes that have one. */
INLINE vm intersect(const lens_surface *s, const vd o[3], const vd d[3], vd h[3])
{
    const double cs = s->curvature_per_mm;
    const vd c = splat(cs), zero = splat(0);
    const vd pz0 = sub(o[2], splat(s->vertex_z_mm));
    const vm transfer = mand(gt(vabs(d[2]), splat(1e-6)),
                             gt(vabs(mul(c, pz0)), splat(TRACE_TRANSFER_RADII)));
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
    const vm swap = lt(far, near);
    const vd lo = pick(swap, far, near), hi = pick(swap, near, far);
    const vm lo_ok = root_ok(t0, lo, pz, d[2], c), hi_ok = root_ok(t0, hi, pz, d[2], c);
    const vd t = pick(lo_ok, lo, hi);
    h[0] = add(px, mul(t, d[0]));
    h[1] = add(py, mul(t, d[1]));
    h[2] = add(pz, mul(t, d[2]));
    return mand(ge(disc, zero), mor(lo_ok, hi_ok));
}

/* The lanes of `alive` that fail at this surface get their status (in the kernel's order of
   tests); returns the lanes still alive. Failures are rare: mostly there is no loop at all. */
INLINE unsigned settle(long long *status, unsigned alive, unsigned hit, unsigned inside,
                       unsigned tir, unsigned grazing)
{
    const unsigned failed = alive & ~(hit & inside & ~tir & ~grazing);
    if (!failed)
        return alive;
    for (int i = 0; i < LANES; i++)
        if (failed >> i & 1)
            status[i] = !(hit >> i & 1) ? TRACE_MISSED : !(inside >> i & 1) ? TRACE_CLIPPED
                      : (tir >> i & 1) ? TRACE_TIR : TRACE_GRAZING;
    return alive & ~failed;
}

/* One surface for the LANES rays at o_at, d_at; returns the lanes still alive. */
INLINE unsigned cross_lanes(const lens_surface *s, double a2, double eta_s, double *o_at[3],
                       double *d_at[3], long long *status, unsigned alive)
{
    const vd c = splat(s->curvature_per_mm), eta = splat(eta_s), one = splat(1);
    vd o[3], d[3], h[3];
    for (int j = 0; j < 3; j++) {
        o[j] = load(o_at[j]);
        d[j] = load(d_at[j]);
    }
    const vm hit = intersect(s, o, d, h);
    /* Refraction at the normal (c hx, c hy, 1 + c hz), oriented against the ray. */
    const vd nx0 = mul(c, h[0]), ny0 = mul(c, h[1]), nz0 = add(one, mul(c, h[2]));
    const vd cos_i0 = neg(dot(nx0, ny0, nz0, d[0], d[1], d[2]));
    const vd flip = pick(lt(cos_i0, splat(0)), splat(-1), one);
    const vd nx = mul(nx0, flip), ny = mul(ny0, flip), nz = mul(nz0, flip), cos_i = mul(cos_i0, flip);
    const vd sin2_t = mul(mul(eta, eta), sub(one, mul(cos_i, cos_i)));
    const vd cos_t = vsqrt(vmax(sub(one, sin2_t), splat(0)));
    const vd kk = sub(mul(eta, cos_i), cos_t);
    const vd graze = splat(TRACE_GRAZING_COS);
    const bool refracts = eta_s != 1;
    alive = settle(status, alive, bits(hit), bits(le(add(mul(h[0], h[0]), mul(h[1], h[1])), splat(a2))),
                   refracts ? bits(gt(sin2_t, one)) : 0,
                   refracts ? bits(mor(lt(cos_i, graze), lt(cos_t, graze))) : 0);
    const vm ok = mask_of(alive);
    store(o_at[0], pick(ok, h[0], o[0]));
    store(o_at[1], pick(ok, h[1], o[1]));
    store(o_at[2], pick(ok, add(h[2], splat(s->vertex_z_mm)), o[2]));
    if (refracts) {
        store(d_at[0], pick(ok, add(mul(eta, d[0]), mul(kk, nx)), d[0]));
        store(d_at[1], pick(ok, add(mul(eta, d[1]), mul(kk, ny)), d[1]));
        store(d_at[2], pick(ok, add(mul(eta, d[2]), mul(kk, nz)), d[2]));
    }
    return alive;
}

/* The kernel's renormalize: d / sqrt(d.d), as d * (1 / sqrt(d.d)). */
INLINE void renormalize_lanes(double *dx, double *dy, double *dz)
{
    const vd x = load(dx), y = load(dy), z = load(dz);
    const vd inv = dvd(splat(1), vsqrt(add(add(mul(x, x), mul(y, y)), mul(z, z))));
    store(dx, mul(x, inv));
    store(dy, mul(y, inv));
    store(dz, mul(z, inv));
}

/* Rays 0 .. n-1 of b, n a multiple of LANES, surfaces last .. first. The surface loop is the
   outer one: the steps of one surface are independent and the processor overlaps them. */
LANES_ENTRY(const lens *l, trace_soa *b, int n)
{
    unsigned alive[TRACE_SOA_MAX / LANES];
    for (int g = 0; g < n / LANES; g++) {
        alive[g] = 0;
        for (int i = 0; i < LANES; i++)
            alive[g] |= (unsigned)(b->status[g * LANES + i] == TRACE_PASSED) << i;
    }
    for (int i = l->count - 1; i >= 0; i--) {
        const double a = lens_semi_aperture_mm(l, i);
        const double eta = lens_ior_behind(l, i) / lens_ior_front(l, i);
        for (int g = 0; g < n / LANES; g++) {
            if (!alive[g])
                continue;
            const int k = g * LANES;
            double *o[3] = {b->ox + k, b->oy + k, b->oz + k}, *d[3] = {b->dx + k, b->dy + k, b->dz + k};
            alive[g] = cross_lanes(&l->surface[i], a * a, eta, o, d, b->status + k, alive[g]);
        }
    }
    for (int k = 0; k < n; k += LANES)
        renormalize_lanes(b->dx + k, b->dy + k, b->dz + k);
}
