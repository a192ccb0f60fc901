/* The lens drawn in its meridional section (the y-z plane of camera space), to scale, as SVG:
   the glass of each element, the stop, the film, two fans of rays traced through every
   surface, the cardinal points and the pupils. */
#ifndef LENS2POV_DIAGRAM_H
#define LENS2POV_DIAGRAM_H

#include <stdio.h>
#include "base/error.h"
#include "camera/camera.h"

/* Rays a fan: spread across the pupil region's meridional diameter. */
enum { DIAGRAM_FAN_RAYS = 7 };
/* Surfaces the diagram draws at most (real lenses have a few dozen). */
enum { DIAGRAM_MAX_SURFACES = 256 };

/* The film height (y, mm) of the field fan: the film's half-diagonal, or just inside a
   fisheye's image circle, where the lens still passes rays. */
double diagram_field_height_mm(const camera *c);

/* The pupil sample v of ray k of a fan: samples (0.5, v) lie on the y diameter of the disk
   the pupil's concentric map fills (pupil.h), which the region's shape maps onto its
   meridional chord. */
double diagram_fan_v(int k);

/* The points of the ray from film point (0, film_y, 0) toward pupil sample (0.5, v), as the
   full simulation traces it surface by surface: points[0] on the film, points[1 + j] on
   surface count-1-j, as far as the ray gets (at most count + 1 points). Returns how many,
   in *passed whether it left the front surface and then, when direction is not NULL, its
   outgoing direction in *direction. */
int diagram_ray_points(const camera *c, double film_y, double v, vec3 *points, bool *passed,
                       vec3 *direction);

/* Writes the SVG of the camera's lens at its film distance and stop opening. */
int diagram_write_svg(FILE *out, const camera *c, l2p_error *err);

#endif
