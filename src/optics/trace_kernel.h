/* The full simulation, written once: intersection, clear aperture and refraction at one
   surface for LANES rays side by side, and the final renormalization. Every tracer is this
   text over other operations: trace_one.h makes it one ray in double (trace.c) or in long
   double (tests/precision_trace.c), trace_lanes.h a batch over vector registers (one file per
   instruction set). The operations round as C does, each once and in the order written here,
   so every build of it gives the same rays bit for bit (tests/test_trace.c).

   There are no branches on a ray's own values: a lane that fails a test goes on computing
   with whatever it holds and is masked out; only a test true of no lane skips work.

   The includer defines:
     LANES           rays side by side (1 for one ray), at most 32
     real            the number type of one lane (double or long double), REAL_MAX its largest
     vreal, vmask    LANES reals and a mask of LANES lanes
     INLINE          the attributes of every function (always inlined; the instruction set)
     add sub mul divide vmax vsqrt splat   arithmetic as C's; vmax(a, b) is a > b ? a : b
     lt le gt ge ne  ordered comparisons (ne unordered, as C's !=), giving a vmask
     mand mor        mask logic;  bits(vmask) -> unsigned, bit i = lane i;  mask_of(unsigned)
     pick(m, a, b)   a where m, else b;  vabs, vcopysign, neg (C's -x, also of 0)
   The status codes and the lens description (trace.h, lens.h) are shared. */

_Static_assert(LANES >= 1 && LANES <= 32, "lane masks are unsigned ints");

INLINE vreal dot(vreal ax, vreal ay, vreal az, vreal bx, vreal by, vreal bz)
{
    return add(add(mul(ax, bx), mul(ay, by)), mul(az, bz));
}

/* In local coordinates (x, y, s = z - vertex_z) a surface of curvature c, whose centre lies at
   s = -1/c, is F = c (x^2 + y^2 + s^2) + 2 s = 0; c = 0 is the plane s = 0. Along p + t d
   (|d| = 1): c t^2 + 2 B t + C = 0 with B = c (p.d) + d_z and C = c |p|^2 + 2 s0.
   Spencer and Murty (JOSA 52, 1962) first carry the ray to the vertex's tangent plane: from an
   origin n radii away B^2 and c C agree to about 1/n^2 and their difference loses log10(n^2)
   digits. Rays from the neighbouring surface lose none worth a division, so the transfer is
   made only from more than TRACE_TRANSFER_RADII radii away (trace.h). Then they take the root
   that tends to the vertex as t = -C / (B + sgn(B) sqrt(B^2 - c C)), which loses no digits as
   c -> 0; the other root is -(B + sgn(B) sqrt(B^2 - c C)) / c. The unit normal is
   (c x, c y, 1 + c s); its z component is positive on the cap that holds the vertex, the only
   part the lens has. */

/* A root t (after the transfer t0) is taken when it lies ahead of the ray, is finite, and
   meets the vertex-side cap. */
INLINE vmask root_ok(vreal t0, vreal t, vreal pz, vreal dz, vreal c)
{
    const vmask ahead = ge(add(t0, t), splat(0));
    const vmask finite = le(vabs(t), splat(REAL_MAX));
    const vmask cap = ge(add(splat(1), mul(c, add(pz, mul(t, dz)))), splat(0));
    return mand(mand(ahead, finite), cap);
}

/* The rays o + t d against surface s: the point h where each meets it, in local coordinates,
   and the mask of the lanes that meet it. */
INLINE vmask intersect(const lens_surface *s, const vreal o[3], const vreal d[3], vreal h[3])
{
    const real cs = s->curvature_per_mm;
    const vreal c = splat(cs), zero = splat(0);
    const vreal pz0 = sub(o[2], splat(s->vertex_z_mm));
    const vmask transfer = mand(gt(vabs(d[2]), splat(1e-6)),
                                gt(vabs(mul(c, pz0)), splat(TRACE_TRANSFER_RADII)));
    vreal t0 = zero, px = o[0], py = o[1], pz = pz0;
    if (bits(transfer)) {
        t0 = pick(transfer, divide(neg(pz0), d[2]), zero);
        px = add(px, mul(t0, d[0]));
        py = add(py, mul(t0, d[1]));
        pz = pick(transfer, zero, pz0);
    }
    const vreal B = add(mul(c, dot(px, py, pz, d[0], d[1], d[2])), d[2]);
    const vreal C = add(mul(c, dot(px, py, pz, px, py, pz)), mul(splat(2), pz));
    const vreal disc = sub(mul(B, B), mul(c, C));
    const vreal q = neg(add(B, vcopysign(vsqrt(vmax(disc, zero)), B)));
    /* q = 0 only for a ray tangent to the surface or lying in the plane: a miss. The far root
       q / c is q R (R exact from the file; it saves a division). */
    const vreal near = pick(ne(q, zero), divide(C, q), splat(NAN));
    const vreal far = mul(q, splat(cs != 0 ? s->radius_mm : NAN));
    const vmask swap = lt(far, near);
    const vreal lo = pick(swap, far, near), hi = pick(swap, near, far);
    /* The first root ahead of the ray on the vertex-side cap. */
    const vmask lo_ok = root_ok(t0, lo, pz, d[2], c), hi_ok = root_ok(t0, hi, pz, d[2], c);
    const vreal t = pick(lo_ok, lo, hi);
    h[0] = add(px, mul(t, d[0]));
    h[1] = add(py, mul(t, d[1]));
    h[2] = add(pz, mul(t, d[2]));
    return mand(ge(disc, zero), mor(lo_ok, hi_ok));
}

