/* Focusing: the film distance that puts a plane at a given distance in focus, and back. */
#ifndef LENS2POV_FOCUS_H
#define LENS2POV_FOCUS_H

#include "base/error.h"
#include "optics/lens.h"
#include "optics/thicklens.h"

/* Sets l's film distance so that the plane object_distance_mm in front of the film (INFINITY
   for infinity) is in paraxial focus on the film: a thick-lens estimate, refined by secant
   steps on the axial crossing of a real near-axial ray until it lies on the film. unit_mm
   only words messages in scene units. L2P_BAD_INPUT, naming the closest distance, when the
   plane is closer than the lens can focus; from_look_at words it for a distance that was not
   asked for but came from the look-at point. */
int focus_set(lens *l, double object_distance_mm, double unit_mm, bool from_look_at,
              l2p_error *err);

/* A lens that diverges light (t: its thick lens, film distance 0) forms no real image:
   L2P_BAD_INPUT naming the file. Every command refuses such a lens, info as trace. */
int focus_check_real_image(const lens *l, const thick_lens *t, l2p_error *err);

/* Film plane to the plane conjugate to the film centre at l's film distance, mm; INFINITY
   when the film is in the rear focal plane. Negative for a virtual conjugate. */
double focus_distance_mm(const lens *l);

#endif
