/* The chief ray of a film point: the ray from it through the centre of the aperture stop, out
   of the lens. Its angle to the axis in object space is the point's field angle, a property of
   the lens and its focus alone: not of the pupil a camera samples, the stop's opening or the
   film's size (info's field of view, --angle, plot --what distortion). */
#ifndef LENS2POV_CHIEF_H
#define LENS2POV_CHIEF_H

#include <stdbool.h>
#include "optics/lens.h"
#include "optics/trace.h"

typedef struct chief_lens {
    /* The lens with every rim and the stop opened wide and the blades taken off: a chief ray
       is defined by where it crosses the stop, not by whether the rims let it through (where
       they cut it, the rest of the bundle still images the point at nearly the same angle). */
    lens open;
    double aim_z_mm;   /* the paraxial exit pupil's place, where aiming starts; NAN: none */
} chief_lens;

/* For lens l at its film distance. L2P_FAILED out of memory. */
int chief_lens_open(chief_lens *c, const lens *l);
void chief_lens_close(chief_lens *c);

/* The slope dx/dz at the film of the chief ray of film point (r, 0, 0), r >= 0 in mm, as far
   as the stop: its crossing of the stop's plane is within 1e-11 mm of the centre. False when
   no ray from the point gets there. */
bool chief_slope(const chief_lens *c, double film_radius_mm, double *slope);

/* The chief ray of film point (r, 0, 0), r >= 0 in mm, leaving the front surface; false when
   no ray from the point crosses the stop's centre and leaves the lens (total internal
   reflection, a surface missed or grazed). */
bool chief_ray(const chief_lens *c, double film_radius_mm, ray *out);

/* Its angle to the axis, radians. */
bool chief_angle(const chief_lens *c, double film_radius_mm, double *theta_rad);

/* The surface whose rim limits the beam from the film's centre, for lens l at its opening (c
   opened from it): the stop's index when the stop does, another when the ray toward the
   stop's rim is cut before or after it, with *passing the share of the stop's radius whose
   rays get through; -1 when no ray of the film's centre meets a rim (the stop's image at
   infinity, or heights of the stop no ray gets to). Blades are not rims: a polygon inside
   the stop's circle is the stop still. */
int chief_axial_limit(const chief_lens *c, const lens *l, double *passing);

#endif
