/* The shared samples of --sampling field: one (pixel offset, pupil point) per sub-image, all
   pixels of a sub-image sharing it. A 4-D Sobol sequence (Joe and Kuo's direction numbers),
   Owen-scrambled by hashing (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020), seeded
   by --seed. */
#ifndef LENS2POV_FIELD_SOBOL_H
#define LENS2POV_FIELD_SOBOL_H

#include <stdint.h>
#include "camera/film.h"

/* Point index of the unscrambled Sobol sequence in dimension dim (0..3), as a 32-bit fraction. */
uint32_t sobol_bits(uint32_t index, int dim);

/* Nested uniform scramble of a 32-bit fraction (Owen scrambling with a hashed random tree). */
uint32_t sobol_owen_scramble(uint32_t x, uint32_t seed);

/* Sample k of the shared set: offset_x, offset_y, pupil_u, pupil_v, each in [0, 1). The first
   2^m samples put one value in each interval of width 2^-m in every dimension, and the first
   two dimensions form a (0, m, 2)-net. */
film_sample sobol_shared_sample(uint64_t seed, uint32_t k);

#endif
