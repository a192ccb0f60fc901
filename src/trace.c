#include "trace.h"

/* In local coordinates (x, y, s = z - vertex_z) a surface of curvature c, whose centre lies at
   s = -1/c, is F = c (x^2 + y^2 + s^2) + 2 s = 0; c = 0 is the plane s = 0. Along p + t d
   (|d| = 1): c t^2 + 2 B t + C = 0 with B = c (p.d) + d_z and C = c |p|^2 + 2 s0.
   Spencer and Murty (JOSA 52, 1962) take the root that tends to the vertex as
   t = -C / (B + sgn(B) sqrt(B^2 - c C)), which loses no digits as c -> 0; the other root is
   -(B + sgn(B) sqrt(B^2 - c C)) / c. The unit normal is (c x, c y, 1 + c s); its z component
   is positive on the cap that holds the vertex, the only part of the sphere the lens has. */
trace_status trace_intersect(const lens_surface *s, ray *r, vec3 *normal)
{
    const double c = s->curvature_per_mm;
    const vec3 d = r->d;
    vec3 p = v3(r->o.x, r->o.y, r->o.z - s->vertex_z_mm);
    /* Spencer and Murty first carry the ray to the vertex's tangent plane: from a distant
       origin B^2 and c C are huge and nearly equal, and their difference would cancel. */
    double t0 = 0.0;
    if (fabs(d.z) > 1e-6) {
        t0 = -p.z / d.z;
        p = v3(p.x + t0 * d.x, p.y + t0 * d.y, 0.0);
    }
    const double B = c * v3_dot(p, d) + d.z;
    const double C = c * v3_dot(p, p) + 2.0 * p.z;
    const double disc = B * B - c * C;
    if (!(disc >= 0.0))
        return TRACE_MISSED;
    const double q = -(B + copysign(sqrt(disc), B));
    /* q = 0 only for a ray tangent to the surface or lying in the plane: a miss. */
    double roots[2] = {q != 0.0 ? C / q : NAN, c != 0.0 ? q / c : NAN};
    if (roots[1] < roots[0]) {
        const double t = roots[0];
        roots[0] = roots[1];
        roots[1] = t;
    }
    for (int k = 0; k < 2; k++) {
        const double t = roots[k];
        if (!(t0 + t >= 0.0) || !isfinite(t))
            continue;
        const vec3 h = v3_madd(p, d, t);
        const double nz = 1.0 + c * h.z;   /* > 0 on the vertex-side cap */
        if (!(nz >= 0.0))
            continue;
        r->o = v3(h.x, h.y, h.z + s->vertex_z_mm);
        *normal = v3(c * h.x, c * h.y, nz);
        return TRACE_PASSED;
    }
    return TRACE_MISSED;
}

trace_status trace_refract(vec3 n, double n1, double n2, vec3 *d)
{
    if (n1 == n2)
        return TRACE_PASSED;
    double cos_i = -v3_dot(n, *d);
    if (cos_i < 0.0) {            /* orient n against the ray */
        n = v3_scale(n, -1.0);
        cos_i = -cos_i;
    }
    const double eta = n1 / n2;
    const double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if (sin2_t > 1.0)
        return TRACE_TIR;
    const double cos_t = sqrt(1.0 - sin2_t);
    const vec3 t = v3_madd(v3_scale(*d, eta), n, eta * cos_i - cos_t);
    *d = v3_normalize(t);
    return TRACE_PASSED;
}

/* One surface: intersection, aperture, refraction from n1 to n2. */
static trace_status cross_surface(const lens *l, int i, double n1, double n2, ray *r)
{
    const lens_surface *s = &l->surface[i];
    vec3 n;
    trace_status st = trace_intersect(s, r, &n);
    if (st != TRACE_PASSED)
        return st;
    const double a = lens_semi_aperture_mm(l, i);
    if (!(r->o.x * r->o.x + r->o.y * r->o.y <= a * a))
        return TRACE_CLIPPED;
    return trace_refract(n, n1, n2, &r->d);
}

trace_status trace_toward_scene(const lens *l, int first, int last, ray *r, int *blocked_at)
{
    for (int i = last; i >= first; i--) {
        trace_status st = cross_surface(l, i, lens_ior_behind(l, i), lens_ior_front(l, i), r);
        if (st != TRACE_PASSED) {
            if (blocked_at)
                *blocked_at = i;
            return st;
        }
    }
    return TRACE_PASSED;
}

trace_status trace_toward_film(const lens *l, int first, int last, ray *r, int *blocked_at)
{
    for (int i = first; i <= last; i++) {
        trace_status st = cross_surface(l, i, lens_ior_front(l, i), lens_ior_behind(l, i), r);
        if (st != TRACE_PASSED) {
            if (blocked_at)
                *blocked_at = i;
            return st;
        }
    }
    return TRACE_PASSED;
}
