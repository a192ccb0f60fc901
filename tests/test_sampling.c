/* The per-sample arithmetic made fast (the sample pattern without divisions, the pixel hash
   once per pixel) against the plain formulas it replaces: every sample must be the same, bit
   for bit, or seeded renders would change. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "camera/film.h"

/* ---- The sample pattern as first written: per-sample pixel hash, % and / by gx. */

static uint64_t ref_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double ref_unit_double(uint64_t h) { return (double)(h >> 11) * 0x1.0p-53; }

static uint32_t ref_permute(uint32_t i, uint32_t n, uint32_t key)
{
    uint32_t w = n - 1;
    w |= w >> 1; w |= w >> 2; w |= w >> 4; w |= w >> 8; w |= w >> 16;
    do {
        i ^= key; i *= 0xe170893d; i ^= key >> 16; i ^= (i & w) >> 4; i ^= key >> 8;
        i *= 0x0929eb3f; i ^= key >> 23; i ^= (i & w) >> 1; i *= 1 | key >> 27;
        i *= 0x6935fa69; i ^= (i & w) >> 11; i *= 0x74dcb303; i ^= (i & w) >> 2;
        i *= 0x9e501cc3; i ^= (i & w) >> 2; i *= 0xc860a3df; i &= w; i ^= i >> 5;
    } while (i >= n);
    return i;
}

static film_sample ref_sample(const sample_pattern *p, int px, int py, int k)
{
    const uint64_t pixel = ref_mix64(p->seed ^ ref_mix64(((uint64_t)(uint32_t)py << 32) | (uint32_t)px));
    const uint64_t h1 = ref_mix64(pixel + 4 * (uint64_t)k + 1), h2 = ref_mix64(pixel + 4 * (uint64_t)k + 2);
    const uint32_t pk = ref_permute((uint32_t)k, (uint32_t)p->spp, (uint32_t)pixel);
    film_sample s;
    s.offset_x = ((k % p->gx) + ref_unit_double(h1)) / p->gx;
    s.offset_y = ((k / p->gx) + ref_unit_double(ref_mix64(h1))) / p->gy;
    s.pupil_u = ((pk % p->gx) + ref_unit_double(h2)) / p->gx;
    s.pupil_v = ((pk / p->gx) + ref_unit_double(ref_mix64(h2))) / p->gy;
    return s;
}

static bool same_bits(film_sample a, film_sample b) { return memcmp(&a, &b, sizeof a) == 0; }

/* Sample k of pixel (px, py) both ways: sample_pattern_get, and the pixel hashed once. */
static void check_sample(const sample_pattern *p, sample_pixel pixel, int px, int py, int k)
{
    const film_sample want = ref_sample(p, px, py, k);
    const film_sample got = sample_pattern_get(p, px, py, k);
    const film_sample hoisted = sample_pattern_sample(p, pixel, k);
    cr_assert(same_bits(got, want), "spp %d seed %llu pixel (%d, %d) sample %d: get differs",
              p->spp, (unsigned long long)p->seed, px, py, k);
    cr_assert(same_bits(hoisted, want), "spp %d seed %llu pixel (%d, %d) sample %d: "
              "sample_pattern_sample differs", p->spp, (unsigned long long)p->seed, px, py, k);
}

static const uint64_t SEEDS[] = {0, 1, 5, 12345, 0x9e3779b97f4a7c15ULL, UINT64_MAX};
static const int PIXELS[][2] = {{0, 0}, {1, 0}, {0, 1}, {17, 5}, {639, 479}, {65535, 65536},
                                {2147483647, 2147483647}};

Test(sampling, pattern_matches_the_plain_formulas_for_every_sample)
{
    const int spps[] = {1, 2, 7, 9, 16, 33};
    for (size_t i = 0; i < sizeof spps / sizeof spps[0]; i++)
        for (size_t s = 0; s < sizeof SEEDS / sizeof SEEDS[0]; s++) {
            sample_pattern p;
            sample_pattern_init(&p, spps[i], SEEDS[s]);
            for (size_t j = 0; j < sizeof PIXELS / sizeof PIXELS[0]; j++) {
                const int px = PIXELS[j][0], py = PIXELS[j][1];
                const sample_pixel pixel = sample_pattern_pixel(&p, px, py);
                for (int k = 0; k < p.spp; k++)
                    check_sample(&p, pixel, px, py, k);
            }
        }
}

/* Every divisor gx up to 300, with every k and pupil stratum: the division by multiplication
   must agree with / and % throughout. */
Test(sampling, pattern_matches_for_every_spp_up_to_300)
{
    for (int spp = 1; spp <= 300; spp++) {
        sample_pattern p;
        sample_pattern_init(&p, spp, (uint64_t)spp * 7919);
        for (int px = 0; px < 3; px++) {
            const sample_pixel pixel = sample_pattern_pixel(&p, px, 2 * px + 1);
            for (int k = 0; k < spp; k++)
                check_sample(&p, pixel, px, 2 * px + 1, k);
        }
    }
}

/* The largest counts an int allows, where n gx_multiplier comes closest to 2^63: the last
   samples and a few around powers of two (the pupil strata come out wherever the permutation
   puts them). */
Test(sampling, pattern_matches_for_spp_near_the_int_limit)
{
    const int spps[] = {2147483647, 2147483646, 2147395600, 1 << 30, (1 << 30) + 1, 1 << 16,
                        65537 * 3, 46337 * 46327};
    const int ks[] = {0, 1, 2, 65535, 65536, 1 << 20, (1 << 30) - 1, 1 << 30, (1 << 30) + 1};
    for (size_t i = 0; i < sizeof spps / sizeof spps[0]; i++) {
        sample_pattern p;
        sample_pattern_init(&p, spps[i], SEEDS[i % (sizeof SEEDS / sizeof SEEDS[0])]);
        const sample_pixel pixel = sample_pattern_pixel(&p, 3, 4);
        for (int back = 1; back <= 64; back++)
            check_sample(&p, pixel, 3, 4, p.spp - back);
        for (size_t j = 0; j < sizeof ks / sizeof ks[0]; j++)
            if (ks[j] < p.spp)
                check_sample(&p, pixel, 3, 4, ks[j]);
    }
}
