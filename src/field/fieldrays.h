/* The --rays CSV of a field render: the exact ray of every rendered pixel and where it is
   rendered (docs/contracts.md, "The ray dump"). */
#ifndef LENS2POV_FIELD_FIELDRAYS_H
#define LENS2POV_FIELD_FIELDRAYS_H

#include <stdio.h>
#include "camera/camera.h"

/* Where a sub-image is rendered: its render (numbered as the includes are, field.fNNN.inc)
   and the offset of its top-left pixel in that render's final picture. */
typedef struct field_tiles field_tiles;   /* fieldtiles.h */

typedef struct field_placement {
    int render, dx, dy;
} field_placement;

/* What a sub-image shows: the crop's rectangle x0, y0, w x h (crop pixels) seen with shared
   sample k. A uniform render's sub-image k is the whole crop seen with sample k; adaptive
   sampling's second round renders single tiles (fieldtiles.h). */
typedef struct field_piece {
    int k, x0, y0, w, h;
} field_piece;

/* Writes the header and, sub-image by sub-image (k = 0 .. count - 1) and row by row, a row
   for every pixel of it whose exact ray is rendered (field_trace_pixels, the strata dealt for
   strata_samples, field_strata_count): raster_x, raster_y, film_x, film_y, origin, direction
   (camera space, mm), weight, as the pixel-sampling CSV (and wavelength_nm with dispersion),
   then image (at[k].render), image_x = at[k].dx + x and image_y = at[k].dy + y + 1, the pixel
   of the picture POV-Ray writes (its row 0 is never rendered, docs/fields.md), x and y within
   the sub-image. Sub-image k is pieces[k] (NULL: the whole crop seen with shared sample k);
   with tiles (adaptive sampling; NULL: none) each weight is times field_tiles_scale, as the
   picture counts it. path names the file in a write error. Returns L2P_OK, or L2P_FAILED. */
int field_rays_write(FILE *out, const char *path, const camera *c, int strata_samples,
                     const field_piece *pieces, const field_tiles *tiles,
                     const field_placement *at, int count, l2p_error *err);

#endif
