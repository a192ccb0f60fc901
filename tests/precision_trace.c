/* The long double build of the full-simulation kernel (see precision_trace.h). This file is
   compiled with the test suite's flags; it has no tests of its own. */
#include "precision_trace.h"

#include <float.h>
#include <math.h>

#define KREAL long double
#define KREAL_MAX LDBL_MAX
#define KVEC ld_vec
#define KRAY ld_ray
#define KNAME(f) ld_##f
#include "optics/trace_one.h"

static long double ld_dot(ld_vec a, ld_vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

trace_status precision_trace_range(const lens *l, int first, int last, bool toward_scene,
                                   ld_ray *r, int *blocked_at)
{
    return ld_through(l, first, last, toward_scene, 0.0, r, blocked_at);
}

static int trace_array(const lens *l, bool toward_scene, long double o[3], long double d[3])
{
    ld_ray r = {{o[0], o[1], o[2]}, {d[0], d[1], d[2]}};
    const trace_status st = ld_through(l, 0, l->count - 1, toward_scene, 0.0, &r, NULL);
    o[0] = r.o.x;
    o[1] = r.o.y;
    o[2] = r.o.z;
    d[0] = r.d.x;
    d[1] = r.d.y;
    d[2] = r.d.z;
    return (int)st;
}

int precision_trace_toward_scene(const lens *l, long double o[3], long double d[3])
{
    return trace_array(l, true, o, d);
}

int precision_trace_toward_film(const lens *l, long double o[3], long double d[3])
{
    return trace_array(l, false, o, d);
}

/* Surface by surface with the kernel's own intersect and refract (the same steps as
   ld_through), noting the cosines on both sides and the rim clearance. */
trace_status precision_margin_toward_scene(const lens *l, ld_ray r, precision_margin *m)
{
    m->min_cos = 1;
    m->min_rim_gap_mm = INFINITY;
    m->surface_min_cos = m->surface_min_rim_gap = -1;
    for (int i = l->count - 1; i >= 0; i--) {
        ld_vec n;
        trace_status st = ld_intersect(&l->surface[i], &r, &n);
        if (st != TRACE_PASSED)
            return st;
        const long double a = lens_semi_aperture_mm(l, i);
        const long double gap = a - sqrtl(r.o.x * r.o.x + r.o.y * r.o.y);
        if (gap < m->min_rim_gap_mm) {
            m->min_rim_gap_mm = gap;
            m->surface_min_rim_gap = i;
        }
        if (!(r.o.x * r.o.x + r.o.y * r.o.y <= a * a))
            return TRACE_CLIPPED;
        const long double nn = sqrtl(ld_dot(n, n)), dd = sqrtl(ld_dot(r.d, r.d));
        const long double cos_in = fabsl(ld_dot(n, r.d)) / (nn * dd);
        st = ld_refract(n, lens_ior_behind(l, i), lens_ior_front(l, i), &r.d);
        const long double cos_out = st == TRACE_PASSED
                                        ? fabsl(ld_dot(n, r.d)) / (nn * sqrtl(ld_dot(r.d, r.d)))
                                        : 0;
        const long double c = fminl(cos_in, cos_out);
        if (c < m->min_cos) {
            m->min_cos = c;
            m->surface_min_cos = i;
        }
        if (st != TRACE_PASSED)
            return st;
    }
    return TRACE_PASSED;
}
