/* The exposure of field sampling: every pixel sees the same shared pupil points, so the few
   that fall in the fitted pupil's margin would darken or brighten the whole picture at once;
   post-stratification (src/field/strata.c) takes them out of the exposure. Checked against
   the irradiance at the film's centre computed from the lens alone, and the light the margin
   holds, which post-stratification leaves out when no shared point falls in it. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include "field/strata.h"
#include "field/subimage.h"
#include "optics/trace_batch.h"
#include "support.h"

static const char *const LENSES[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm", "takumar.50mm"};
enum { LENS_COUNT = 5 };

/* A 64 x 48 film, focused at 3 m, physical weights, stopped to f_number (NAN: the full
   opening). */
static void setup(camera *c, const char *name, double f_number, int spp, uint64_t seed,
                  dispersion_mode dispersion)
{
    camera_options o;
    camera_options_default(&o);
    o.width = 64;
    o.height = 48;
    o.spp = spp;
    o.seed = seed;
    o.f_number = f_number;
    o.focus_distance_units = 3.0;
    o.weighting = WEIGHTING_PHYSICAL;
    o.dispersion = dispersion;
    test_camera(c, name, &o);
}

/* Whether the ray from the film's centre with direction cosines (a, 0) gets through. */
static bool centre_passes(const lens *l, double a)
{
    trace_batch s;
    s.ox[0] = s.oy[0] = s.oz[0] = 0.0;
    s.dx[0] = a, s.dy[0] = 0.0, s.dz[0] = sqrt(1.0 - a * a);
    s.status[0] = TRACE_PASSED;
    trace_batch_toward_scene(l, &s, 1);
    return s.status[0] == TRACE_PASSED;
}

/* The irradiance at the film's centre from a background of radiance 1, from the lens alone: by
   symmetry the passing directions form a cone of half-angle alpha about the axis, and
   E = integral of cos(theta) d(omega) over it = pi sin^2(alpha). The cone's edge is found by
   stepping out in sin(alpha) and bisecting. */
static double centre_irradiance(const lens *l)
{
    double in = 0.0, out = 0.0;
    for (double a = 1e-3; a < 1.0; a += 1e-3)
        if (!centre_passes(l, a)) {
            out = a;
            break;
        }
    cr_assert(out > 0.0, "nothing blocks the centre's rays");
    in = out - 1e-3;
    for (int i = 0; i < 50; i++) {
        const double mid = 0.5 * (in + out);
        *(centre_passes(l, mid) ? &in : &out) = mid;
    }
    return M_PI * in * in;
}

/* What field sampling gives the film's centre from a background of radiance 1: the mean over
   the spp shared samples of their weights there, post-stratified (src/field/strata.c). The
   point is the axis itself, where the passing region is a disk and the fit's margin passes
   nothing; a pixel's film points move off it with the shared pixel offsets. */
static double field_centre(const camera *c, bool stratified)
{
    field_strata t;
    field_strata_count(c, &t);
    sample_batch *b = malloc(sizeof *b);
    double sum = 0.0;
    b->n = 1;
    for (int k = 0; k < c->samples.spp; k++) {
        const film_sample s = field_shared_sample(c, k, NULL);
        b->film_point[0] = v3(0.0, 0.0, 0.0);
        b->u[0] = s.pupil_u, b->v[0] = s.pupil_v;
        b->wavelength_nm[0] = s.wavelength_nm;
        camera_trace_batch(c, b);
        if (b->passed[0])
            sum += b->weight[0] * (stratified ? field_strata_scale(&t, c, s) : 1.0);
    }
    free(b);
    return sum / c->samples.spp;
}

/* Over eight seeds, field sampling at the film's centre against the lens's own irradiance
   there, at 16 and 64 shared samples, full aperture and f/8, on the four standard lenses and
   one of real glass traced at its d line. Without post-stratification it moved by k / spp
   with the k shared points in the margin: 2.2-2.4% at 64 spp and 5.5% at 16 on every lens.
   What is left is the quasi-Monte Carlo error of a smooth weight, cos^4 over the cone, which
   grows with its spread s = 1 - cos^4(alpha): measured at worst 0.046 s at 16 spp and 0.016 s
   at 64 (the f/1.4 Takumar, s = 0.24); allowed s / 10 and s / 30, plus 2e-4. */
Test(field_exposure, the_film_centre_is_exposed_right_for_every_seed)
{
    static const double F_NUMBERS[] = {NAN, 8.0};
    static const int SPP[] = {16, 64};
    static const double PER_SPREAD[] = {1.0 / 10.0, 1.0 / 30.0};
    for (int i = 0; i < LENS_COUNT; i++)
        for (int f = 0; f < 2; f++)
            for (int n = 0; n < 2; n++) {
                double expected = 0.0, tolerance = 0.0;
                for (uint64_t seed = 1; seed <= 8; seed++) {
                    camera c;
                    setup(&c, LENSES[i], F_NUMBERS[f], SPP[n], seed, DISPERSION_OFF);
                    if (seed == 1) {
                        expected = centre_irradiance(&c.lens);
                        const double cos2 = 1.0 - expected / M_PI;   /* E = pi sin^2(alpha) */
                        tolerance = (1.0 - cos2 * cos2) * PER_SPREAD[n] + 2e-4;
                    }
                    const double got = field_centre(&c, true);
                    cr_expect(fabs(got / expected - 1.0) <= tolerance,
                              "%s f/%g, %d spp, seed %d: %.6g against %.6g", LENSES[i],
                              F_NUMBERS[f], SPP[n], (int)seed, got, expected);
                    camera_free(&c);
                }
            }
}

