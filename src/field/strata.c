/* Every pixel of a field render sees the same N shared pupil points. The fitted pupil is its
   region grown by PUPIL_FIT_MARGIN, so the M points that land in the margin ring are blocked
   at every pixel near the axis at once, and the plain estimate (1 / N) sum f there is
   (N - M) / (N (1 - e)) times the truth, e = 1 - 1 / g^2 the ring's share of the disk: the
   whole picture a few percent too bright or too dark, by seed. Post-stratified over the core
   and the ring (Owen, "Monte Carlo theory, methods and examples", 2013, section 8.4), the
   estimate is (1 - e) mean_core f + e mean_ring f: a core sample is weighted by
   N (1 - e) / (N - M) and a ring sample by N e / M. With M = 0 the ring's light is left out:
   none on the axis, and off it what the fit's last growth holds (docs/fields.md). With
   dispersion the pupil is grown to hold every wavelength's region as well, so on the axis part
   of the core is blocked too, by wavelength: the plain estimate stays. */
#include "field/strata.h"

#include "field/subimage.h"

void field_strata_count(const camera *c, field_strata *out)
{
    const int n = c->samples.spp;
    int ring = 0;
    for (int k = 0; k < n; k++) {
        const film_sample s = field_shared_sample(c, k, NULL);
        ring += pupil_in_margin(&c->pupil, s.pupil_u, s.pupil_v);
    }
    const double e = 1.0 - 1.0 / (PUPIL_FIT_MARGIN * PUPIL_FIT_MARGIN);
    *out = (field_strata){1.0, 1.0};
    if (c->dispersion || !pupil_is_fitted(&c->pupil) || ring == n)   /* plain: see above */
        return;
    out->core_scale = n * (1.0 - e) / (n - ring);
    if (ring > 0)
        out->margin_scale = n * e / ring;
}

double field_strata_scale(const field_strata *t, const camera *c, film_sample s)
{
    return pupil_in_margin(&c->pupil, s.pupil_u, s.pupil_v) ? t->margin_scale : t->core_scale;
}
