/* The full simulation for many rays at once, in structure-of-arrays form and without branches
   inside the loop over rays: one ray's work is a long chain of divisions and square roots, and
   only independent rays side by side keep the processor busy. Same formulas, in the same
   order, as trace_kernel.h (tests/test_trace.c checks they agree bit for bit). */
#include "trace_batch.h"

#include <float.h>

static inline double dmax(double a, double b) { return a > b ? a : b; }

/* Valid root: ahead of the ray (counting the transfer t0), finite, and on the vertex cap.
   Bitwise & rather than &&: no branches, so the loop vectorizes. */
static inline long long root_ok(double t0, double t, double pz, double dz, double c)
{
    return (t0 + t >= 0) & (fabs(t) <= DBL_MAX) & (1 + c * (pz + t * dz) >= 0);
}

static void cross_surface(const lens *l, int i, double eta, trace_soa *b, int n)
{
    const lens_surface *s = &l->surface[i];
    const double c = s->curvature_per_mm, R = s->radius_mm, zv = s->vertex_z_mm;
    const double a = lens_semi_aperture_mm(l, i), a2 = a * a;
    const double far_scale = c != 0 ? R : NAN;
    const long long refracts = eta != 1;
    for (int k = 0; k < n; k++) {
        const double dx = b->dx[k], dy = b->dy[k], dz = b->dz[k];
        const long long transfer = fabs(dz) > 1e-6;
        const double pz0 = b->oz[k] - zv;
        const double t0 = transfer ? -pz0 / dz : 0;
        const double px = b->ox[k] + t0 * dx, py = b->oy[k] + t0 * dy, pz = transfer ? 0 : pz0;
        const double B = c * (px * dx + py * dy + pz * dz) + dz;
        const double C = c * (px * px + py * py + pz * pz) + 2 * pz;
        const double disc = B * B - c * C;
        const double q = -(B + copysign(sqrt(dmax(disc, 0)), B));
        const double near = q != 0 ? C / q : NAN, far = q * far_scale;
        const double lo = far < near ? far : near, hi = far < near ? near : far;
        const long long lo_ok = root_ok(t0, lo, pz, dz, c), hi_ok = root_ok(t0, hi, pz, dz, c);
        const double t = lo_ok ? lo : hi;
        const double hx = px + t * dx, hy = py + t * dy, hz = pz + t * dz;
        const long long hit = (disc >= 0) & (lo_ok | hi_ok);
        const long long inside = hx * hx + hy * hy <= a2;
        /* Refraction at the normal (c hx, c hy, 1 + c hz), oriented against the ray. */
        const double nx0 = c * hx, ny0 = c * hy, nz0 = 1 + c * hz;
        const double cos_i0 = -(nx0 * dx + ny0 * dy + nz0 * dz);
        const double flip = cos_i0 < 0 ? -1 : 1;
        const double nx = nx0 * flip, ny = ny0 * flip, nz = nz0 * flip, cos_i = cos_i0 * flip;
        const double sin2_t = eta * eta * (1 - cos_i * cos_i);
        const double cos_t = sqrt(dmax(1 - sin2_t, 0));
        const double kk = eta * cos_i - cos_t;
        const long long tir = refracts & (sin2_t > 1);
        const long long alive = b->status[k] == TRACE_PASSED;
        const long long ok = alive & hit & inside & !tir;
        const long long why = !hit ? TRACE_MISSED : !inside ? TRACE_CLIPPED : tir ? TRACE_TIR : TRACE_PASSED;
        b->status[k] = alive ? why : b->status[k];
        const long long bend = ok & refracts;
        b->ox[k] = ok ? hx : b->ox[k];
        b->oy[k] = ok ? hy : b->oy[k];
        b->oz[k] = ok ? hz + zv : b->oz[k];
        b->dx[k] = bend ? eta * dx + kk * nx : dx;
        b->dy[k] = bend ? eta * dy + kk * ny : dy;
        b->dz[k] = bend ? eta * dz + kk * nz : dz;
    }
}

void trace_soa_toward_scene(const lens *l, trace_soa *b, int n)
{
    for (int i = l->count - 1; i >= 0; i--)
        cross_surface(l, i, lens_ior_behind(l, i) / lens_ior_front(l, i), b, n);
    for (int k = 0; k < n; k++) {
        const double inv = 1 / sqrt(b->dx[k] * b->dx[k] + b->dy[k] * b->dy[k] + b->dz[k] * b->dz[k]);
        b->dx[k] *= inv;
        b->dy[k] *= inv;
        b->dz[k] *= inv;
    }
}
