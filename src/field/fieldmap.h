/* The field map: what developing a field render needs, on disk (PREFIX.map of trace
   --sampling field; WORK/field.map of render --sampling field when --keep-temp keeps its
   work folder), so that `develop` takes the renders of either. render itself develops from
   the same map in memory, its weights kept apart (weights_of).

   File layout: a text header of SAMPLEMAP_HEADER_BYTES bytes, as the sample map's
   (samplemap.h) but with the first line "lens2pov-fieldmap 1", its face layout keys 0, and the
   line "renders R" before "end"; then, little-endian: spp blocks of crop width x crop height
   float32 weights, row by row, block k sub-image k's (0 where no face renders the pixel);
   then R pairs uint32 width, height (render r's final picture: POV-Ray renders one pixel more
   each way, docs/fields.md); then spp quadruples uint32 render, dx, dy, band (where sub-image
   k lies in its render's final picture, and its wavelength band, 0 without dispersion).
   A map of pieces (adaptive sampling's, fieldtiles.h) has the first line "lens2pov-fieldmap
   2", the line "subimages S" after "renders R", and spp the picture's (each pixel's sums are
   divided by it, the weights scaled to it); then, little-endian: R pairs uint32 width,
   height; S records of eight uint32: render, dx, dy, band, then x0, y0, w, h (the rectangle
   of the crop the sub-image shows, its top left at (dx, dy)); then each sub-image's w x h
   float32 weights in turn, row by row.
   Readers refuse, with "FILE: what is wrong", a wrong first line, a size other than the
   layout's, a sub-image outside the crop or its render or a band outside wavelength_bands
   (a map of pieces has none); a weight that is negative or not finite when its block is
   read. */
#ifndef LENS2POV_FIELD_FIELDMAP_H
#define LENS2POV_FIELD_FIELDMAP_H

#include <stdint.h>
#include "base/error.h"
#include "base/outfile.h"
#include "field/fieldrays.h"
#include "image/samplemap.h"

typedef struct field_map {
    samplemap_header header;   /* the camera's; faces, packed_width and chunk_faces 0 */
    int subimages;             /* spp, but in a map of pieces */
    int renders;
    int *width, *height;       /* each render's final picture */
    field_placement *at;       /* each sub-image's render and place */
    uint32_t *band;            /* each sub-image's wavelength band (0 without dispersion) */
    /* What each sub-image shows, its weights one a pixel of its piece (adaptive sampling's);
       NULL: each the whole crop seen with sample k. */
    field_piece *piece;
    long long *offset;         /* a map of pieces read from path: where its weights begin */
    char *path;                /* where the weights are read from */
    /* Or, for render's map in memory: what gives sub-image k's, kept or made again
       (field_render.c, from fieldpass.h); NULL: read from path. */
    int (*weights_of)(const void *ctx, int k, float *weights, l2p_error *err);
    const void *weights_ctx;
} field_map;

/* Writing, in three steps: begin leaves room for the header and the weights (the file must be
   a regular file opened for writing); the weights of sub-image k go to their place in any
   order, from any thread (pwrite); finish appends the tables and writes the header. Each
   returns L2P_OK or L2P_FAILED with a message naming the file. */
int field_map_begin(const outfile *f, const samplemap_header *h, l2p_error *err);
int field_map_put_weights(const outfile *f, const samplemap_header *h, int k, const float *weights,
                          l2p_error *err);
int field_map_finish(const outfile *f, const field_map *m, l2p_error *err);

/* A map of pieces, all at once: m's tables and each sub-image's weights (field_map_weights),
   into f (a regular file opened for writing). L2P_OK or L2P_FAILED, naming the file. */
int field_map_write_pieces(const outfile *f, const field_map *m, l2p_error *err);

/* Whether path starts with the field map's first word, any version (develop tells the two
   maps apart; field_map_read then refuses a version it does not read). */
int field_map_is_one(const char *path);

int field_map_read(const char *path, field_map *out, l2p_error *err);

/* Sub-image k's weights (crop width x crop height floats, or its piece's), checked when read
   from the file. */
int field_map_weights(const field_map *m, int k, float *weights, l2p_error *err);

void field_map_free(field_map *m);

#endif
