/* Every pixel of a field render sees the same N shared pupil points. On the axis the passing
   region is a disk, but the pupil samples a larger one: the rear pupil's disk holds the rear
   rim, the stop-image pupil's has the fit's last growth (PUPIL_FIT_MARGIN), and with
   dispersion both grow to hold every wavelength's region. A point beyond the passing disk is
   blocked at every pixel near the axis at once, so with the plain estimate (1 / N) sum f the
   whole picture came out (N - M) / (N s) of the truth, M the points the seed put there and s
   the disk's share of the pupil: a few percent off, by seed.

   So the shared points are stratified (Owen, "Monte Carlo theory, methods and examples", 2013,
   section 8.4) over the core, the disk that passes on the axis (radius c(lambda) on the unit
   disk, measured here), and the ring around it. The stratum comes from pupil_u alone: a
   shared sample with pupil_u >= 1 - q goes to the ring. In the first P = 2^m samples each
   interval of width 2^-m holds one pupil_u (sobol.h), so with q = k / P exactly k of them go
   to the ring, whatever the seed. A sample is then placed uniformly in its stratum by the
   equal-area polar map, r^2 = c^2 u / (1 - q) in the core and c^2 + (1 - c^2) (u - 1 + q) / q
   in the ring, phi = 2 pi pupil_v, which keeps the Sobol points' stratification in
   (r^2, phi). With K of the N samples in the core, a core sample's weight is multiplied by
   N c^2 / K and a ring sample's by N (1 - c^2) / (N - K): each stratum's mean times its share
   of the disk. The axis is then exposed right for every seed, and off it the estimate is
   unbiased, but for the fit margin's sliver of light when the ring gets no sample
   (ring_samples).

   With blades the region that passes on the axis is the blades' polygon (its image), no disk
   about the axis. The samples are then post-stratified (Owen, section 8.9): left where they
   are, split by whether they pass on the axis (K of N), and weighted N a / K and
   N (1 - a) / (N - K), a the passing share of the unit disk, (1 / 2 pi) times the integral of
   R(phi)^2 over the directions, R the passing radius bisected in each. Given K each stratum's
   samples are uniform in it, so the estimate stays unbiased, and the axis is exposed right
   for every seed. Only for a whole render's samples: adaptive sampling's later blocks would
   need their own K. */
#include "field/fieldpixels.h"
#include "field/strata.h"

#include <math.h>
#include <stdlib.h>
#include "optics/spectrum.h"

static double strata_nm(int i)
{
    return SPECTRUM_MIN_NM + i * (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) / (FIELD_STRATA_WAVELENGTHS - 1);
}

/* A value measured at the strata's wavelengths, interpolated linearly at nm. */
static double interpolate(const double at[FIELD_STRATA_WAVELENGTHS], double nm)
{
    const double x = (nm - SPECTRUM_MIN_NM) / (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) * (FIELD_STRATA_WAVELENGTHS - 1);
    if (!(x > 0.0))
        return at[0];
    if (!(x < FIELD_STRATA_WAVELENGTHS - 1))
        return at[FIELD_STRATA_WAVELENGTHS - 1];
    const int i = (int)x;
    return at[i] + (x - i) * (at[i + 1] - at[i]);
}

/* Directions over which the passing share of the disk on the axis is integrated. */
enum { AXIS_DIRECTIONS = 512 };

/* Whether the film's centre passes pupil sample (u, v) of the unit square at wavelength nm. */
static bool passes_at_centre(const camera *c, double u, double v, double nm, sample_batch *b)
{
    b->n = 1;
    b->film_point[0] = v3(0.0, 0.0, 0.0);
    b->u[0] = u, b->v[0] = v;
    b->wavelength_nm[0] = nm;
    camera_trace_batch(c, b);
    return b->passed[0];
}

