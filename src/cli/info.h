/* `lens2pov info`: the lens's first-order properties, and with film options the camera's. */
#ifndef LENS2POV_INFO_H
#define LENS2POV_INFO_H

#include <stdbool.h>
#include <stdio.h>
#include "camera/camera.h"

typedef struct lens_info {
    double efl_mm, bfd_mm, ffd_mm, f_number, stop_diameter_mm, total_length_mm;
    double p1_from_rear_mm, p2_from_rear_mm;   /* principal planes, + toward the scene */
    double entrance_pupil_from_rear_mm, entrance_pupil_diameter_mm;
    double exit_pupil_from_rear_mm, exit_pupil_diameter_mm;
} lens_info;

/* First-order properties of the lens at its full stop, independent of the film distance. */
int lens_info_of(const lens *l, lens_info *out, l2p_error *err);

/* Half field angle, degrees, of film point p: field_angles_half_deg (camera/fieldangle.h) at
   its distance from the axis. */
double info_half_field_deg(const camera *c, vec3 p);

/* The working (image-side) f-number at the camera's focus and aperture, paraxial; NAN when the
   stop has no image. */
double info_working_f_number(const camera *c);

/* Prints them, and the camera's focus and field of view when c is not NULL; the wavelength
   first when it is not NAN (the lens was taken to it); glass: the file gives Abbe numbers. */
void info_print(FILE *out, const lens *l, bool glass, const lens_info *li, const camera *c,
                double wavelength_nm, bool json);

#endif
