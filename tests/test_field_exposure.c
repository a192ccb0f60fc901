/* The exposure of field sampling: every pixel sees the same shared pupil points, so the few
   beyond the disk that passes on the axis would darken or brighten the whole picture at once;
   post-stratification (src/field/strata.c) takes them out of the exposure. Checked against
   the irradiance at the film's centre computed from the lens alone, and the light the ring
   holds off the axis, which post-stratification leaves out when no shared point falls in it. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include "field/strata.h"
#include "field/subimage.h"
#include "optics/spectrum.h"
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

/* With dispersion, that irradiance averaged over the wavelengths as they are sampled,
   lambda = P^-1(u) for u uniform (spectrum.h), at 64 midpoints of u. */
static double centre_irradiance_spectral(const camera *c)
{
    if (!c->dispersion)
        return centre_irradiance(&c->lens);
    double sum = 0.0;
    for (int i = 0; i < 64; i++) {
        lens at;
        cr_assert_eq(lens_copy(&at, &c->lens), 0);
        lens_at_wavelength(&at, spectrum_wavelength_nm((i + 0.5) / 64.0));
        sum += centre_irradiance(&at);
        lens_free(&at);
    }
    return sum / 64.0;
}

/* Sample (u, v) traced from film point p at wavelength nm (read with dispersion only). */
static bool trace_at(const camera *c, vec3 p, double u, double v, double nm, double *weight)
{
    sample_batch *b = malloc(sizeof *b);
    b->n = 1;
    b->film_point[0] = p;
    b->u[0] = u, b->v[0] = v;
    b->wavelength_nm[0] = nm;
    camera_trace_batch(c, b);
    const bool passed = b->passed[0];
    *weight = b->weight[0];
    free(b);
    return passed;
}

/* What field sampling gives the film's centre from a background of radiance 1: the mean over
   the spp shared samples of their weights there, post-stratified. The point is the axis itself;
   a pixel's film points move off it with the shared pixel offsets. */
static double field_centre(const camera *c)
{
    field_strata t;
    field_strata_count(c, &t);
    double sum = 0.0, w;
    for (int k = 0; k < c->samples.spp; k++) {
        const film_sample s = field_shared_sample(c, k, NULL);
        if (trace_at(c, v3(0.0, 0.0, 0.0), s.pupil_u, s.pupil_v, s.wavelength_nm, &w))
            sum += w * field_strata_scale(&t, s);
    }
    return sum / c->samples.spp;
}

/* Over eight seeds, field sampling at the film's centre against the lens's own irradiance
   there, at 16 and 64 shared samples, full aperture and f/8, on the four standard lenses and
   one of real glass, at its d line and with dispersion. Without post-stratification it moved
   by k / spp with the k shared points beyond the passing disk: 2.2-2.4% at 64 spp and 5.5% at
   16 on every lens at the d line, up to 9% at 16 spp with dispersion. What is left is the
   quasi-Monte Carlo error of a smooth weight, cos^4 over the cone, which grows with its spread
   s = 1 - cos^4(alpha): measured at worst 0.046 s at 16 spp and 0.016 s at 64 (the f/1.4
   Takumar, s = 0.24); allowed s / 10 and s / 30, plus 2e-4 and, with dispersion, the spread
   of the irradiance over the spectrum over the samples. */
