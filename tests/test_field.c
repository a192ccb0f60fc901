/* Ray fields (--sampling field): the shared sample set's stratification, and the adaptive
   distribution-3 mesh of a sub-image read back through the model of POV-Ray
   (src/field/povuv.c) against the exact traced rays. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "field/sobol.h"
#include "support.h"

/* ---------------------------------------------------------------- the sample set */

static double dim_of(film_sample s, int d)
{
    return d == 0 ? s.offset_x : d == 1 ? s.offset_y : d == 2 ? s.pupil_u : s.pupil_v;
}

/* The first 2^m points put exactly one value in each interval [i/2^m, (i+1)/2^m) of every
   dimension. */
Test(field, shared_samples_are_stratified_in_each_dimension)
{
    for (uint64_t seed = 0; seed < 4; seed++)
        for (int m = 0; m <= 10; m++) {
            int n = 1 << m;
            for (int d = 0; d < 4; d++) {
                char *seen = calloc((size_t)n, 1);
                for (int k = 0; k < n; k++) {
                    double t = dim_of(sobol_shared_sample(seed, (uint32_t)k), d);
                    cr_assert(t >= 0 && t < 1);
                    int cell = (int)(t * n);
                    cr_assert(!seen[cell], "seed %d, 2^%d points, dim %d: interval %d twice",
                              (int)seed, m, d, cell);
                    seen[cell] = 1;
                }
                free(seen);
            }
        }
}

/* The pixel offsets (dimensions 0 and 1) form a (0, m, 2)-net: for every split m = a + b,
   each box of 2^-a x 2^-b holds exactly one of the first 2^m points. */
Test(field, shared_pixel_offsets_form_a_0_m_2_net)
{
    for (uint64_t seed = 0; seed < 4; seed++)
        for (int m = 0; m <= 10; m++)
            for (int a = 0; a <= m; a++) {
                int n = 1 << m, na = 1 << a, nb = 1 << (m - a);
                char *seen = calloc((size_t)n, 1);
                for (int k = 0; k < n; k++) {
                    film_sample s = sobol_shared_sample(seed, (uint32_t)k);
                    int box = (int)(s.offset_x * na) * nb + (int)(s.offset_y * nb);
                    cr_assert(!seen[box], "seed %d, m %d, a %d: box %d twice", (int)seed, m, a, box);
                    seen[box] = 1;
                }
                free(seen);
            }
}

Test(field, seeds_scramble_the_samples)
{
    film_sample a = sobol_shared_sample(1, 3), b = sobol_shared_sample(2, 3);
    cr_expect(a.offset_x != b.offset_x && a.pupil_u != b.pupil_u);
    film_sample c = sobol_shared_sample(1, 3);
    cr_expect(memcmp(&a, &c, sizeof a) == 0, "the same seed gives the same samples");
}
