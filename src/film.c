#include "film.h"

void film_init(film *f, int width, int height, double diagonal_mm)
{
    const double a = (double)height / (double)width;
    f->width = width;
    f->height = height;
    f->diagonal_mm = diagonal_mm;
    f->width_mm = diagonal_mm / sqrt(1.0 + a * a);
    f->height_mm = a * f->width_mm;
}

vec3 film_camera_from_raster(const film *f, double rx, double ry)
{
    return v3((0.5 - rx / f->width) * f->width_mm, (ry / f->height - 0.5) * f->height_mm, 0.0);
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
}

/* splitmix64's finaliser: a bijective, well-mixed hash of 64 bits. */
static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static double unit_double(uint64_t h) { return (double)(h >> 11) * 0x1.0p-53; }

/* Kensler's permute(): a bijection of [0, n) chosen by key, by cycle-walking a hash on the
   next power of two. */
static uint32_t permute(uint32_t i, uint32_t n, uint32_t key)
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

film_sample sample_pattern_get(const sample_pattern *p, int px, int py, int k)
{
    const uint64_t pixel = mix64(p->seed ^ mix64(((uint64_t)(uint32_t)py << 32) | (uint32_t)px));
    const uint64_t h1 = mix64(pixel + 4 * (uint64_t)k + 1), h2 = mix64(pixel + 4 * (uint64_t)k + 2);
    const uint32_t pk = permute((uint32_t)k, (uint32_t)p->spp, (uint32_t)pixel);
    film_sample s;
    s.offset_x = ((k % p->gx) + unit_double(h1)) / p->gx;
    s.offset_y = ((k / p->gx) + unit_double(mix64(h1))) / p->gy;
    s.pupil_u = ((pk % p->gx) + unit_double(h2)) / p->gx;
    s.pupil_v = ((pk / p->gx) + unit_double(mix64(h2))) / p->gy;
    return s;
}