Test(field_exposure, the_film_centre_is_exposed_right_for_every_seed)
{
    static const double F_NUMBERS[] = {NAN, 8.0};
    static const int SPP[] = {16, 64};
    static const double PER_SPREAD[] = {1.0 / 10.0, 1.0 / 30.0};
    for (int i = 0; i <= LENS_COUNT; i++)
        for (int f = 0; f < 2; f++)
            for (int n = 0; n < 2; n++) {
                const bool spectral = i == LENS_COUNT;   /* the last lens again, with dispersion */
                const char *name = LENSES[spectral ? LENS_COUNT - 1 : i];
                double expected = 0.0, tolerance = 0.0;
                for (uint64_t seed = 1; seed <= 8; seed++) {
                    camera c;
                    setup(&c, name, F_NUMBERS[f], SPP[n], seed, spectral ? DISPERSION_ON : DISPERSION_OFF);
                    if (seed == 1) {
                        expected = centre_irradiance_spectral(&c);
                        const double cos2 = 1.0 - expected / M_PI;   /* E = pi sin^2(alpha) */
                        tolerance = (1.0 - cos2 * cos2) * PER_SPREAD[n] + 2e-4;
                        if (spectral) {
                            lens blue, red;
                            cr_assert_eq(lens_copy(&blue, &c.lens), 0);
                            cr_assert_eq(lens_copy(&red, &c.lens), 0);
                            lens_at_wavelength(&blue, SPECTRUM_MIN_NM);
                            lens_at_wavelength(&red, SPECTRUM_MAX_NM);
                            tolerance += fabs(centre_irradiance(&blue) - centre_irradiance(&red)) /
                                         expected / SPP[n];
                            lens_free(&blue), lens_free(&red);
                        }
                    }
                    const double got = field_centre(&c);
                    cr_expect(fabs(got / expected - 1.0) <= tolerance,
                              "%s%s f/%g, %d spp, seed %d: %.6g against %.6g (%.2e, allowed %.2e)", name,
                              spectral ? " with dispersion" : "", F_NUMBERS[f], SPP[n], (int)seed, got,
                              expected, got / expected - 1.0, tolerance);
                    camera_free(&c);
                }
            }
}

/* On the axis the fitted region is a disk grown by the fit's margin, exactly: the core is
   1 / PUPIL_FIT_MARGIN of the unit disk, to the fit's bisection. The post-stratified weights
   keep the strata's shares: over the shared samples the core's scales add up to N s and the
   ring's to N (1 - s), or nothing when no sample falls in the ring. The rear and stop pupils
   and thick tracing keep the plain estimate. */