/* Whether it passes the pupil sample at radius r on the unit disk's x axis. */
static bool axis_passes(const camera *c, double r, double nm, sample_batch *b)
{
    return passes_at_centre(c, 0.5 * (r + 1.0), 0.5, nm, b);
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

/* The share of the unit disk that passes on the axis at nm: (1 / 2 pi) times the integral of
   R(phi)^2 by the midpoint rule, R bisected to 2^-30 in each direction, the directions side by
   side in the batch; 0 when the axis's own ray is blocked. */
static double axis_share_at(const camera *c, double nm, sample_batch *b)
{
    if (!axis_passes(c, 0.0, nm, b))
        return 0.0;
    double sum = 0.0;
    for (int first = 0; first < AXIS_DIRECTIONS; first += CAMERA_BATCH) {
        const int n = AXIS_DIRECTIONS - first < CAMERA_BATCH ? AXIS_DIRECTIONS - first : CAMERA_BATCH;
        double in[CAMERA_BATCH], out[CAMERA_BATCH];
        for (int k = 0; k < n; k++)
            in[k] = 0.0, out[k] = 1.0 + 1e-9;   /* the rim itself may pass */
        for (int step = 0; step < 30; step++) {
            b->n = n;
            for (int k = 0; k < n; k++) {
                const double phi = 2.0 * M_PI * (first + k + 0.5) / AXIS_DIRECTIONS;
                const double r = fmin(1.0, 0.5 * (in[k] + out[k]));
                b->film_point[k] = v3(0.0, 0.0, 0.0);
                pupil_square_of_disk(r * cos(phi), r * sin(phi), &b->u[k], &b->v[k]);
                b->wavelength_nm[k] = nm;
            }
            camera_trace_batch(c, b);
            for (int k = 0; k < n; k++)
                *(b->passed[k] ? &in[k] : &out[k]) = 0.5 * (in[k] + out[k]);
        }
        for (int k = 0; k < n; k++)
            sum += fmin(1.0, in[k]) * fmin(1.0, in[k]);
    }
    return sum / AXIS_DIRECTIONS;
}

/* Whether shared sample s passes on the axis. */
static bool passes_on_axis(const camera *c, film_sample s, sample_batch *b)
{
    return passes_at_centre(c, s.pupil_u, s.pupil_v, s.wavelength_nm, b);
}

/* The share of a stratum averaged over the wavelengths' sampling density, lambda = P^-1(u) for
   u uniform (spectrum.h), by the midpoint rule; the d line's without dispersion. */
static double mean_over_spectrum(const double *at, const camera *c)
{
    if (!c->dispersion)
        return at[0];
    enum { STEPS = 4096 };
    double sum = 0.0;
    for (int i = 0; i < STEPS; i++)
        sum += interpolate(at, spectrum_wavelength_nm((i + 0.5) / STEPS));
    return sum / STEPS;
}

/* Post-stratification with blades (above): the passing share on the axis and the samples'
   count there; off when either stratum would be empty. */
static void post_count(const camera *c, int n, sample_batch *b, field_strata *out)
{
    double share[FIELD_STRATA_WAVELENGTHS];
    const double d_line = c->dispersion ? 0.0 : axis_share_at(c, 0.0, b);
    for (int i = 0; i < FIELD_STRATA_WAVELENGTHS; i++)
        share[i] = c->dispersion ? axis_share_at(c, strata_nm(i), b) : d_line;
    int passing = 0;
    for (int k = 0; k < n; k++)
        passing += passes_on_axis(c, field_shared_sample(c, k, NULL), b);
    out->axis_share = mean_over_spectrum(share, c);
    out->axis_count = passing;
    out->camera = c;
    /* K = N: every sample carries a (the others' stratum is empty, its light on the axis
       none). K = 0 leaves nothing to carry the axis's light: the plain weights then. */
    out->post = passing > 0 && out->axis_share > 0.0 && out->axis_share < 1.0;
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

/* k: the ring's share of the first P samples, in proportion to its share of the disk and
   leaving the core one at least. The ring of a stop-image pupil at one wavelength is only the
   fit's margin around the region's own shape, which passes almost nothing (docs/fields.md),
   and rounds to none below 64 samples. Elsewhere it gets one at least: with dispersion it holds
   what the other wavelengths pass, and the rear pupil's disk about the axis holds the regions
   off it. */
static int ring_samples(int p, double share, bool margin_only)
{
    const long k = lround(p * (1.0 - share));
    const long least = margin_only ? 0 : 1;
    return (int)(k < least ? least : k > p - 1 ? p - 1 : k);
}

void field_strata_count(const camera *c, int samples, field_strata *out)
{
    *out = (field_strata){.on = false};
    sample_batch *b = malloc(sizeof *b);
    /* the stop pupil and thick tracing fit no region (every sample passes the axis or none
       is known to); one sample cannot be split */
    const int n = samples;
    const bool fitted = (c->pupil.kind == PUPIL_STOP_IMAGE || c->pupil.kind == PUPIL_REAR) &&
                        pupil_is_fitted(&c->pupil);
    if (!b || !fitted || n < 2) {
        free(b);
        return;
    }
    if (c->lens.blades.count > 0 && n == c->samples.spp) {
        post_count(c, n, b, out);
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
    const double share = usable ? core_share(out, c) : 0.0;
    /* no core on the axis (a central obstruction), or no ring (the whole disk passes) */
    if (!usable || !(share < 1.0))
        return;
    int p = 1;
    while (p <= n / 2)
        p *= 2;
    const bool margin_only = c->pupil.kind == PUPIL_STOP_IMAGE && !c->dispersion;
    out->ring_from = 1.0 - (double)ring_samples(p, share, margin_only) / p;
    for (int k = 0; k < n; k++)
        out->ring_count += field_shared_sample(c, k, NULL).pupil_u >= out->ring_from;
    out->core_count = n - out->ring_count;
    out->on = out->core_count > 0;   /* always, by the above */
}

double field_strata_core_radius(const field_strata *t, double nm)
{
    return interpolate(t->core_radius, nm);
}

bool field_strata_in_ring(const field_strata *t, film_sample s)
{
    return t->on && s.pupil_u >= t->ring_from;
}

double field_strata_place(const field_strata *t, film_sample *s)
{
    if (t->post) {
        sample_batch b;   /* one sample: on the stack, no failure to handle */
        const int n = t->camera->samples.spp, k = t->axis_count;
        return passes_on_axis(t->camera, *s, &b) ? n * t->axis_share / k
               : k < n                           ? n * (1.0 - t->axis_share) / (n - k)
                                                 : 1.0;   /* none such, but a ray's doubt */
    }
    if (!t->on)
        return 1.0;
    const double c = field_strata_core_radius(t, s->wavelength_nm), core = c * c;
    const bool ring = field_strata_in_ring(t, *s);
    const double r2 = ring ? core + (1.0 - core) * (s->pupil_u - t->ring_from) / (1.0 - t->ring_from)
                           : core * s->pupil_u / t->ring_from;
    const double r = sqrt(r2), phi = 2.0 * M_PI * s->pupil_v;
    pupil_square_of_disk(r * cos(phi), r * sin(phi), &s->pupil_u, &s->pupil_v);
    const int n = t->core_count + t->ring_count;
    return ring ? n * (1.0 - core) / t->ring_count : n * core / t->core_count;
}
