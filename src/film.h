/* Film geometry, raster <-> film, and the stratified sample pattern. */
#ifndef LENS2POV_FILM_H
#define LENS2POV_FILM_H

#include <stdint.h>
#include "vec3.h"

typedef struct film {
    int width, height;        /* pixels */
    double diagonal_mm;
    double width_mm, height_mm;
} film;

/* fw = D / sqrt(1 + a^2), fh = a fw with a = H / W (the contract). */
void film_init(film *f, int width, int height, double diagonal_mm);

/* The contract's raster mapping: ((0.5 - rx / W) fw, (ry / H - 0.5) fh, 0). The lens inverts
   the image; this mirror makes the final picture upright and unmirrored. */
vec3 film_camera_from_raster(const film *f, double rx, double ry);

/* One film sample: its position in the pixel and on the unit square of the pupil. Sample k of
   pixel (px, py) depends only on the seed, the pixel and k: a crop or a chunk of the film
   traces exactly the samples the whole film would. Both the pixel and the pupil are
   stratified in a gx x gy grid (gx gy = spp, as square as spp allows); the pupil strata are
   paired with the pixel strata through a per-pixel permutation, so that the pairs are not
   correlated (Kensler, "Correlated Multi-Jittered Sampling", 2013). */
typedef struct film_sample {
    double offset_x, offset_y; /* in the pixel, [0, 1) */
    double pupil_u, pupil_v;   /* on the unit square, [0, 1) */
} film_sample;

typedef struct sample_pattern {
    int spp, gx, gy;
    uint64_t seed;
} sample_pattern;

void sample_pattern_init(sample_pattern *p, int spp, uint64_t seed);
film_sample sample_pattern_get(const sample_pattern *p, int px, int py, int k);

#endif
