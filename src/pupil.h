/* Exit pupils (seed section III): the disk on the film side toward which film rays are aimed,
   and sampling it. */
#ifndef LENS2POV_PUPIL_H
#define LENS2POV_PUPIL_H

#include <stdbool.h>
#include "error.h"
#include "lens.h"
#include "vec3.h"

typedef enum pupil_kind {
    PUPIL_STOP,        /* the aperture stop itself: misses rays the lens would pass (diagnostic) */
    PUPIL_REAR,        /* the rear element's rim: passes many rays the lens then blocks */
    PUPIL_STOP_IMAGE   /* the paraxial image of the stop through the stop-to-film surfaces */
} pupil_kind;

/* Rings of film radius over which a pupil's disk may grow (see pupil_cover). */
enum { PUPIL_RINGS = 16 };

typedef struct pupil {
    pupil_kind kind;
    double z_mm;        /* plane of the disk, camera space; may lie behind the film (z < 0) */
    double radius_mm;   /* the model's radius */
    /* The radius sampled for film points in ring i, i.e. at film radius in
       [i, i + 1) * ring_width_mm; the last ring extends to infinity. */
    double ring_radius_mm[PUPIL_RINGS];
    double ring_width_mm;
} pupil;

/* Name as used on the command line: "stop", "rear", "stop-image". */
const char *pupil_kind_name(pupil_kind k);
int pupil_kind_parse(const char *name, pupil_kind *k);

/* The paraxial image of the stop (centre and rim conjugates) through the surfaces behind it
   (toward_film: the exit pupil) or in front of it (the entrance pupil, seen from the scene). */
int pupil_stop_image(const lens *l, bool toward_film, double *z_mm, double *radius_mm,
                     l2p_error *err);

/* Builds the pupil for the lens at its current film distance and stop opening; every ring
   samples the model's disk. */
int pupil_make(const lens *l, pupil_kind kind, pupil *out, l2p_error *err);

/* Shirley and Chiu's concentric map of the unit square onto the unit disk: it keeps strata
   compact and areas proportional. */
void concentric_disk(double u, double v, double *x, double *y);

/* Grows each ring's disk, never shrinking it, until it holds every point of the pupil plane
   through which a film ray of that ring gets through the lens (full simulation). A disk that
   misses some of them biases the picture dark: the paraxial image of the stop is about 4%
   too small in radius on the double-Gauss at f/2, and off axis the bundle shifts. Rays aimed
   at the extra area are blocked by the trace, and the weight uses the area sampled, so the
   estimate stays unbiased. film_radius_mm: the largest film radius used. */
void pupil_cover(pupil *pu, const lens *l, double film_radius_mm);

/* The film ray from film point p toward the pupil point of sample (u, v), and the seed's
   weight A cos^4(theta) / Z^2 (A: area of the disk sampled for p's ring, Z: axial distance
   from the film to the pupil).
   Returns the weight; 0 when the pupil lies in the film plane. */
double pupil_film_ray(const pupil *pu, vec3 film_point, double u, double v, vec3 *direction);

/* The same for n film samples at once, faster: directions[k] and weights[k] are what
   pupil_film_ray gives for film_points[k], u[k] and v[k], bit for bit. */
void pupil_film_rays(const pupil *pu, int n, const vec3 *film_points, const double *u,
                     const double *v, vec3 *directions, double *weights);

/* The unit direction from film point p toward point (x, y) of the pupil plane, and the radius
   of the disk sampled for p. */
vec3 pupil_direction(const pupil *pu, vec3 film_point, double x_mm, double y_mm);
double pupil_ring_radius_mm(const pupil *pu, vec3 film_point);

#endif
