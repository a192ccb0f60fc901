/* The adaptive distribution-3 mesh of one sub-image: the whole crop seen with one shared
   sample (pixel offset and pupil point). docs/fields.md has the design. */
#ifndef LENS2POV_FIELD_SUBIMAGE_H
#define LENS2POV_FIELD_SUBIMAGE_H

#include <stdint.h>
#include "camera/camera.h"
#include "field/fieldmesh.h"

/* How far POV-Ray's interpolated ray may be from the exact one. */
typedef struct field_tolerance {
    double pixels;       /* the asked tolerance, in pixels (--field-tolerance) */
    double angle_rad;    /* between the directions */
    double origin_mm;    /* origin offset across the exact ray, camera space */
} field_tolerance;

/* From a tolerance in pixels: a pixel of pitch p seen through a lens of rear focal length f
   spans p / f rad, so angle = tol p / f; an origin moved by e across its ray moves a subject
   at distance Z by e / Z rad, so origin = tol p Z / f with Z the focus distance (film plane
   to the plane in focus), at most 100 f. */
void field_tolerance_of(const camera *c, double pixels, field_tolerance *t);

/* The builder checks each pixel with the face's affine form of the model (povuv_affine_ray),
   which agrees with the model to far less than this share of the tolerance (test_field.c
   measures it), and keeps this much of the tolerance back for it: a pixel the builder passes
   is within the tolerance by the model itself. */
#define FIELD_AFFINE_MARGIN 1e-6

/* The most a pixel's squared error is scaled by where a pixel spans a smaller angle than at the
   film's centre (subimage.c, pixel_scale): a quarter of the centre's angle. Real lenses stay
   far from it (the 22 mm wide angle's corners on a 35 mm film: 2.7); it bounds what a lens
   whose field folds asks of POV-Ray's float32 rays. */
#define FIELD_MOST_STRICTER 16.0

/* What building a sub-image found. */
typedef struct field_stats {
    int faces, lone_faces, vertices;
    long passed, blocked;      /* pixels whose exact ray the lens passes, blocks */
    double worst_pixels;       /* largest error of a covered pixel, in the tolerance's pixels */
} field_stats;

/* Pixels between the vertices of the coarsest grid, and of the base grid on which a coarsest
   cell that fails is split: below the base grid the mesh follows the field, its edges, halving
   and hulls; above it only whole cells are tried. */
enum { FIELD_COARSEST_CELL = 128, FIELD_BASE_CELL = 32 };

/* The crop of camera c (crop_x0..crop_x1, crop_y0..crop_y1) seen with shared sample s, as a
   mesh for a render of exactly the crop's size (vertex pixel positions are crop pixels):
   every pixel whose exact ray passes lies in at least one face, every face that contains it
   gives it a ray within the tolerance (checked here, with the model of povuv.c), and no face
   contains a pixel the lens blocks (or whose film point is beyond the lens's reach, as with
   pixel sampling). out is cleared first; its render size is field_render_size of the crop's.
   weights (NULL, or one a crop pixel, row by row) gets each pixel's sample weight times
   weight_scale (field_strata_place), 0 where blocked. Returns L2P_OK, or L2P_FAILED when out
   of memory. */
int field_build_subimage(const camera *c, film_sample s, double weight_scale,
                         const field_tolerance *t, int base_cell, field_mesh *out, float *weights,
                         field_stats *st, l2p_error *err);

/* The render size for a crop of w x h: the smallest 2^a - 1 >= w, 2^b - 1 >= h, so that UVs
   are short binary fractions. */
int field_render_size(int n);

#endif
