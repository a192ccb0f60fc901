/* The --rays CSV of a field render: the exact ray of every rendered pixel and where it is
   rendered (docs/contracts.md, "The ray dump"). */
#ifndef LENS2POV_FIELD_FIELDRAYS_H
#define LENS2POV_FIELD_FIELDRAYS_H

#include <stdio.h>
#include "camera/camera.h"

/* Where a sub-image is rendered: its render (numbered as the includes are, field.fNNN.inc)
   and the offset of its top-left pixel in that render's final picture. */
typedef struct field_placement {
    int render, dx, dy;
} field_placement;

/* Writes the header and, sub-image by sub-image (k = 0 .. spp - 1) and row by row, a row for
   every crop pixel whose exact ray is rendered (field_trace_pixels): raster_x, raster_y,
   film_x, film_y, origin, direction (camera space, mm), weight, as the pixel-sampling CSV (and
   wavelength_nm with dispersion), then image (at[k].render), image_x = at[k].dx + x and image_y = at[k].dy + y + 1, the pixel of
   the picture POV-Ray writes (its row 0 is never rendered, docs/fields.md). path names the
   file in a write error. Returns L2P_OK, or L2P_FAILED. */
int field_rays_write(FILE *out, const char *path, const camera *c, const field_placement *at,
                     int spp, l2p_error *err);

#endif
