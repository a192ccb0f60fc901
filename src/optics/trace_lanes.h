/* The full simulation over lanes of rays side by side: trace_kernel.h over vector registers,
   driven over a batch (trace_batch). One ray alone is a chain of divisions and square roots,
   each waiting on the one before; independent rays side by side keep the processor busy.

   The includer (one file per instruction set) defines trace_kernel.h's operations over
   LANES doubles, load and store of LANES doubles, and names the entry point with
   LANES_ENTRY. */

_Static_assert(TRACE_BATCH_MAX % LANES == 0, "a batch is whole steps");

typedef double real;
#define REAL_MAX DBL_MAX
#include "optics/trace_kernel.h"

/* The media either side of a surface as n = a + b x (lens_cauchy), x = 1 / lambda^2. */
typedef struct media {
    bool disperses;            /* either medium does; else eta is one number */
    double eta;                /* n1 / n2 toward the scene from the file's indices */
    double a_film, b_film, a_scene, b_scene;
} media;

static media media_of(const lens *l, int i)
{
    media m = {.a_scene = 1.0, .b_scene = 0.0};
    lens_cauchy(&l->surface[i], &m.a_film, &m.b_film);
    if (i > 0)
        lens_cauchy(&l->surface[i - 1], &m.a_scene, &m.b_scene);
    m.disperses = m.b_film != 0 || m.b_scene != 0;
    m.eta = lens_ior_behind(l, i) / lens_ior_front(l, i);
    return m;
}

/* Each lane's eta for the step at k; whether the surface refracts at all. Without wavelengths
   (x NULL), or where neither medium disperses, one eta for every lane. */
INLINE bool eta_of(const media *m, const double *x, int k, vreal *eta)
{
    if (!x || !m->disperses) {
        *eta = splat(m->eta);
        return m->eta != 1;
    }
    const vreal xk = load(x + k);
    *eta = divide(index_at(m->a_film, m->b_film, xk), index_at(m->a_scene, m->b_scene, xk));
    return true;
}

/* Rays 0 .. n-1 of b, n a multiple of LANES, surfaces last .. first; x, when not NULL, gives
   each ray's 1 / lambda^2 (nm^-2) for the indices. The surface loop is the outer one: the
   steps of one surface are independent and the processor overlaps them. */
LANES_ENTRY(const lens *l, trace_batch *b, int n, const double *x)
{
    unsigned alive[TRACE_BATCH_MAX / LANES];
    for (int g = 0; g < n / LANES; g++) {
        alive[g] = 0;
        for (int i = 0; i < LANES; i++)
            alive[g] |= (unsigned)(b->status[g * LANES + i] == TRACE_PASSED) << i;
    }
    for (int i = l->count - 1; i >= 0; i--) {
        const double a = lens_semi_aperture_mm(l, i);
        const media m = media_of(l, i);
        for (int g = 0; g < n / LANES; g++) {
            if (!alive[g])
                continue;
            const int k = g * LANES;
            vreal eta;
            const bool refracts = eta_of(&m, x, k, &eta);
            vreal o[3] = {load(b->ox + k), load(b->oy + k), load(b->oz + k)};
            vreal d[3] = {load(b->dx + k), load(b->dy + k), load(b->dz + k)};
            alive[g] = cross(&l->surface[i], a * a, lens_blades_of(l, i), refracts, eta, o, d,
                             b->status + k, alive[g]);
            store(b->ox + k, o[0]);
            store(b->oy + k, o[1]);
            store(b->oz + k, o[2]);
            store(b->dx + k, d[0]);
            store(b->dy + k, d[1]);
            store(b->dz + k, d[2]);
        }
    }
    for (int k = 0; k < n; k += LANES) {
        vreal d[3] = {load(b->dx + k), load(b->dy + k), load(b->dz + k)};
        renormalize(d);
        store(b->dx + k, d[0]);
        store(b->dy + k, d[1]);
        store(b->dz + k, d[2]);
    }
}
