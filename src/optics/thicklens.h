/* The thick lens of any run of surfaces, as Kolb, Mitchell and Hanrahan (1995) approximate a
   lens: cardinal points from two traced rays parallel to the axis, the real <-> image space
   transforms, and thick-lens tracing.

   "Real" space is the scene side of the subsystem, "image" space its film side. Points are
   camera-space z coordinates in mm. Newton's form of the imaging equation, with x measured
   from F1 toward the scene and x' from F2 toward the film: x x' = f1 f2, and the transverse
   magnification image/real is -x'/f2 = -f1/x. f1 = F1 - P1 and f2 = P2 - F2 (positive for a
   converging system); their ratio is that of the indices on the two sides. */
#ifndef LENS2POV_THICKLENS_H
#define LENS2POV_THICKLENS_H

#include <stdbool.h>
#include "base/error.h"
#include "optics/lens.h"
#include "optics/trace.h"

typedef struct thick_lens {
    double p1_z_mm, p2_z_mm;   /* principal planes (z): P1 on the scene side, P2 on the film side */
    double f1_z_mm, f2_z_mm;   /* focal points (z): F1 front (scene side), F2 rear (film side) */
    double front_focal_length_mm, rear_focal_length_mm;  /* F1 - P1, P2 - F2 */
} thick_lens;

/* Cardinal points of surfaces first .. last. Fails with L2P_BAD_INPUT for an afocal or
   degenerate subsystem (a parallel ray leaves parallel, or cannot get through). */
int thick_lens_of(const lens *l, int first, int last, thick_lens *out, l2p_error *err);

/* Conjugate points. Return false when the conjugate lies at infinity. */
bool thick_real_from_image(const thick_lens *t, vec3 image, vec3 *real);
bool thick_image_from_real(const thick_lens *t, vec3 real, vec3 *image);

/* Traces a film-side ray (d.z > 0) through the thick lens toward the scene: it crosses P2,
   leaves P1 at the same height, and passes through the real conjugate of every point of its
   image-space line. The tangent form sigma' = (f2/f1) sigma - h/f1 has no singularity when
   that conjugate is at infinity. The origin is left on the plane P1. */
bool thick_trace_toward_scene(const thick_lens *t, ray *r);

/* Effective focal length: the rear focal length of the whole lens when both sides are air. */
static inline double thick_efl_mm(const thick_lens *t) { return t->rear_focal_length_mm; }

#endif
