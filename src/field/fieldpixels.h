/* A sub-image's pixels seen with its shared sample (docs/fields.md): the shared sample set,
   each crop pixel's raster position, exact ray and weight. The mesh builder (subimage.c), the
   --rays CSV (fieldrays.c), the strata (strata.c) and the weights made again (fieldpass.c)
   all take them from here, so that they are the same. */
#ifndef LENS2POV_FIELD_FIELDPIXELS_H
#define LENS2POV_FIELD_FIELDPIXELS_H

#include <stdint.h>
#include "camera/camera.h"
#include "field/fieldrays.h"

/* Narrows *out, a copy of camera c, to piece p: its crop becomes the piece's rectangle of
   c's, for all that takes a sub-image's pixels from the camera's crop. (A camera is large:
   copied once, narrowed for each piece.) */
void field_piece_crop(const camera *c, const field_piece *p, camera *out);

/* Pixel i of the crop (row by row: i = y * crop width + x) seen with shared sample s: its
   raster position, (crop_x0 + x + offset_x, crop_y0 + y + offset_y). */
void field_pixel_raster(const camera *c, film_sample s, long i, double *rx, double *ry);

/* The exact rays of crop pixels first .. first + n - 1 (n <= CAMERA_BATCH) seen with shared
   sample s, into b: each one's film point, ray (camera space), weight (times weight_scale,
   field_strata_place), and whether it is rendered: the lens passes it, its film point is
   within the lens's reach (as pixel sampling asks) and the ray and weight are finite.
   Building a sub-image and the --rays CSV both take the rays from here, so that they are
   the same rays. */
void field_trace_pixels(const camera *c, film_sample s, double weight_scale, long first, int n,
                        sample_batch *b);

/* The weights alone of the same pixels (b's film points and weights), as field_trace_pixels
   gives them to those that pass, bit for bit, without tracing the lens: a render develops its
   sub-images with weights made again where they pass (fieldpass.h) instead of keeping them. */
void field_weigh_pixels(const camera *c, film_sample s, double weight_scale, long first, int n,
                        sample_batch *b);

/* Sub-image k's shared sample: point k of the Owen-scrambled Sobol set; with dispersion also
   its wavelength, the bands dealt to the sub-images as pixel sampling deals them to a pixel's
   samples (sample_pattern_wavelength), and *band (when not NULL) gets its band, 0 without.
   field_strata_place then moves its pupil point into its stratum. */
film_sample field_shared_sample(const camera *c, int k, uint32_t *band);

#endif
