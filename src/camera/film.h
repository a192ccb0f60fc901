/* Film geometry, raster <-> film, and the stratified sample pattern. */
#ifndef LENS2POV_FILM_H
#define LENS2POV_FILM_H

#include <stdint.h>
#include "base/vec3.h"

typedef struct film {
    int width, height;        /* pixels */
    double diagonal_mm;
    double width_mm, height_mm;
} film;

/* fw = D / sqrt(1 + a^2), fh = a fw with a = H / W (the contract). */
void film_init(film *f, int width, int height, double diagonal_mm);

/* The contract's raster mapping: ((0.5 - rx / W) fw, (ry / H - 0.5) fh, 0). The lens inverts
   the image; this mirror makes the final picture upright and unmirrored. Inline: it runs once
   per film sample. */
static inline vec3 film_camera_from_raster(const film *f, double rx, double ry)
{
    return v3((0.5 - rx / f->width) * f->width_mm, (ry / f->height - 0.5) * f->height_mm, 0.0);
}

/* One film sample: its position in the pixel and on the unit square of the pupil. Sample k of
   pixel (px, py) depends only on the seed, the pixel and k: a crop or a chunk of the film
   traces exactly the samples the whole film would. Both the pixel and the pupil are
   stratified in a gx x gy grid (gx gy = spp, as square as spp allows); the pupil strata are
   paired with the pixel strata through a per-pixel permutation, so that the pairs are not
   correlated (Kensler, "Correlated Multi-Jittered Sampling", 2013). */
typedef struct film_sample {
    double offset_x, offset_y; /* in the pixel, [0, 1) */
    double pupil_u, pupil_v;   /* on the unit square, [0, 1) */
    double wavelength_nm;      /* with dispersion (sample_pattern_wavelength); else 0 */
} film_sample;

typedef struct sample_pattern {
    int spp, gx, gy;
    uint64_t seed;
    /* Derived from spp, to spare every sample a division: n / gx is
       (n gx_multiplier) >> gx_shift for 0 <= n < 2^31, and the permutation works on the
       power of two above spp, less one. */
    uint64_t gx_multiplier;
    int gx_shift;
    uint32_t permute_mask;
} sample_pattern;

/* What sample k of a pixel takes from the pixel: a hash of the seed and its coordinates. */
typedef struct sample_pixel {
    uint64_t hash;
} sample_pixel;

void sample_pattern_init(sample_pattern *p, int spp, uint64_t seed);

/* Sample k of pixel (px, py) in two steps, so that a loop over a pixel's samples hashes the
   pixel once: sample_pattern_get(p, px, py, k) is
   sample_pattern_sample(p, sample_pattern_pixel(p, px, py), k), bit for bit. */
sample_pixel sample_pattern_pixel(const sample_pattern *p, int px, int py);
film_sample sample_pattern_sample(const sample_pattern *p, sample_pixel pixel, int k);
film_sample sample_pattern_get(const sample_pattern *p, int px, int py, int k);

/* With --dispersion, a sample's wavelength: the spp samples of a pixel take one band each of
   spp equal shares of the wavelength density (spectrum.h), through a second per-pixel
   permutation, so that the bands are paired with neither the pixel nor the pupil strata; the
   wavelength is jittered within its band. */
typedef struct wavelength_sample {
    int band;                  /* 0 .. spp - 1 */
    double nm;
} wavelength_sample;

wavelength_sample sample_pattern_wavelength(const sample_pattern *p, sample_pixel pixel, int k);

/* What the sub-images of --sampling field share instead of a pixel: a hash of the seed alone. */
sample_pixel sample_pattern_shared(const sample_pattern *p);

#endif
