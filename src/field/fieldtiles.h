/* Adaptive field sampling's tiles (docs/adaptive.md): the crop in squares of
   FIELD_TILE_PX pixels, each with its own count of shared samples: a first round renders the
   whole crop with the first of them, and a second renders the rest, each sample over
   rectangles of the tiles whose count is above it (pieces, fieldrays.h). A pixel is the mean
   of its tile's samples. */
#ifndef LENS2POV_FIELD_FIELDTILES_H
#define LENS2POV_FIELD_FIELDTILES_H

#include "base/error.h"
#include "camera/camera.h"
#include "field/fieldrays.h"

enum { FIELD_TILE_PX = 8 };

/* The most sub-images a tile gets, in first rounds: a tile's count is a multiple of the first
   round's. */
enum { FIELD_TILE_MOST_ROUNDS = 16 };

/* The most tiles a piece of the second round spans from top to bottom: the renders of pieces
   all have the height of the tallest (fieldpack.c, field_pack_shelves), so one piece as tall as
   the crop would make every render that tall. */
enum { FIELD_PIECE_TILES_HIGH = 4 };

struct field_tiles {
    int width, height;         /* the crop's pixels */
    int across, down;          /* tiles */
    int *samples;              /* each tile's count of sub-images, row by row */
    int most;                  /* the largest count: the sub-images in all */
    int spp;                   /* the mean count asked for: the picture's spp */
};

/* The count of the tile that holds crop pixel i (i = y * width + x). */
int field_tiles_samples_at(const field_tiles *t, long i);

/* What crop pixel i's weights are multiplied by for the picture to divide its sums by spp:
   spp over its tile's count. */
double field_tiles_scale(const field_tiles *t, long i);

/* The counts for a crop of w x h after a first round of `first` sub-images (a power of two,
   at least 2): `sums` holds each pixel's sum of weight times colour over them, `early` over
   the first half of them (3 a pixel). A tile's count is proportional to the spread of its
   pixels' two estimates, its RMS difference standing for the first half's error (Neyman
   allocation: for samples in proportion to the error of one, Cochran, "Sampling techniques",
   1977, section 5.5), rounded to a multiple of `first`, from `first` to
   FIELD_TILE_MOST_ROUNDS times it, and scaled so that the counts average `budget` over the
   crop's pixels as near as that rounding allows. L2P_FAILED out of memory. */
int field_tiles_allocate(field_tiles *t, int w, int h, const double *sums, const double *early,
                         int first, int budget, l2p_error *err);

/* The pieces of the second round: for each sample from `first` on, rectangles of the tiles
   whose count is above it, each such tile in one; taller pieces first, then wider. *out (free
   it; NULL when none) gets them; returns their count, or -1 out of memory. */
long field_tiles_pieces(const field_tiles *t, int first, field_piece **out);

void field_tiles_free(field_tiles *t);

#endif
