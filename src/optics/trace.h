/* Full simulation, as Kolb, Mitchell and Hanrahan (1995) trace a lens: a ray through the lens
   surfaces, in double precision. */
#ifndef LENS2POV_TRACE_H
#define LENS2POV_TRACE_H

#include <stdbool.h>
#include "optics/lens.h"
#include "base/vec3.h"

/* A refraction whose incidence or refraction cosine is below this counts as blocked: there the
   direction's error grows like 1/cos and a ray traced back may no longer find its way, while
   the light such rays carry (cos^4 weighted, at the rim of the bundle) is negligible. */
#define TRACE_GRAZING_COS 1e-4

/* A ray more than this many radii from a surface's vertex plane is carried to that plane before
   the intersection (Spencer and Murty; trace_kernel.h): the error stays within 16 ulp. */
#define TRACE_TRANSFER_RADII 4

typedef struct ray {
    vec3 o;  /* origin, camera space, mm */
    vec3 d;  /* unit direction */
} ray;

/* Why a ray did not get through. */
typedef enum trace_status {
    TRACE_PASSED = 0,
    TRACE_MISSED,      /* no intersection with the surface's cap, or behind the ray */
    TRACE_CLIPPED,     /* outside a surface's clear aperture or the stop's opening */
    TRACE_TIR,         /* total internal reflection */
    TRACE_GRAZING      /* refracted within a hair of grazing: see TRACE_GRAZING_COS */
} trace_status;

/* Intersects surface s (its vertex at s->vertex_z_mm) and moves r->o there. The cap is the
   part of the sphere on the vertex side of its centre; the root is taken in Spencer and
   Murty's vertex-relative form, which stays exact for near-flat surfaces. */
trace_status trace_intersect(const lens_surface *s, ray *r, vec3 *normal);

/* Refracts r->d at a surface with unit normal n (either orientation) from index n1 to n2:
   d' = eta d + (eta cos_i - cos_t) n with eta = n1/n2 (Heckbert's form). */
trace_status trace_refract(vec3 n, double n1, double n2, vec3 *d);

/* Traces r through surfaces last, last-1, ..., first (toward the scene, +z), or first .. last
   (toward the film); surfaces outside the range are ignored. Returns TRACE_PASSED with r on
   the last surface, or why it was blocked, with *blocked_at the surface (may be NULL) and r
   left on the last surface it crossed. */
trace_status trace_toward_scene(const lens *l, int first, int last, ray *r, int *blocked_at);
trace_status trace_toward_film(const lens *l, int first, int last, ray *r, int *blocked_at);

/* trace_toward_scene with the indices at this wavelength (nm), n(lambda) of lens_index_at. */
trace_status trace_toward_scene_at(const lens *l, int first, int last, double wavelength_nm,
                                   ray *r, int *blocked_at);

#endif
