/* Every pixel of a field render sees the same N shared pupil points. On the axis the passing
   region is a disk, but the stop-image pupil samples a larger one: the fit's last growth
   (PUPIL_FIT_MARGIN) and, with dispersion, the growth that holds every wavelength's region. So
   the M points beyond the passing disk are blocked at every pixel near the axis at once, and
   the plain estimate (1 / N) sum f there is (N - M) / (N s) times the truth, s the disk's share
   of the pupil: the whole picture a few percent too bright or too dark, by seed.

   Post-stratified over the core, the disk that passes on the axis (radius c(lambda) on the
   unit disk, measured here), and the ring around it (Owen, "Monte Carlo theory, methods and
   examples", 2013, section 8.4), the estimate is s mean_core f + (1 - s) mean_ring f: a core
   sample is weighted by N s / (N - M), a ring sample by N (1 - s) / M, and the axis is exposed
   right for every seed. With M = 0 the ring's light is left out: none on the axis, a little off
   it (docs/fields.md measures it). */
#include "field/strata.h"

#include <math.h>
#include <stdlib.h>
#include "field/subimage.h"
#include "optics/spectrum.h"

static double strata_nm(int i)
{
    return SPECTRUM_MIN_NM + i * (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) / (FIELD_STRATA_WAVELENGTHS - 1);
}

/* Whether the film's centre passes the pupil sample at radius r on the unit disk's x axis. */
static bool axis_passes(const camera *c, double r, double nm, sample_batch *b)
{
    b->n = 1;
    b->film_point[0] = v3(0.0, 0.0, 0.0);
    b->u[0] = 0.5 * (r + 1.0), b->v[0] = 0.5;
    b->wavelength_nm[0] = nm;
    camera_trace_batch(c, b);
    return b->passed[0];
}

/* c(nm): the passing disk's radius on the unit disk, bisected to 1e-12; 0 when the axis's own
   ray is blocked (a central obstruction), 1 when the whole disk passes. */
static double core_radius_at(const camera *c, double nm, sample_batch *b)
{
    if (!axis_passes(c, 0.0, nm, b))
        return 0.0;
    if (axis_passes(c, 1.0, nm, b))
        return 1.0;
    double in = 0.0, out = 1.0;
    for (int i = 0; i < 40; i++) {
        const double mid = 0.5 * (in + out);
        *(axis_passes(c, mid, nm, b) ? &in : &out) = mid;
    }
    return in;
}

/* The core's share: c^2 averaged over the wavelengths' sampling density, lambda = P^-1(u) for
   u uniform (spectrum.h), by the midpoint rule; c^2 without dispersion. */
static double core_share(const field_strata *t, const camera *c)
{
    if (!c->dispersion)
        return t->core_radius[0] * t->core_radius[0];
    enum { STEPS = 4096 };
    double sum = 0.0;
    for (int i = 0; i < STEPS; i++) {
        const double r = field_strata_core_radius(t, spectrum_wavelength_nm((i + 0.5) / STEPS));
        sum += r * r;
    }
    return sum / STEPS;
}

void field_strata_count(const camera *c, field_strata *out)
{
    *out = (field_strata){.on = false, .core_share = 1.0, .core_scale = 1.0, .ring_scale = 1.0};
    sample_batch *b = malloc(sizeof *b);
    /* other pupils sample the passing region loosely (rear) or not at all (stop, thick) */
    if (!b || c->pupil.kind != PUPIL_STOP_IMAGE || !pupil_is_fitted(&c->pupil)) {
        free(b);
        return;
    }
    /* without dispersion every sample is traced at the d line: one radius serves */
    const double d_line = c->dispersion ? 0.0 : core_radius_at(c, 0.0, b);
    bool usable = true;
    for (int i = 0; i < FIELD_STRATA_WAVELENGTHS; i++) {
        out->core_radius[i] = c->dispersion ? core_radius_at(c, strata_nm(i), b) : d_line;
        usable = usable && out->core_radius[i] > 0.0;
    }
    free(b);
    const int n = c->samples.spp;
    int ring = 0;
    for (int k = 0; k < n && usable; k++)
        ring += field_strata_in_ring(out, field_shared_sample(c, k, NULL));
    if (!usable || ring == n)   /* no core on the axis, or no sample in it: plain */
        return;
    out->on = true;
    out->core_share = core_share(out, c);
    out->core_scale = n * out->core_share / (n - ring);
    if (ring > 0)
        out->ring_scale = n * (1.0 - out->core_share) / ring;
}

double field_strata_core_radius(const field_strata *t, double nm)
{
    const double x = (nm - SPECTRUM_MIN_NM) / (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) * (FIELD_STRATA_WAVELENGTHS - 1);
    if (!(x > 0.0))
        return t->core_radius[0];
    if (!(x < FIELD_STRATA_WAVELENGTHS - 1))
        return t->core_radius[FIELD_STRATA_WAVELENGTHS - 1];
    const int i = (int)x;
    return t->core_radius[i] + (x - i) * (t->core_radius[i + 1] - t->core_radius[i]);
}

bool field_strata_in_ring(const field_strata *t, film_sample s)
{
    return pupil_disk_radius(s.pupil_u, s.pupil_v) > field_strata_core_radius(t, s.wavelength_nm);
}

double field_strata_scale(const field_strata *t, film_sample s)
{
    if (!t->on)
        return 1.0;
    return field_strata_in_ring(t, s) ? t->ring_scale : t->core_scale;
}
