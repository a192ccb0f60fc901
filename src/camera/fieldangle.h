/* A camera's field angles: how far from the axis the subject of a film point lies. */
#ifndef LENS2POV_FIELDANGLE_H
#define LENS2POV_FIELDANGLE_H

#include <stdbool.h>
#include "camera/camera.h"
#include "optics/chief.h"

typedef struct field_angles {
    const camera *camera;
    chief_lens chief;          /* the camera's lens for its chief rays; empty with --trace
                                  thick */
    bool thick;
} field_angles;

/* For many film radii of camera c, which must outlive f. L2P_FAILED out of memory. */
int field_angles_open(field_angles *f, const camera *c);
void field_angles_close(field_angles *f);

/* The angle, radians, of the ray of film radius rho_mm (mm, along +x) that defines the field:
   the chief ray (optics/chief.h), or with --trace thick the ray through the middle of the thick
   lens's exit pupil, whose mapping has no distortion. False where there is none. */
bool field_angles_ray(const field_angles *f, double rho_mm, double *theta_rad);

/* The half field angle, degrees, at film radius rho_mm: field_angles_ray's, except beyond the
   reach of the camera's pupil (a fisheye's image circle), where the picture ends and the
   field with it, and beyond the last radius whose ray leaves the lens (bisection). NAN when
   even the axis has none. */
double field_angles_half_deg(const field_angles *f, double rho_mm);

#endif
