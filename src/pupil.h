/* Exit pupils (seed section III): the disk on the film side toward which film rays are aimed,
   and sampling it. */
#ifndef LENS2POV_PUPIL_H
#define LENS2POV_PUPIL_H

#include "error.h"
#include "lens.h"
#include "vec3.h"

typedef enum pupil_kind {
    PUPIL_STOP,        /* the aperture stop itself: misses rays the lens would pass (diagnostic) */
    PUPIL_REAR,        /* the rear element's rim: passes many rays the lens then blocks */
    PUPIL_STOP_IMAGE   /* the paraxial image of the stop through the stop-to-film surfaces */
} pupil_kind;

typedef struct pupil {
    pupil_kind kind;
    double z_mm;        /* plane of the disk, camera space; may lie behind the film (z < 0) */
    double radius_mm;
} pupil;

/* Name as used on the command line: "stop", "rear", "stop-image". */
const char *pupil_kind_name(pupil_kind k);
int pupil_kind_parse(const char *name, pupil_kind *k);

/* Builds the pupil for the lens at its current film distance and stop opening. */
int pupil_make(const lens *l, pupil_kind kind, pupil *out, l2p_error *err);

/* Shirley and Chiu's concentric map of the unit square onto the unit disk: it keeps strata
   compact and areas proportional. */
void concentric_disk(double u, double v, double *x, double *y);

/* The film ray from film point p toward the pupil point of sample (u, v), and the seed's
   weight A cos^4(theta) / Z^2 (A: pupil area, Z: axial distance from the film to the pupil).
   Returns the weight; 0 when the pupil lies in the film plane. */
double pupil_film_ray(const pupil *pu, vec3 film_point, double u, double v, vec3 *direction);

#endif
