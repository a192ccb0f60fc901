/* Charts of a lens against film radius, drawn by gnuplot: distortion and relative
   illumination (vignetting). The tables are computed here; plot_run_gnuplot draws them. */
#ifndef LENS2POV_PLOT_H
#define LENS2POV_PLOT_H

#include <stdio.h>
#include "base/error.h"
#include "camera/camera.h"

/* Rows of a table: film radii 0, R/24, ..., R (R the film's half-diagonal). */
enum { PLOT_ROWS = 25 };
/* Cells a side of the fine grid that measures the irradiance (optics/irradiance.h). */
enum { PLOT_IRRADIANCE_GRID = 512 };
/* The PNG's size in pixels. */
enum { PLOT_WIDTH_PX = 800, PLOT_HEIGHT_PX = 500 };

/* Writes the distortion table: film radius (mm), the chief ray's field angle (deg), the
   paraxial image height k tan(theta) (mm) and the distortion 100 (r / (k tan theta) - 1) (%),
   with k the limit of r / tan(theta) at the axis (the focal length when focused at infinity).
   The field angle is camera/fieldangle.h's (the chief ray through the stop's centre); rows
   beyond a fisheye's image circle are left out. L2P_FAILED out of memory. */
int plot_distortion_table(FILE *out, const camera *c, l2p_error *err);

/* Writes E(r)/E(0) for each camera (the same lens at several f-numbers), one column each:
   irradiance_at (optics/irradiance.h) at film point (0, r), or with --trace thick
   irradiance_through_disk of the exit pupil. */
void plot_vignetting_table(FILE *out, const camera *const *cams, int count);

/* Draws table (a file of folder dir written by one of the above, named relative to dir) with
   gnuplot into dir/plot.png: what is "distortion" or "vignetting", title a line of text without
   quotes, labels the titles of vignetting's count columns. L2P_FAILED with a message when
   gnuplot is missing or fails. */
int plot_run_gnuplot(const char *what, const char *dir, const char *table, const char *title,
                     const char *const *labels, int count, l2p_error *err);

#endif
