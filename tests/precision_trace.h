/* A precision reference for the full simulation: src/optics/trace_kernel.h built a second
   time, through trace_one.h, with long double (x87 extended: a 64-bit significand, 11 more bits than double), over the same
   lens description. The double tracer and this one run the same formulas in the same order on
   the same inputs (the lens's numbers are doubles, exact in both), so the difference of their
   results is the rounding error of the double tracer, to within 2^-11 of itself. */
#ifndef LENS2POV_PRECISION_TRACE_H
#define LENS2POV_PRECISION_TRACE_H

#include <stdbool.h>
#include "optics/lens.h"
#include "optics/trace.h"

/* The kernel's ray, in long double. */
typedef struct ld_vec { long double x, y, z; } ld_vec;
typedef struct ld_ray { ld_vec o, d; } ld_ray;

/* trace_toward_scene / trace_toward_film over the whole lens in long double: o and d are
   updated in place (d is renormalized at the end, as the double tracer does). Return a
   trace_status; *blocked_at (may be NULL) gets the surface that blocked the ray. */
int precision_trace_toward_scene(const lens *l, long double o[3], long double d[3]);
int precision_trace_toward_film(const lens *l, long double o[3], long double d[3]);
trace_status precision_trace_range(const lens *l, int first, int last, bool toward_scene,
                                   ld_ray *r, int *blocked_at);

/* How close a ray comes to the places where tracing is ill-conditioned, along its path
   through the whole lens toward the scene (traced in long double, surface by surface, with
   the same kernel functions):
     min_cos      the smallest cosine of the angle between the ray and a surface normal, on
                  either side of any surface (grazing incidence, or grazing refraction at the
                  edge of total internal reflection: the derivative of the refracted direction
                  grows like 1 / cos);
     min_rim_gap  the smallest distance from a crossing point to the rim of that surface's
                  clear aperture (or the stop's opening), in mm, signed (< 0: outside);
   Returns the status of the trace (the values cover the surfaces crossed so far). */
typedef struct precision_margin {
    long double min_cos;
    long double min_rim_gap_mm;
    int surface_min_cos;
    int surface_min_rim_gap;
} precision_margin;
trace_status precision_margin_toward_scene(const lens *l, ld_ray r, precision_margin *m);

#endif
