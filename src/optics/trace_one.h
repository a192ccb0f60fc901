/* The full simulation of one ray: trace_kernel.h with one lane, its operations plain C over a
   number type. It builds the double-precision tracer (trace.c) and a long double reference
   (tests/precision_trace.c). The includer defines:
     KREAL, KREAL_MAX  the number type and its largest finite value
     KVEC, KRAY        struct types {KREAL x, y, z;} and {KVEC o, d;}
     KNAME(f)          the name of function f in this build
   <tgmath.h> picks sqrt, fabs and copysign of the right precision. */
#include <stdbool.h>
#include <tgmath.h>

#define LANES 1
#define REAL_MAX KREAL_MAX
#define INLINE static inline __attribute__((always_inline))
typedef KREAL real;
typedef KREAL vreal;
typedef bool vmask;

INLINE vreal add(vreal a, vreal b) { return a + b; }
INLINE vreal sub(vreal a, vreal b) { return a - b; }
INLINE vreal mul(vreal a, vreal b) { return a * b; }
INLINE vreal divide(vreal a, vreal b) { return a / b; }
INLINE vreal vmax(vreal a, vreal b) { return a > b ? a : b; }
INLINE vreal vsqrt(vreal a) { return sqrt(a); }
INLINE vreal splat(real a) { return a; }
INLINE vmask lt(vreal a, vreal b) { return a < b; }
INLINE vmask le(vreal a, vreal b) { return a <= b; }
INLINE vmask gt(vreal a, vreal b) { return a > b; }
INLINE vmask ge(vreal a, vreal b) { return a >= b; }
INLINE vmask ne(vreal a, vreal b) { return a != b; }
INLINE vmask mand(vmask a, vmask b) { return a & b; }
INLINE vmask mor(vmask a, vmask b) { return a | b; }
INLINE unsigned bits(vmask m) { return m; }
INLINE vmask mask_of(unsigned lanes) { return lanes & 1; }
INLINE vreal pick(vmask m, vreal a, vreal b) { return m ? a : b; }
INLINE vreal vabs(vreal a) { return fabs(a); }
INLINE vreal vcopysign(vreal a, vreal b) { return copysign(a, b); }
INLINE vreal neg(vreal a) { return -a; }

#include "optics/trace_kernel.h"

/* Surface s alone: r moves to the surface, with the normal there; r is unchanged on a miss. */
static trace_status KNAME(intersect)(const lens_surface *s, KRAY *r, KVEC *normal)
{
    const vreal o[3] = {r->o.x, r->o.y, r->o.z}, d[3] = {r->d.x, r->d.y, r->d.z};
    vreal h[3], n[3];
    if (!intersect(s, o, d, h))
        return TRACE_MISSED;
    normal_at(s, h, n);
    r->o.x = h[0];
    r->o.y = h[1];
    r->o.z = h[2] + (real)s->vertex_z_mm;
    normal->x = n[0];
    normal->y = n[1];
    normal->z = n[2];
    return TRACE_PASSED;
}

/* Refraction alone, from index n1 to n2: d is unchanged unless it passes. */
static trace_status KNAME(refract)(KVEC n, KREAL n1, KREAL n2, KVEC *d)
{
    const real eta = n1 / n2;
    if (eta == 1)
        return TRACE_PASSED;
    const vreal nn[3] = {n.x, n.y, n.z}, dd[3] = {d->x, d->y, d->z};
    vreal e[3];
    vmask tir, grazing;
    refract(nn, eta, dd, e, &tir, &grazing);
    if (tir)
        return TRACE_TIR;
    if (grazing)
        return TRACE_GRAZING;
    d->x = e[0];
    d->y = e[1];
    d->z = e[2];
    return TRACE_PASSED;
}

/* Surfaces last .. first toward the scene (+z), or first .. last toward the film, with the
   indices at this wavelength (nm; 0: the file's n_d). A blocked ray stays on the last surface
   it crossed. */
static trace_status KNAME(through)(const lens *l, int first, int last, bool toward_scene,
                                   double wavelength_nm, KRAY *r, int *blocked_at)
{
    vreal o[3] = {r->o.x, r->o.y, r->o.z}, d[3] = {r->d.x, r->d.y, r->d.z};
    long long status = TRACE_PASSED;
    const int step = toward_scene ? -1 : 1;
    for (int i = toward_scene ? last : first; i >= first && i <= last; i += step) {
        real front = lens_ior_front(l, i), behind = lens_ior_behind(l, i);
        if (wavelength_nm > 0) {
            front = i == 0 ? 1.0 : lens_index_at(&l->surface[i - 1], wavelength_nm);
            behind = lens_index_at(&l->surface[i], wavelength_nm);
        }
        const real a = lens_semi_aperture_mm(l, i), eta = toward_scene ? behind / front : front / behind;
        if (!cross(&l->surface[i], a * a, lens_blades_of(l, i), eta != 1, eta, o, d, &status, 1)) {
            if (blocked_at)
                *blocked_at = i;
            break;
        }
    }
    if (status == TRACE_PASSED)
        renormalize(d);
    r->o.x = o[0];
    r->o.y = o[1];
    r->o.z = o[2];
    r->d.x = d[0];
    r->d.y = d[1];
    r->d.z = d[2];
    return (trace_status)status;
}
