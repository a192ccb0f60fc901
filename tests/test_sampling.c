/* The per-sample arithmetic made fast (the sample pattern without divisions, the pixel hash
   once per pixel, the pupil ring without hypot) against the plain formulas it replaces: every
   sample and every ring must be the same, bit for bit, or seeded renders would change. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "film.h"
#include "pupil.h"

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

/* ---- The pupil ring: as first written, hypot then fmin. */

static double ref_ring_radius_mm(const pupil *pu, vec3 p)
{
    const double r = hypot(p.x, p.y);
    int ring = pu->ring_width_mm > 0.0 ? (int)fmin(r / pu->ring_width_mm, PUPIL_RINGS - 1) : 0;
    return pu->ring_radius_mm[ring < 0 ? 0 : ring];
}

static pupil ringed_pupil(double ring_width_mm, double z_mm)
{
    pupil pu;
    memset(&pu, 0, sizeof pu);
    pu.kind = PUPIL_STOP_IMAGE;
    pu.z_mm = z_mm;
    pu.radius_mm = 1.0;
    pu.ring_width_mm = ring_width_mm;
    for (int i = 0; i < PUPIL_RINGS; i++)
        pu.ring_radius_mm[i] = 1.0 + i;    /* every ring its own radius */
    return pu;
}

/* The film ray as first written, from the public pieces. */
static double ref_film_ray(const pupil *pu, vec3 film_point, double u, double v, vec3 *direction)
{
    double dx, dy;
    concentric_disk(u, v, &dx, &dy);
    const double radius = ref_ring_radius_mm(pu, film_point);
    *direction = pupil_direction(pu, film_point, dx * radius, dy * radius);
    const double cos_theta = direction->z;
    const double area = M_PI * radius * radius;
    return area * (cos_theta * cos_theta) * (cos_theta * cos_theta) / (pu->z_mm * pu->z_mm);
}

/* The same bits, or both NaN (whose payload may follow the operand order the compiler picks). */
static bool same_double(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (isnan(a) && isnan(b));
}

static void check_point(const pupil *pu, vec3 p)
{
    const double want = ref_ring_radius_mm(pu, p), got = pupil_ring_radius_mm(pu, p);
    cr_assert(same_double(want, got), "width %a, point (%a, %a): ring radius %g, hypot gives %g",
              pu->ring_width_mm, p.x, p.y, got, want);
    vec3 want_d, got_d;
    const double want_w = ref_film_ray(pu, p, 0.3, 0.8, &want_d);
    const double got_w = pupil_film_ray(pu, p, 0.3, 0.8, &got_d);
    cr_assert(same_double(want_w, got_w) && same_double(want_d.x, got_d.x) &&
              same_double(want_d.y, got_d.y) && same_double(want_d.z, got_d.z),
              "width %a, point (%a, %a): film ray differs", pu->ring_width_mm, p.x, p.y);
}

/* Points on and a few ulps either side of every ring boundary, in several directions. */
static void check_boundaries(const pupil *pu)
{
    const double angles[] = {0.0, 0.1, M_PI / 4, 1.0, M_PI / 2, 2.5, M_PI, 4.0, 5.9};
    for (int ring = 0; ring <= PUPIL_RINGS + 1; ring++)
        for (size_t a = 0; a < sizeof angles / sizeof angles[0]; a++) {
            double r = ring * pu->ring_width_mm;
            for (int step = 0; step < 8; step++)
                r = nextafter(r, 0.0);
            for (int step = 0; step < 17; step++, r = nextafter(r, INFINITY))
                check_point(pu, v3(r * cos(angles[a]), r * sin(angles[a]), 0.0));
        }
}

Test(sampling, pupil_ring_matches_hypot_at_ring_boundaries)
{
    const double widths[] = {1.09375, 0.1, 1.0 / 3.0, 2.7, 1e-3, 1e3, 1e-200, 1e200};
    for (size_t i = 0; i < sizeof widths / sizeof widths[0]; i++) {
        const pupil pu = ringed_pupil(widths[i], i % 2 ? 25.0 : -12.0);
        check_boundaries(&pu);
    }
}

Test(sampling, pupil_ring_matches_hypot_everywhere_else)
{
    const double widths[] = {1.09375, 0.3, 0.0, -1.0, NAN, 5e-324, 1e-300, 1e300, INFINITY};
    const double odd[] = {0.0, -0.0, 5e-324, 1e-300, 1e-160, 1e-150, 1e150, 1e160, 1e300,
                          INFINITY, -INFINITY, NAN};
    for (size_t i = 0; i < sizeof widths / sizeof widths[0]; i++) {
        const pupil pu = ringed_pupil(widths[i], 40.0);
        uint64_t h = 42 + i;
        for (int n = 0; n < 20000; n++) {
            h = ref_mix64(h);
            const double x = 40.0 * (ref_unit_double(h) - 0.5), y = 40.0 * (ref_unit_double(ref_mix64(h)) - 0.5);
            check_point(&pu, v3(x, y, 0.0));
        }
        for (size_t a = 0; a < sizeof odd / sizeof odd[0]; a++)
            for (size_t b = 0; b < sizeof odd / sizeof odd[0]; b++)
                check_point(&pu, v3(odd[a], odd[b], 0.0));
    }
}

/* A batch through pupil_film_rays against ref_film_ray, the formula as first written
   (pupil_film_ray is now the batch of one, so it cannot serve as the reference), with the
   disk's centre, its diagonals and both halves of the map among the samples. */
Test(sampling, pupil_film_rays_match_one_at_a_time)
{
    enum { N = 64 };
    const double z_mm[] = {25.0, -12.0};
    for (int zi = 0; zi < 2; zi++) {
        const pupil pu = ringed_pupil(1.09375, z_mm[zi]);
        vec3 film[N], d[N];
        double u[N], v[N], w[N];
        uint64_t h = 7 + (uint64_t)zi;
        for (int k = 0; k < N; k++) {
            h = ref_mix64(h);
            film[k] = v3(30.0 * (ref_unit_double(h) - 0.5), 30.0 * (ref_unit_double(h >> 7) - 0.5), 0.0);
            u[k] = ref_unit_double(ref_mix64(h));
            v[k] = ref_unit_double(ref_mix64(h + 1));
        }
        u[0] = v[0] = 0.5;                  /* the centre */
        u[1] = v[1] = 0.25;                 /* a diagonal, |a| = |b| */
        u[2] = 0.0; v[2] = 1.0;
        pupil_film_rays(&pu, N, film, u, v, d, w);
        for (int k = 0; k < N; k++) {
            vec3 d1;
            const double w1 = ref_film_ray(&pu, film[k], u[k], v[k], &d1);
            cr_assert(same_double(w[k], w1) && same_double(d[k].x, d1.x) &&
                      same_double(d[k].y, d1.y) && same_double(d[k].z, d1.z),
                      "z %g, sample %d: the batch differs from the single ray", z_mm[zi], k);
        }
    }
}