/* The post-stratified weights keep the strata's shares: over the shared samples the core's
   scales add up to N (1 - e) and the ring's to N e (e = 1 - 1 / PUPIL_FIT_MARGIN^2), or
   nothing when no sample falls in the ring; with dispersion, or a pupil that was not fitted,
   every scale is 1. */
Test(field_exposure, the_strata_keep_their_shares)
{
    const double e = 1.0 - 1.0 / (PUPIL_FIT_MARGIN * PUPIL_FIT_MARGIN);
    bool saw_ring = false, saw_no_ring = false;
    for (int spp = 1; spp <= 1024; spp *= 4)
        for (uint64_t seed = 1; seed <= 4; seed++) {
            camera c;
            setup(&c, "dgauss.50mm", NAN, spp, seed, DISPERSION_OFF);
            field_strata t;
            field_strata_count(&c, &t);
            double core = 0.0, ring = 0.0;
            for (int k = 0; k < spp; k++) {
                const film_sample s = field_shared_sample(&c, k, NULL);
                *(pupil_in_margin(&c.pupil, s.pupil_u, s.pupil_v) ? &ring : &core) +=
                    field_strata_scale(&t, &c, s);
            }
            if (core == 0.0) {   /* every sample in the ring: the plain estimate */
                cr_expect_float_eq(ring, spp, 1e-12);
            } else {
                cr_expect_float_eq(core, spp * (1.0 - e), 1e-9 * spp, "%d spp, seed %d", spp, (int)seed);
                cr_expect(ring == 0.0 || fabs(ring - spp * e) <= 1e-9 * spp, "%d spp: ring %g", spp, ring);
            }
            saw_ring |= ring > 0.0, saw_no_ring |= ring == 0.0;
            camera_free(&c);
        }
    cr_expect(saw_ring && saw_no_ring, "the cases do not cover both");
    static const struct { const char *lens; dispersion_mode d; pupil_kind p; } PLAIN[] = {
        {"takumar.50mm", DISPERSION_ON, PUPIL_STOP_IMAGE}, {"dgauss.50mm", DISPERSION_OFF, PUPIL_STOP}};
    for (int i = 0; i < 2; i++) {
        camera_options o;
        camera_options_default(&o);
        o.width = 64, o.height = 48, o.spp = 256;
        o.dispersion = PLAIN[i].d, o.pupil = PLAIN[i].p;
        camera c;
        test_camera(&c, PLAIN[i].lens, &o);
        field_strata t;
        field_strata_count(&c, &t);
        cr_expect(t.core_scale == 1.0 && t.margin_scale == 1.0, "%s", PLAIN[i].lens);
        camera_free(&c);
    }
}

/* A tiny generator for the ring's points (its own, so the test does not lean on the shared
   set it checks). */
static double next_unit(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) * 0x1.0p-53;
}

/* A point of the square's ring beyond 1 / PUPIL_FIT_MARGIN, uniform in area: its half-side t
   has density proportional to t, and the point is uniform along that square's edge. */
static void ring_point(uint64_t *s, double *u, double *v)
{
    const double lo = 1.0 / PUPIL_FIT_MARGIN;
    const double t = sqrt(lo * lo + next_unit(s) * (1.0 - lo * lo));
    const double along = t * (2.0 * next_unit(s) - 1.0);
    const int side = (int)(4.0 * next_unit(s));
    const double a = side == 0 ? t : side == 1 ? -t : along, b = side < 2 ? along : side == 2 ? t : -t;
    *u = 0.5 * (a + 1.0), *v = 0.5 * (b + 1.0);
}

/* What post-stratification leaves out when no shared point falls in the ring: the light the
   ring passes, against the whole pupil's, at film radii from the centre to the corner, full
   aperture (stopped down the regions are smaller and rounder, and the ring passes nothing).
   Each stratum's mean weight is taken over points uniform in it; measured at most 9e-5 (the
   fisheye, 40,000 points a stratum at 41 radii); allowed 3e-4, under half a step of a half
   float. */
Test(field_exposure, the_margin_ring_passes_almost_no_light)
{
    const double e = 1.0 - 1.0 / (PUPIL_FIT_MARGIN * PUPIL_FIT_MARGIN);
    const int points = FULL_OR_ASAN(8000, 2000);
    for (int i = 0; i < LENS_COUNT; i++) {
        camera c;
        setup(&c, LENSES[i], NAN, 16, 1, DISPERSION_OFF);
        uint64_t state = 12345;
        for (int j = 0; j <= 10; j++) {
            const vec3 p = v3(0.05 * j * c.film.diagonal_mm, 0.0, 0.0);
            double ring = 0.0, core = 0.0, w;
            ray r;
            for (int k = 0; k < points; k++) {
                double u, v;
                ring_point(&state, &u, &v);
                if (camera_trace(&c, p, u, v, &r, &w))
                    ring += w;
                do
                    u = next_unit(&state), v = next_unit(&state);
                while (pupil_in_margin(&c.pupil, u, v));
                if (camera_trace(&c, p, u, v, &r, &w))
                    core += w;
            }
            const double ring_light = e * ring, all = ring_light + (1.0 - e) * core;
            cr_expect(ring_light <= 3e-4 * all, "%s, film radius %.2f mm: the ring passes %.2e of the light",
                      LENSES[i], p.x, all > 0.0 ? ring_light / all : 0.0);
        }
        camera_free(&c);
    }
}
