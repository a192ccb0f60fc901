#include "optics/trace.h"

#include <float.h>

/* The kernel for one ray in double precision; tests/precision_trace.c builds it in long
   double. */
#define KREAL double
#define KREAL_MAX DBL_MAX
#define KVEC vec3
#define KRAY ray
#define KNAME(f) kernel_##f
#include "optics/trace_one.h"

trace_status trace_intersect(const lens_surface *s, ray *r, vec3 *normal)
{
    return kernel_intersect(s, r, normal);
}

trace_status trace_refract(vec3 n, double n1, double n2, vec3 *d)
{
    return kernel_refract(n, n1, n2, d);
}

trace_status trace_toward_scene(const lens *l, int first, int last, ray *r, int *blocked_at)
{
    return kernel_through(l, first, last, true, 0.0, r, blocked_at);
}

trace_status trace_toward_scene_at(const lens *l, int first, int last, double wavelength_nm,
                                   ray *r, int *blocked_at)
{
    return kernel_through(l, first, last, true, wavelength_nm, r, blocked_at);
}

trace_status trace_toward_film(const lens *l, int first, int last, ray *r, int *blocked_at)
{
    return kernel_through(l, first, last, false, 0.0, r, blocked_at);
}
