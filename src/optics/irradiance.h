/* The film irradiance a uniform background gives, measured with the full simulation alone,
   without the pupils: what the relative illumination (vignetting) of a lens is. */
#ifndef LENS2POV_IRRADIANCE_H
#define LENS2POV_IRRADIANCE_H

#include "optics/lens.h"
#include "base/vec3.h"

/* E at film point p for a background of radiance 1: the integral of cos(theta) over the
   directions the lens passes from p, which is the area of the passing set in the plane of
   direction cosines (a, b), since d(omega) cos(theta) = da db. A 128 x 128 grid over the unit
   square finds the set (or, when it is narrower than the grid's cells, finer grids about the
   chief ray's direction); an n x n grid over its bounding box (grown by two cells of the grid
   that found it) measures it. 0 when no direction passes. */
double irradiance_at(const lens *l, vec3 p, int n);

/* E for a background of radiance 1 at a film point r from the axis, seen through a disk of
   radius R standing Z in front of the film, centred on the axis and parallel to it (a thick
   lens's exit pupil, which blocks nothing else): the projected solid angle of the disk,
   (pi / 2) (1 - (Z^2 + r^2 - R^2) / sqrt((Z^2 + r^2 + R^2)^2 - 4 r^2 R^2)) (the view factor of
   a disk to a parallel element off its axis; pi R^2 / (Z^2 + R^2) on it). */
double irradiance_through_disk(double r_mm, double z_mm, double radius_mm);

#endif
