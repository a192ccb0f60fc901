/* The full-simulation kernel, written once over a number type so that the same text builds the
   double-precision tracer (trace.c) and a long double reference (tests/precision_trace.c).
   The includer defines:
     KREAL        the number type
     KVEC, KRAY   struct types {KREAL x, y, z;} and {KVEC o, d;}
     KNAME(f)     the name of function f in this build
   <tgmath.h> picks sqrt, fabs, copysign, isfinite of the right precision. Status codes and
   the lens description (lens.h, trace_status) are shared. */
#include <tgmath.h>

static inline KREAL KNAME(dot)(KVEC a, KVEC b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static inline KVEC KNAME(madd)(KVEC a, KVEC b, KREAL s)
{
    KVEC v = {a.x + b.x * s, a.y + b.y * s, a.z + b.z * s};
    return v;
}

/* In local coordinates (x, y, s = z - vertex_z) a surface of curvature c, whose centre lies at
   s = -1/c, is F = c (x^2 + y^2 + s^2) + 2 s = 0; c = 0 is the plane s = 0. Along p + t d
   (|d| = 1): c t^2 + 2 B t + C = 0 with B = c (p.d) + d_z and C = c |p|^2 + 2 s0.
   Spencer and Murty (JOSA 52, 1962) first carry the ray to the vertex's tangent plane: from an
   origin n radii away B^2 and c C agree to about 1/n^2 and their difference loses log10(n^2)
   digits. Rays from the neighbouring surface lose none worth a division, so the transfer is
   made only from more than TRACE_TRANSFER_RADII radii away. Then they take the root that tends
   to the vertex as t = -C / (B + sgn(B) sqrt(B^2 - c C)), which loses no digits as c -> 0;
   the other root is -(B + sgn(B) sqrt(B^2 - c C)) / c. The unit normal is (c x, c y, 1 + c s);
   its z component is positive on the cap that holds the vertex, the only part the lens has. */
/* TRACE_TRANSFER_RADII (trace.h): beyond it a ray is carried to the vertex plane first. */

static inline int KNAME(needs_transfer)(KREAL c, KREAL pz, KREAL dz)
{
    return fabs(dz) > (KREAL)1e-6 && fabs(c * pz) > TRACE_TRANSFER_RADII;
}

static inline __attribute__((always_inline)) trace_status KNAME(intersect)(const lens_surface *s, KRAY *r, KVEC *normal)
{
    const KREAL c = s->curvature_per_mm;
    const KVEC d = r->d;
    KVEC p = {r->o.x, r->o.y, r->o.z - (KREAL)s->vertex_z_mm};
    KREAL t0 = 0;
    if (KNAME(needs_transfer)(c, p.z, d.z)) {
        t0 = -p.z / d.z;
        p.x += t0 * d.x;
        p.y += t0 * d.y;
        p.z = 0;
    }
    const KREAL B = c * KNAME(dot)(p, d) + d.z;
    const KREAL C = c * KNAME(dot)(p, p) + 2 * p.z;
    const KREAL disc = B * B - c * C;
    if (!(disc >= 0))
        return TRACE_MISSED;
    const KREAL q = -(B + copysign(sqrt(disc), B));
    /* q = 0 only for a ray tangent to the surface or lying in the plane: a miss. The far root
       q / c is q R (R exact from the file; it saves a division). */
    KREAL near = q != 0 ? C / q : (KREAL)NAN, far = c != 0 ? q * (KREAL)s->radius_mm : (KREAL)NAN;
    if (far < near) {
        const KREAL t = near;
        near = far;
        far = t;
    }
    /* The first root ahead of the ray on the vertex-side cap. */
    KREAL t = near;
    KVEC h = KNAME(madd)(p, d, t);
    if (!(t0 + t >= 0) || !isfinite(t) || !(1 + c * h.z >= 0)) {
        t = far;
        h = KNAME(madd)(p, d, t);
        if (!(t0 + t >= 0) || !isfinite(t) || !(1 + c * h.z >= 0))
            return TRACE_MISSED;
    }
    r->o.x = h.x;
    r->o.y = h.y;
    r->o.z = h.z + (KREAL)s->vertex_z_mm;
    normal->x = c * h.x;
    normal->y = c * h.y;
    normal->z = 1 + c * h.z;
    return TRACE_PASSED;
}

/* Refraction from index n1 to n2 at unit normal n (either orientation), Heckbert's form:
   d' = eta d + (eta cos_i - cos_t) n with eta = n1 / n2. d' is a unit vector in exact
   arithmetic; the rounding it gathers over a lens is removed once, at the end of the trace. */
static inline __attribute__((always_inline)) trace_status KNAME(refract_eta)(KVEC n, KREAL eta, KVEC *d)
{
    if (eta == 1)
        return TRACE_PASSED;
    KREAL cos_i = -KNAME(dot)(n, *d);
    if (cos_i < 0) {               /* orient n against the ray */
        n.x = -n.x;
        n.y = -n.y;
        n.z = -n.z;
        cos_i = -cos_i;
    }
    const KREAL sin2_t = eta * eta * (1 - cos_i * cos_i);
    if (sin2_t > 1)
        return TRACE_TIR;
    const KREAL cos_t = sqrt(1 - sin2_t);
    if (cos_i < (KREAL)TRACE_GRAZING_COS || cos_t < (KREAL)TRACE_GRAZING_COS)
        return TRACE_GRAZING;
    const KREAL k = eta * cos_i - cos_t;
    d->x = eta * d->x + k * n.x;
    d->y = eta * d->y + k * n.y;
    d->z = eta * d->z + k * n.z;
    return TRACE_PASSED;
}

static trace_status KNAME(refract)(KVEC n, KREAL n1, KREAL n2, KVEC *d)
{
    return KNAME(refract_eta)(n, n1 / n2, d);
}

/* One surface: intersection, clear aperture (or the stop's opening), refraction with
   eta = n1 / n2. */
static inline __attribute__((always_inline)) trace_status KNAME(cross)(const lens *l, int i, KREAL eta, KRAY *r)
{
    KVEC n;
    trace_status st = KNAME(intersect)(&l->surface[i], r, &n);
    if (st != TRACE_PASSED)
        return st;
    const KREAL a = lens_semi_aperture_mm(l, i);
    if (!(r->o.x * r->o.x + r->o.y * r->o.y <= a * a))
        return TRACE_CLIPPED;
    return KNAME(refract_eta)(n, eta, &r->d);
}

static void KNAME(renormalize)(KVEC *d)
{
    const KREAL inv = 1 / sqrt(KNAME(dot)(*d, *d));
    d->x *= inv;
    d->y *= inv;
    d->z *= inv;
}

/* Surfaces last .. first toward the scene (+z), or first .. last toward the film. */
static trace_status KNAME(through)(const lens *l, int first, int last, bool toward_scene,
                                   KRAY *r, int *blocked_at)
{
    const int step = toward_scene ? -1 : 1;
    for (int i = toward_scene ? last : first; i >= first && i <= last; i += step) {
        const KREAL front = lens_ior_front(l, i), behind = lens_ior_behind(l, i);
        trace_status st = KNAME(cross)(l, i, toward_scene ? behind / front : front / behind, r);
        if (st != TRACE_PASSED) {
            if (blocked_at)
                *blocked_at = i;
            return st;
        }
    }
    KNAME(renormalize)(&r->d);
    return TRACE_PASSED;
}
