/* Owen-scrambled Sobol points in four dimensions. */
#include "field/sobol.h"

/* Direction numbers: dimension 0 is the van der Corput sequence (m_k = 1); dimensions 1..3
   use the primitive polynomials and initial m values of Joe and Kuo's new-joe-kuo-6.21201
   table (d = 2: s 1, a 0, m 1; d = 3: s 2, a 1, m 1 3; d = 4: s 3, a 1, m 1 3 1). */
typedef struct sobol_dim { int s; uint32_t a; uint32_t m[3]; } sobol_dim;
static const sobol_dim DIMS[3] = {{1, 0, {1, 0, 0}}, {2, 1, {1, 3, 0}}, {3, 1, {1, 3, 1}}};

/* v_k = m_k 2^(32-k); beyond s, Bratley and Fox's recurrence
   v_k = v_{k-s} ^ (v_{k-s} >> s) ^ sum_j a_j v_{k-j} (a_j the polynomial's inner bits). */
static void directions(int dim, uint32_t v[32])
{
    if (dim == 0) {
        for (int k = 0; k < 32; k++)
            v[k] = 1u << (31 - k);
        return;
    }
    const sobol_dim *d = &DIMS[dim - 1];
    for (int k = 0; k < d->s; k++)
        v[k] = d->m[k] << (31 - k);
    for (int k = d->s; k < 32; k++) {
        uint32_t x = v[k - d->s] ^ (v[k - d->s] >> d->s);
        for (int j = 1; j < d->s; j++)
            if ((d->a >> (d->s - 1 - j)) & 1)
                x ^= v[k - j];
        v[k] = x;
    }
}

uint32_t sobol_bits(uint32_t index, int dim)
{
    uint32_t v[32], x = 0;
    directions(dim, v);
    for (int k = 0; index; k++, index >>= 1)
        if (index & 1)
            x ^= v[k];
    return x;
}

static uint32_t reverse_bits(uint32_t x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/* Burley's Laine-Karras-style hash: each bit is flipped by a function of the bits below it
   only (additions and multiplications by even constants carry upward), so on the reversed
   fraction it flips each digit by a function of the digits above it: a nested uniform
   scramble. */
static uint32_t laine_karras(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

uint32_t sobol_owen_scramble(uint32_t x, uint32_t seed)
{
    return reverse_bits(laine_karras(reverse_bits(x), seed));
}

static uint32_t hash32(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return (uint32_t)((z ^ (z >> 31)) >> 32);
}

/* A fraction in [0, 1): the top 24 bits, so that the float32 of the sample map keeps it. */
static double unit(uint32_t x) { return (double)(x >> 8) * 0x1.0p-24; }

film_sample sobol_shared_sample(uint64_t seed, uint32_t k)
{
    double t[4];
    for (int dim = 0; dim < 4; dim++) {
        uint32_t s = hash32(seed * 4 + (uint64_t)dim + 0x9e3779b97f4a7c15ULL);
        t[dim] = unit(sobol_owen_scramble(sobol_bits(k, dim), s));
    }
    return (film_sample){t[0], t[1], t[2], t[3], 0.0};
}