Test(field_exposure, the_strata_keep_their_shares)
{
    bool saw_ring = false, saw_no_ring = false;
    for (int spp = 1; spp <= 1024; spp *= 4)
        for (uint64_t seed = 1; seed <= 4; seed++)
            for (int spectral = 0; spectral < 2; spectral++) {
                camera c;
                setup(&c, spectral ? "takumar.50mm" : "dgauss.50mm", NAN, spp, seed,
                      spectral ? DISPERSION_ON : DISPERSION_OFF);
                field_strata t;
                field_strata_count(&c, &t);
                if (!spectral)
                    cr_expect(fabs(field_strata_core_radius(&t, 587.6) * PUPIL_FIT_MARGIN - 1.0) < 1e-6,
                              "core %.9g", field_strata_core_radius(&t, 587.6));
                double core = 0.0, ring = 0.0;
                for (int k = 0; k < spp; k++) {
                    const film_sample s = field_shared_sample(&c, k, NULL);
                    *(field_strata_in_ring(&t, s) ? &ring : &core) += field_strata_scale(&t, s);
                }
                if (!t.on) {   /* every sample in the ring: the plain estimate */
                    cr_expect(core == 0.0 && ring == spp, "%d spp: core %g, ring %g", spp, core, ring);
                } else {
                    cr_expect(fabs(core - spp * t.core_share) <= 1e-9 * spp, "%d spp, seed %d: core %g",
                              spp, (int)seed, core);
                    cr_expect(ring == 0.0 || fabs(ring - spp * (1.0 - t.core_share)) <= 1e-9 * spp,
                              "%d spp: ring %g", spp, ring);
                    saw_ring |= ring > 0.0, saw_no_ring |= ring == 0.0;
                }
                camera_free(&c);
            }
    cr_expect(saw_ring && saw_no_ring, "the cases do not cover both");
    static const struct { pupil_kind p; trace_kind trace; } PLAIN[] = {
        {PUPIL_REAR, TRACE_KIND_FULL}, {PUPIL_STOP, TRACE_KIND_FULL}, {PUPIL_STOP_IMAGE, TRACE_KIND_THICK}};
    for (int i = 0; i < 3; i++) {
        camera_options o;
        camera_options_default(&o);
        o.width = 64, o.height = 48, o.spp = 256;
        o.pupil = PLAIN[i].p, o.trace = PLAIN[i].trace;
        camera c;
        test_camera(&c, "dgauss.50mm", &o);
        field_strata t;
        field_strata_count(&c, &t);
        cr_expect(!t.on && field_strata_scale(&t, field_shared_sample(&c, 0, NULL)) == 1.0, "case %d", i);
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

/* A point of the square's ring beyond lo (the unit disk's beyond radius lo), uniform in area:
   its half-side t has density proportional to t, the point uniform along that square's edge. */
static void ring_point(uint64_t *s, double lo, double *u, double *v)
{
    const double t = sqrt(lo * lo + next_unit(s) * (1.0 - lo * lo));
    const double along = t * (2.0 * next_unit(s) - 1.0);
    const int side = (int)(4.0 * next_unit(s));
    const double a = side == 0 ? t : side == 1 ? -t : along, b = side < 2 ? along : side == 2 ? t : -t;
    *u = 0.5 * (a + 1.0), *v = 0.5 * (b + 1.0);
}

/* The light the ring passes at film point p and wavelength nm, over the whole pupil's: each
   stratum's mean weight over points uniform in it, times its share. */
static double ring_light(const camera *c, const field_strata *t, vec3 p, double nm, int points,
                         uint64_t *state)
{
    const double lo = field_strata_core_radius(t, nm), ring_share = 1.0 - lo * lo;
    double ring = 0.0, core = 0.0, w, u, v;
    for (int k = 0; k < points; k++) {
        ring_point(state, lo, &u, &v);
        if (trace_at(c, p, u, v, nm, &w))
            ring += w;
        do
            u = next_unit(state), v = next_unit(state);
        while (pupil_disk_radius(u, v) > lo);
        if (trace_at(c, p, u, v, nm, &w))
            core += w;
    }
    const double all = ring_share * ring + (1.0 - ring_share) * core;
    return all > 0.0 ? ring_share * ring / all : 0.0;
}

/* What post-stratification leaves out when no shared point falls in the ring: the light the
   ring passes, against the whole pupil's, at film radii from the centre to the corner, full
   aperture (stopped down, the regions are smaller and rounder and the ring passes nothing).
   At the d line the ring is the fit's margin: measured at most 9e-5 (the fisheye, 40,000
   points a stratum at 41 radii), allowed 3e-4, under half a step of a half float. With
   dispersion it also holds what the pupil grew for the other wavelengths: measured at most
   1.3% (the Takumar, at 780 nm, in the corner), allowed 2.5%; a ring of 2.5% to 7% of the
   pupil, which 16 shared points miss about one time in three and 64 one time in thirty. */
Test(field_exposure, the_ring_passes_little_light)
{
    const int points = FULL_OR_ASAN(8000, 2000);
    for (int i = 0; i <= LENS_COUNT; i++) {
        const bool spectral = i == LENS_COUNT;
        const char *name = LENSES[spectral ? LENS_COUNT - 1 : i];
        camera c;
        setup(&c, name, NAN, 16, 1, spectral ? DISPERSION_ON : DISPERSION_OFF);
        field_strata t;
        field_strata_count(&c, &t);
        uint64_t state = 12345;
        for (int j = 0; j <= 10; j++)
            for (int w = 0; w < (spectral ? 5 : 1); w++) {
                const vec3 p = v3(0.05 * j * c.film.diagonal_mm, 0.0, 0.0);
                const double nm = spectral ? SPECTRUM_MIN_NM + 100.0 * w : 587.6;
                const double share = ring_light(&c, &t, p, nm, points, &state);
                cr_expect(share <= (spectral ? 0.025 : 3e-4),
                          "%s, film radius %.2f mm, %g nm: the ring passes %.2e of the light", name, p.x,
                          nm, share);
            }
        camera_free(&c);
    }
}