/* The normal (c x, c y, 1 + c s) at the point h of surface s, in local coordinates. */
INLINE void normal_at(const lens_surface *s, const vreal h[3], vreal n[3])
{
    const vreal c = splat(s->curvature_per_mm);
    n[0] = mul(c, h[0]);
    n[1] = mul(c, h[1]);
    n[2] = add(splat(1), mul(c, h[2]));
}

/* Refraction of d from index n1 to n2 at the normal n (either orientation), Heckbert's form:
   d' = eta d + (eta cos_i - cos_t) n with eta = n1 / n2. d' goes to e; *tir gets the lanes
   totally reflected, *grazing those within a hair of grazing (TRACE_GRAZING_COS, trace.h).
   d' is a unit vector in exact arithmetic; the rounding it gathers over a lens is removed
   once, at the end of the trace. */
INLINE void refract(const vreal n[3], vreal eta, const vreal d[3], vreal e[3], vmask *tir,
                    vmask *grazing)
{
    const vreal one = splat(1), cos_i0 = neg(dot(n[0], n[1], n[2], d[0], d[1], d[2]));
    /* n oriented against the ray; a product with -1 is exactly C's -x. */
    const vreal flip = pick(lt(cos_i0, splat(0)), splat(-1), one);
    const vreal cos_i = mul(cos_i0, flip);
    const vreal sin2_t = mul(mul(eta, eta), sub(one, mul(cos_i, cos_i)));
    const vreal cos_t = vsqrt(vmax(sub(one, sin2_t), splat(0)));
    const vreal k = sub(mul(eta, cos_i), cos_t), graze = splat(TRACE_GRAZING_COS);
    *tir = gt(sin2_t, one);
    *grazing = mor(lt(cos_i, graze), lt(cos_t, graze));
    e[0] = add(mul(eta, d[0]), mul(k, mul(n[0], flip)));
    e[1] = add(mul(eta, d[1]), mul(k, mul(n[1], flip)));
    e[2] = add(mul(eta, d[2]), mul(k, mul(n[2], flip)));
}

/* The lanes of `alive` that fail get their status, in the order the tests are made: missed,
   clipped, totally reflected, grazing. Returns the lanes still alive. Failures are rare:
   mostly there is no loop at all. */
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

/* Within the blades' polygon, inscribed in the opening of squared radius a2: a point is inside
   when its projection on every edge's outward normal is at most the apothem, R cos(pi / N). */
INLINE vmask within_blades(const lens_blades *b, real a2, vreal x, vreal y)
{
    vreal far = add(mul(x, splat(b->normal_x[0])), mul(y, splat(b->normal_y[0])));
    for (int k = 1; k < b->count; k++)
        far = vmax(far, add(mul(x, splat(b->normal_x[k])), mul(y, splat(b->normal_y[k]))));
    return le(far, splat(sqrt(a2) * b->apothem_ratio));
}

/* The index n = a + b x of a medium (lens_cauchy) for each lane's x = 1 / lambda^2. */
INLINE vreal index_at(real a, real b_nm2, vreal x)
{
    return add(splat(a), mul(splat(b_nm2), x));
}

/* One surface for the rays o, d of the lanes `alive`: the intersection, the clear aperture
   (or the stop's opening) of squared radius a2, and within it the blades' polygon when there
   are blades, then, when it refracts, refraction with each lane's eta = n1 / n2. A ray that
   gets through moves to the surface with its new direction; one that does not stays as it was
   and gets its status. Returns the lanes still alive. */
INLINE unsigned cross(const lens_surface *s, real a2, const lens_blades *blades, bool refracts,
                      vreal eta, vreal o[3], vreal d[3], long long *status, unsigned alive)
{
    vreal h[3], e[3];
    const vmask hit = intersect(s, o, d, h);
    vmask inside = le(add(mul(h[0], h[0]), mul(h[1], h[1])), splat(a2));
    if (blades)
        inside = mand(inside, within_blades(blades, a2, h[0], h[1]));
    unsigned tir = 0, grazing = 0;
    if (refracts) {
        vreal n[3];
        vmask t, g;
        normal_at(s, h, n);
        refract(n, eta, d, e, &t, &g);
        tir = bits(t);
        grazing = bits(g);
    }
    alive = settle(status, alive, bits(hit), bits(inside), tir, grazing);
    const vmask ok = mask_of(alive);
    o[0] = pick(ok, h[0], o[0]);
    o[1] = pick(ok, h[1], o[1]);
    o[2] = pick(ok, add(h[2], splat(s->vertex_z_mm)), o[2]);
    if (refracts) {
        d[0] = pick(ok, e[0], d[0]);
        d[1] = pick(ok, e[1], d[1]);
        d[2] = pick(ok, e[2], d[2]);
    }
    return alive;
}

/* d / sqrt(d.d), as d * (1 / sqrt(d.d)). */
INLINE void renormalize(vreal d[3])
{
    const vreal inv = divide(splat(1), vsqrt(dot(d[0], d[1], d[2], d[0], d[1], d[2])));
    d[0] = mul(d[0], inv);
    d[1] = mul(d[1], inv);
    d[2] = mul(d[2], inv);
}
