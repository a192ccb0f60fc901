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

/* Rays 0 .. n-1 of b, n a multiple of LANES, surfaces last .. first. The surface loop is the
   outer one: the steps of one surface are independent and the processor overlaps them. */
LANES_ENTRY(const lens *l, trace_batch *b, int n)
{
    unsigned alive[TRACE_BATCH_MAX / LANES];
    for (int g = 0; g < n / LANES; g++) {
        alive[g] = 0;
        for (int i = 0; i < LANES; i++)
            alive[g] |= (unsigned)(b->status[g * LANES + i] == TRACE_PASSED) << i;
    }
    for (int i = l->count - 1; i >= 0; i--) {
        const double a = lens_semi_aperture_mm(l, i);
        const double eta = lens_ior_behind(l, i) / lens_ior_front(l, i);
        for (int g = 0; g < n / LANES; g++) {
            if (!alive[g])
                continue;
            const int k = g * LANES;
            vreal o[3] = {load(b->ox + k), load(b->oy + k), load(b->oz + k)};
            vreal d[3] = {load(b->dx + k), load(b->dy + k), load(b->dz + k)};
            alive[g] = cross(&l->surface[i], a * a, lens_blades_of(l, i), eta, o, d, b->status + k,
                             alive[g]);
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
