#include "camera/film.h"

#include "optics/spectrum.h"

void film_init(film *f, int width, int height, double diagonal_mm)
{
    const double a = (double)height / (double)width;
    f->width = width;
    f->height = height;
    f->diagonal_mm = diagonal_mm;
    f->width_mm = diagonal_mm / sqrt(1.0 + a * a);
    f->height_mm = a * f->width_mm;
}

/* Granlund and Montgomery ("Division by invariant integers using multiplication", 1994,
   theorem 4.2): with 2^(l - 1) < d <= 2^l and m = ceil(2^(31 + l) / d), n / d is
   (n m) >> (31 + l) for every 0 <= n < 2^31. m <= 2^32, so n m < 2^63 fits. */
static void divisor_init(uint32_t d, uint64_t *multiplier, int *shift)
{
    int l = 0;
    while ((1ULL << l) < d)
        l++;
    *shift = 31 + l;
    *multiplier = ((1ULL << *shift) + d - 1) / d;
}

static uint32_t divide_by_gx(const sample_pattern *p, uint32_t n)
{
    return (uint32_t)(((uint64_t)n * p->gx_multiplier) >> p->gx_shift);
}

void sample_pattern_init(sample_pattern *p, int spp, uint64_t seed)
{
    int gx = 1;
    for (int d = 1; (long long)d * d <= spp; d++)
        if (spp % d == 0)
            gx = d;
    p->spp = spp;
    p->gx = spp / gx;
    p->gy = gx;
    p->seed = seed;
    divisor_init((uint32_t)p->gx, &p->gx_multiplier, &p->gx_shift);
    uint32_t w = (uint32_t)spp - 1;
    w |= w >> 1; w |= w >> 2; w |= w >> 4; w |= w >> 8; w |= w >> 16;
    p->permute_mask = w;
}

/* splitmix64's finaliser: a bijective, well-mixed hash of 64 bits. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* h >> 11 < 2^53 converts exactly; through int64_t it takes one instruction. */
static double unit_double(uint64_t h) { return (double)(int64_t)(h >> 11) * 0x1.0p-53; }

/* Kensler's permute(): a bijection of [0, n) chosen by key, by cycle-walking a hash on the
   next power of two (w: that power less one). */
static uint32_t permute(uint32_t i, uint32_t n, uint32_t w, uint32_t key)
{
    do {
        i ^= key; i *= 0xe170893d; i ^= key >> 16; i ^= (i & w) >> 4; i ^= key >> 8;
        i *= 0x0929eb3f; i ^= key >> 23; i ^= (i & w) >> 1; i *= 1 | key >> 27;
        i *= 0x6935fa69; i ^= (i & w) >> 11; i *= 0x74dcb303; i ^= (i & w) >> 2;
        i *= 0x9e501cc3; i ^= (i & w) >> 2; i *= 0xc860a3df; i &= w; i ^= i >> 5;
    } while (i >= n);
    return i;
}

sample_pixel sample_pattern_pixel(const sample_pattern *p, int px, int py)
{
    sample_pixel pixel;
    pixel.hash = mix64(p->seed ^ mix64(((uint64_t)(uint32_t)py << 32) | (uint32_t)px));
    return pixel;
}

film_sample sample_pattern_sample(const sample_pattern *p, sample_pixel pixel, int k)
{
    const uint64_t h1 = mix64(pixel.hash + 4 * (uint64_t)k + 1);
    const uint64_t h2 = mix64(pixel.hash + 4 * (uint64_t)k + 2);
    const uint32_t pk = permute((uint32_t)k, (uint32_t)p->spp, p->permute_mask, (uint32_t)pixel.hash);
    const uint32_t ky = divide_by_gx(p, (uint32_t)k), pky = divide_by_gx(p, pk);
    const uint32_t kx = (uint32_t)k - ky * (uint32_t)p->gx, pkx = pk - pky * (uint32_t)p->gx;
    film_sample s;
    s.offset_x = (kx + unit_double(h1)) / p->gx;
    s.offset_y = (ky + unit_double(mix64(h1))) / p->gy;
    s.pupil_u = (pkx + unit_double(h2)) / p->gx;
    s.pupil_v = (pky + unit_double(mix64(h2))) / p->gy;
    s.wavelength_nm = 0.0;
    return s;
}

film_sample sample_pattern_get(const sample_pattern *p, int px, int py, int k)
{
    return sample_pattern_sample(p, sample_pattern_pixel(p, px, py), k);
}

/* Hashes 4k + 1 and 4k + 2 give the pixel and pupil jitters; 4k + 3 the wavelength's. */
wavelength_sample sample_pattern_wavelength(const sample_pattern *p, sample_pixel pixel, int k)
{
    const uint32_t band = permute((uint32_t)k, (uint32_t)p->spp, p->permute_mask,
                                  (uint32_t)(pixel.hash >> 32));
    const double u = (band + unit_double(mix64(pixel.hash + 4 * (uint64_t)k + 3))) / p->spp;
    return (wavelength_sample){(int)band, spectrum_wavelength_nm(u)};
}

sample_pixel sample_pattern_shared(const sample_pattern *p)
{
    return (sample_pixel){mix64(p->seed ^ 0x5eedf1e1d0000000ULL)};
}
