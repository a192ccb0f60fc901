#include "raytable/povface.h"

void povface_single(vec3 o, vec3 d, double size, vec3 v[3])
{
    /* a, b span the plane normal to d with a x b = d; vertices at 0, 240 and 120 degrees give
       (P3 - P1) x (P2 - P1) = +k d, the winding POV-Ray turns into direction d. */
    const vec3 helper = fabs(d.x) < 0.6 ? v3(1, 0, 0) : v3(0, 1, 0);
    const vec3 a = v3_normalize(v3_cross(d, helper));
    const vec3 b = v3_cross(d, a);
    const double c = -0.5 * size, s = 0.8660254037844386 * size;
    v[0] = v3_madd(o, a, size);
    v[1] = v3_add(o, v3_add(v3_scale(a, c), v3_scale(b, -s)));
    v[2] = v3_add(o, v3_add(v3_scale(a, c), v3_scale(b, s)));
}

/* Distance from x to the line through p along the unit vector u. */
static double line_distance(vec3 x, vec3 p, vec3 u)
{
    const vec3 q = v3_sub(x, p);
    return v3_length(v3_madd(q, u, -v3_dot(q, u)));
}

/* The farthest vertex of a pair may lie at most this many lone-triangle sizes from the mesh's
   origin: float32 then moves an origin by at most sqrt(3) 2^-24 128 = 1.3e-5 of the size
   (0.2 um for the double-Gauss). And at most this many times the smaller of the faces'
   heights over the shared edge (3 r), which keeps the faces from being slivers: a direction
   then moves by some 1e-7 rad at worst. On the double-Gauss at 160 x 120 x 16 samples, 86% of
   neighbouring rays share an edge (with a reach of 32: 45%, 256: 92%). */
#define PAIR_MAX_REACH 128.0
#define PAIR_MAX_ASPECT 2.0

bool povface_pair(vec3 o1, vec3 d1, vec3 o2, vec3 d2, double size, vec3 v[4], bool swap[2])
{
    /* A face's plane holds its centroid and is normal to its ray, so a shared edge lies on the
       line where the planes (x - o1).d1 = 0 and (x - o2).d2 = 0 meet: direction n = d1 x d2.
       Relative to the origins' midpoint m, with h_k = (o_k - m).d_k and c = d1.d2, its point
       nearest m is ((h1 - c h2) d1 + (h2 - c h1) d2) / |n|^2 (it lies in span(d1, d2)). */
    if (!(v3_isfinite(o1) && v3_isfinite(d1) && v3_isfinite(o2) && v3_isfinite(d2)))
        return false;
    const vec3 n = v3_cross(d1, d2);
    const double nn = v3_dot(n, n);
    if (!(nn > 1e-24))
        return false;
    const vec3 u = v3_scale(n, 1.0 / sqrt(nn));
    const vec3 m = v3_scale(v3_add(o1, o2), 0.5);
    const double c = v3_dot(d1, d2), h1 = v3_dot(v3_sub(o1, m), d1), h2 = v3_dot(v3_sub(o2, m), d2);
    /* The edge is centred on that point and as long as the origins' farther distance from the
       line; each third vertex then makes its face's centroid the origin. */
    const vec3 p = v3_add(m, v3_scale(v3_add(v3_scale(d1, h1 - c * h2), v3_scale(d2, h2 - c * h1)),
                                      1.0 / nn));
    const double r1 = line_distance(o1, p, u), r2 = line_distance(o2, p, u);
    const double half = fmax(r1, r2);
    const vec3 a = v3_madd(p, u, -half), b = v3_madd(p, u, half);
    const vec3 c1 = v3_sub(v3_scale(o1, 3.0), v3_scale(p, 2.0));
    const vec3 c2 = v3_sub(v3_scale(o2, 3.0), v3_scale(p, 2.0));
    /* A face's height over the edge is 3 r: its third vertex is 3 (o - p) away from p. */
    const double reach = fmax(fmax(v3_length(a), v3_length(b)), fmax(v3_length(c1), v3_length(c2)));
    if (!(reach < PAIR_MAX_ASPECT * 3.0 * fmin(r1, r2) && reach <= PAIR_MAX_REACH * size))
        return false;
    v[0] = a;
    v[1] = b;
    v[2] = c1;
    v[3] = c2;
    swap[0] = v3_dot(v3_cross(v3_sub(c1, a), v3_sub(b, a)), d1) < 0.0;
    swap[1] = v3_dot(v3_cross(v3_sub(c2, a), v3_sub(b, a)), d2) < 0.0;
    return true;
}
