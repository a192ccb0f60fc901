/* Packing a field render's sub-images into POV-Ray renders: what each render holds and where
   each sub-image lies in its picture. Every render of a call has one size, since a POV-Ray
   process renders all its renders at one size (field_povray.c, assign_jobs). */
#ifndef LENS2POV_FIELD_FIELDPACK_H
#define LENS2POV_FIELD_FIELDPACK_H

#include "field/fieldrays.h"

/* One POV-Ray render: its final size (POV-Ray renders one more each way) and sub-images. */
typedef struct field_render_plan {
    int width, height;
    int used_width, used_height;   /* the grid of sub-images, from the top left: rendered */
    int first, count;
    long long faces;
} field_render_plan;

/* A sub-image as packing sees it: what it shows, its faces, and (set by packing) its place. */
typedef struct field_packed {
    field_piece piece;
    long long faces;
    field_placement at;
} field_packed;

/* Whole crops of w x h: consecutive sub-images in a grid, as many a render as cost least
   (the frames' overhead frame_s against POV-Ray's face search), at most FIELD_FACES_PER_RENDER
   faces or one sub-image. Returns the number of renders. */
int field_pack_grid(field_packed *subs, int spp, int w, int h, int jobs, double frame_s,
                    field_render_plan *plans);

/* The number of renders field_pack_grid would make of spp sub-images of faces_per_sub faces
   each: for estimates before the sub-images are built. */
int field_pack_count_estimate(int spp, int w, int h, int jobs, double faces_per_sub,
                              double frame_s);

/* Pieces (adaptive sampling's second round, taller first: field_tiles_pieces) on shelves
   across renders as wide as the crop's. Returns the number of renders. */
int field_pack_shelves(field_packed *subs, int n, int crop_w, int jobs, double frame_s,
                       field_render_plan *plans);

#endif
