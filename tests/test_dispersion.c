/* Dispersion (--dispersion, --wavelength; docs/dispersion.md): the observer and the colour
   weights, the tracers at a wavelength, first-order properties at the F and C lines against an
   independent paraxial trace, the pupil at every wavelength, and pictures through POV-Ray. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/camera.h"
#include "optics/lens.h"
#include "optics/spectrum.h"
#include "optics/trace.h"
#include "optics/trace_batch.h"
#include "image/image_io.h"
#include "support.h"

/* ---------------------------------------------------------------- the observer */

/* CIE 1931 2-degree observer, from the CIE's 5 nm table (CIE 015:2004, table T.4). */
static const double CIE_TABLE[][4] = {
    {450, 0.33620, 0.03800, 1.77211}, {500, 0.00490, 0.32300, 0.27200},
    {555, 0.51205, 1.00000, 0.00575}, {600, 1.06220, 0.63100, 0.00080},
    {650, 0.28350, 0.10700, 0.00002}, {420, 0.13438, 0.00400, 0.64560},
};

/* The multi-lobe fit's error is within 2% of the functions' peaks (Wyman et al. 2013,
   figure 2); 0.03 allows that on z, whose peak is 1.78. */
Test(spectrum, the_observer_matches_the_cie_table)
{
    for (size_t i = 0; i < sizeof CIE_TABLE / sizeof CIE_TABLE[0]; i++) {
        double xyz[3];
        spectrum_cie1931_xyz(CIE_TABLE[i][0], xyz);
        for (int c = 0; c < 3; c++)
            cr_expect(fabs(xyz[c] - CIE_TABLE[i][c + 1]) < 0.03, "%g nm, %c: %g, table %g",
                      CIE_TABLE[i][0], "xyz"[c], xyz[c], CIE_TABLE[i][c + 1]);
    }
}

/* Each channel's band weights average exactly 1, whatever the number of bands: a grey scene
   stays grey. */
Test(spectrum, band_weights_average_one_in_every_channel)
{
    const int counts[] = {1, 2, 3, 7, 16, 64, 1000};
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
        double sum[3] = {0, 0, 0};
        for (int b = 0; b < counts[i]; b++) {
            double w[3];
            spectrum_band_weights(b, counts[i], w);
            for (int c = 0; c < 3; c++)
                sum[c] += w[c];
        }
        for (int c = 0; c < 3; c++)
            cr_expect(fabs(sum[c] / counts[i] - 1.0) < 1e-12, "%d bands, channel %d: mean %.15g",
                      counts[i], c, sum[c] / counts[i]);
    }
}

/* With many bands a band's weights are the colour of its wavelength: red leads at 610 nm,
   green at 540, blue at 450, and red is negative at 500 nm, as linear sRGB of a spectral
   colour is. */
Test(spectrum, narrow_bands_have_their_wavelengths_colour)
{
    enum { N = 400 };
    const double at[4] = {610, 540, 450, 500};
    for (int i = 0; i < 4; i++) {
        int b = 0;
        while (b + 1 < N && spectrum_wavelength_nm((b + 1.0) / N) <= at[i])
            b++;
        double w[3];
        spectrum_band_weights(b, N, w);
        if (i == 3) {
            cr_expect(w[0] < 0, "red at 500 nm: %g", w[0]);
            continue;
        }
        const int lead = w[0] > w[1] && w[0] > w[2] ? 0 : w[1] > w[2] ? 1 : 2;
        cr_expect_eq(lead, i, "%g nm: weights %g %g %g", at[i], w[0], w[1], w[2]);
    }
}

/* Simpson's rule on the observer: the integral of x + y + z over [a, b]. */
static double observer_integral(double a, double b)
{
    enum { STEPS = 4000 };
    const double h = (b - a) / STEPS;
    double sum = 0;
    for (int i = 0; i <= STEPS; i++) {
        double xyz[3];
        spectrum_cie1931_xyz(a + i * h, xyz);
        sum += (i == 0 || i == STEPS ? 1 : i % 2 ? 4 : 2) * (xyz[0] + xyz[1] + xyz[2]);
    }
    return sum * h / 3;
}

/* The wavelengths are drawn with density proportional to x + y + z: the share of u that lands
   in [a, b] is that integral's share, and the ends are exact. */
Test(spectrum, wavelengths_follow_the_observer)
{
    cr_assert_eq(spectrum_wavelength_nm(0.0), SPECTRUM_MIN_NM);
    cr_assert_eq(spectrum_wavelength_nm(1.0), SPECTRUM_MAX_NM);
    const double total = observer_integral(SPECTRUM_MIN_NM, SPECTRUM_MAX_NM);
    const double edges[] = {450, 500, 550, 600, 650};
    for (size_t i = 0; i + 1 < sizeof edges / sizeof edges[0]; i++) {
        /* the u at which the wavelength crosses each edge, by bisection */
        double u[2];
        for (int e = 0; e < 2; e++) {
            double lo = 0, hi = 1;
            for (int k = 0; k < 60; k++)
                *(spectrum_wavelength_nm(0.5 * (lo + hi)) < edges[i + e] ? &lo : &hi) = 0.5 * (lo + hi);
            u[e] = lo;
        }
        const double want = observer_integral(edges[i], edges[i + 1]) / total;
        cr_expect(fabs((u[1] - u[0]) - want) < 1e-5, "[%g, %g] nm: share %.6f, observer %.6f",
                  edges[i], edges[i + 1], u[1] - u[0], want);
    }
    double last = 0;
    for (int k = 0; k <= 10000; k++) {
        const double nm = spectrum_wavelength_nm(k / 10000.0);
        cr_assert(nm >= last, "decreasing at u = %g", k / 10000.0);
        last = nm;
    }
}

/* ---------------------------------------------------------------- tracing at a wavelength */

static void read_lens(const char *name, lens *l)
{
    char path[512];
    snprintf(path, sizeof path, LENS_DIR "%s.dat", name);
    l2p_error err;
    cr_assert_eq(lens_read(path, l, &err), 0, "%s", err.text);
}

/* Every instruction set gives, with a wavelength per ray, the one-ray tracer's rays bit for
   bit; and a ray at a wavelength is the ray of the lens taken to that wavelength. */
Test(dispersion, every_tracer_gives_the_same_rays_at_each_wavelength)
{
    lens l, mono;
    read_lens("cooke-triplet.50mm", &l);
    lens_set_film_distance(&l, 42.0);
    enum { N = 61 };
    double nm[N];
    trace_batch want;
    for (int k = 0; k < N; k++) {
        nm[k] = 380.0 + 400.0 * k / (N - 1);
        const vec3 q = v3(-6.0 + 12.0 * (k % 7) / 6.0, -5.0 + 10.0 * (k % 5) / 4.0, 42.0);
        const vec3 p = v3(3.0 * (k % 3) - 3.0, 2.0 - (k % 4), 0.0);
        const vec3 d = v3_normalize(v3_sub(q, p));
        want.ox[k] = p.x, want.oy[k] = p.y, want.oz[k] = p.z;
        want.dx[k] = d.x, want.dy[k] = d.y, want.dz[k] = d.z;
        want.status[k] = TRACE_PASSED;
    }
    const trace_batch in = want;
    int passed = 0;
    for (int k = 0; k < N; k++) {
        ray r = {v3(in.ox[k], in.oy[k], in.oz[k]), v3(in.dx[k], in.dy[k], in.dz[k])};
        want.status[k] = trace_toward_scene_at(&l, 0, l.count - 1, nm[k], &r, NULL);
        want.ox[k] = r.o.x, want.oy[k] = r.o.y, want.oz[k] = r.o.z;
        want.dx[k] = r.d.x, want.dy[k] = r.d.y, want.dz[k] = r.d.z;
        passed += want.status[k] == TRACE_PASSED;
        /* the same ray through the lens at that wavelength */
        cr_assert_eq(lens_copy(&mono, &l), 0);
        lens_at_wavelength(&mono, nm[k]);
        ray m = {v3(in.ox[k], in.oy[k], in.oz[k]), v3(in.dx[k], in.dy[k], in.dz[k])};
        cr_assert_eq(trace_toward_scene(&mono, 0, mono.count - 1, &m, NULL), want.status[k]);
        cr_assert(m.d.x == r.d.x && m.d.y == r.d.y && m.d.z == r.d.z, "ray %d at %g nm", k, nm[k]);
        lens_free(&mono);
    }
    cr_assert(passed > N / 3, "%d of %d rays pass: the test needs passing rays", passed, N);
    const char *best = trace_batch_isa(), *isas[] = {"avx512", "avx2", "sse2", "scalar"};
    for (int i = 0; i < 4; i++) {
        if (trace_batch_use_isa(isas[i]) != 0)
            continue;
        trace_batch b = in;
        trace_batch_toward_scene_at(&l, &b, N, nm);
        for (int k = 0; k < N; k++) {
            cr_assert_eq(b.status[k], want.status[k], "%s, ray %d", isas[i], k);
            if (want.status[k] == TRACE_PASSED)
                cr_assert(b.ox[k] == want.ox[k] && b.oy[k] == want.oy[k] && b.oz[k] == want.oz[k] &&
                          b.dx[k] == want.dx[k] && b.dy[k] == want.dy[k] && b.dz[k] == want.dz[k],
                          "%s, ray %d at %g nm differs", isas[i], k, nm[k]);
        }
    }
    cr_assert_eq(trace_batch_use_isa(best), 0);
    lens_free(&l);
}

/* Blue bends more than red: through a converging lens a marginal ray at 400 nm crosses the
   axis before the same ray at 700 nm. */
Test(dispersion, blue_focuses_nearer_than_red_through_a_singlet_group)
{
    lens l;
    double cross_z[2];
    const double nm[2] = {400.0, 700.0};
    for (int i = 0; i < 2; i++) {
        read_lens("petzval.50mm", &l);
        lens_set_film_distance(&l, 0.0);
        lens_at_wavelength(&l, nm[i]);
        ray r = {v3(2.0, 0.0, 1000.0), v3(0.0, 0.0, -1.0)};
        cr_assert_eq(trace_toward_film(&l, 0, l.count - 1, &r, NULL), TRACE_PASSED);
        cross_z[i] = r.o.z - r.o.x / r.d.x * r.d.z;
        lens_free(&l);
    }
    cr_expect(cross_z[0] > cross_z[1], "blue crosses the axis at z %g, red at %g (film at 0)",
              cross_z[0], cross_z[1]);
}

/* ---------------------------------------------------------------- first-order properties */

/* n(lambda) from n_d and V_d, written here from the definitions: n = A + B / lambda^2 with
   n(587.5618) = n_d and n(486.1327) - n(656.2725) = (n_d - 1) / V_d. */
static double cauchy_index(double nd, double vd, double nm)
{
    if (vd == 0)
        return nd;
    const double b = (nd - 1) / vd / (1 / (486.1327 * 486.1327) - 1 / (656.2725 * 656.2725));
    return nd + b * (1 / (nm * nm) - 1 / (587.5618 * 587.5618));
}

/* A paraxial y-nu trace (Smith, Modern Optical Engineering, ch. 3) of the ray at height y
   and angle u in front of the lens, with the indices at nm, to film_mm behind the rear
   vertex: after each surface n'u' = nu - y (n' - n) c, and y grows by t u' to the next.
   Returns the height on the film; *at_stop (when not NULL) gets the height at the stop and
   *u_out the angle behind the lens. */
static double paraxial_trace(const lens *l, double nm, double y, double u, double film_mm,
                             double *at_stop, double *u_out)
{
    double nu = u, n = 1.0;
    for (int i = 0; i < l->count; i++) {
        const lens_surface *s = &l->surface[i];
        const double n2 = cauchy_index(s->ior, s->abbe, nm);
        if (i == l->stop && at_stop)
            *at_stop = y;
        nu -= y * (n2 - n) * s->curvature_per_mm;
        n = n2;
        y += (i + 1 < l->count ? s->thickness_mm : film_mm) * nu / n;
    }
    if (u_out)
        *u_out = nu;
    return y;
}

/* The focal length: a ray parallel to the axis at height 1 leaves at angle u', f = -1 / u'. */
static double paraxial_efl_mm(const lens *l, double nm)
{
    double u;
    paraxial_trace(l, nm, 1.0, 0.0, 0.0, NULL, &u);
    return -1.0 / u;
}

static double info_efl_mm(const char *lens_name, double nm)
{
    char path[512], wavelength[32], *out = NULL;
    snprintf(path, sizeof path, LENS_DIR "%s.dat", lens_name);
    snprintf(wavelength, sizeof wavelength, "%.10g", nm);
    cr_assert_eq(run_lens2pov(&out, NULL, "info", path, "--wavelength", wavelength, "--json", NULL), 0);
    const char *at = strstr(out, "\"efl_mm\":");
    cr_assert_not_null(at, "%s", out);
    const double efl = strtod(at + 9, NULL);
    cr_assert(strstr(out, "\"wavelength_nm\":"), "%s", out);
    free(out);
    return efl;
}

/* info --wavelength at the F and C lines gives the focal lengths an independent paraxial trace
   gives with n(lambda), and so their difference, the longitudinal colour of the focal length. */
Test(dispersion, focal_lengths_at_f_and_c_match_a_paraxial_trace)
{
    const char *names[] = {"cooke-triplet.50mm", "tessar.100mm", "petzval.50mm", "takumar.50mm",
                           "sonnar.180mm"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        lens l;
        read_lens(names[i], &l);
        const double f_f = paraxial_efl_mm(&l, 486.1327), f_c = paraxial_efl_mm(&l, 656.2725);
        const double g_f = info_efl_mm(names[i], 486.1327), g_c = info_efl_mm(names[i], 656.2725);
        /* info finds the focal length from rays near the axis: paraxial to its 10 digits */
        cr_expect(fabs(g_f - f_f) < 1e-7 * f_f && fabs(g_c - f_c) < 1e-7 * f_c,
                  "%s: info f_F %.9g f_C %.9g, paraxial %.9g %.9g", names[i], g_f, g_c, f_f, f_c);
        cr_expect(fabs((g_c - g_f) - (f_c - f_f)) < 1e-5 && fabs(f_c - f_f) > 0.05,
                  "%s: f_C - f_F %.6g mm, paraxial %.6g", names[i], g_c - g_f, f_c - f_f);
        lens_free(&l);
    }
}

/* ---------------------------------------------------------------- the pupil */

/* Every ray that the lens passes at any wavelength crosses the pupil plane inside the region
   sampled for its film point at that wavelength: a dense grid over the rear element, and
   beyond its rim, traced at six wavelengths across the spectrum, none of them one a pupil is
   fitted at. Film points on the diagonal, between the pupil's nodes and out to the corner
   (beyond the fisheye's image circle); the full stop, a quarter of it, and for the triplet a
   0.2 mm stop, through which its samples are drawn from spectral pupils. */
Test(dispersion, every_passing_ray_at_every_wavelength_lies_in_the_pupil)
{
    const char *names[] = {"cooke-triplet.50mm", "retrofocus.28mm", "fisheye-dx.10.5mm"};
    const double nm[] = {382, 421, 486, 555, 656, 778}, along[] = {0, 0.3, 0.52, 0.77, 0.93, 1.0};
    enum { N = 160 };
    for (int li = 0; li < 3; li++)
        for (int oi = 0; oi < (li == 0 ? 3 : 2); oi++) {   /* the 0.2 mm stop: the triplet's */
            lens l;
            read_lens(names[li], &l);
            camera_options o;
            camera_options_default(&o);
            o.width = 64;
            o.height = 48;
            const double stop = oi == 2 ? 0.2 / l.surface[l.stop].aperture_diameter_mm : oi ? 0.25 : 1.0;
            o.aperture_diameter_mm = stop * l.surface[l.stop].aperture_diameter_mm;
            o.weighting = WEIGHTING_PHYSICAL;
            camera c;
            l2p_error err;
            cr_assert_eq(camera_setup(&c, &l, &o, &err), 0, "%s", err.text);
            cr_assert(c.dispersion, "%s: dispersion is on for a lens with Abbe numbers", names[li]);
            if (oi == 2)
                cr_expect(c.spectral, "%s: no spectral pupils through a 0.2 mm stop", names[li]);
            const lens_surface *rear = &c.lens.surface[c.lens.count - 1];
            const double reach = 0.75 * rear->aperture_diameter_mm, z = rear->vertex_z_mm;
            for (size_t pi = 0; pi < sizeof along / sizeof along[0]; pi++) {
                const vec3 p = v3(along[pi] * 0.5 * c.film.width_mm, along[pi] * 0.5 * c.film.height_mm, 0);
                for (size_t wi = 0; wi < sizeof nm / sizeof nm[0]; wi++) {
                    long passing = 0, outside = 0;
                    for (int j = 0; j < N; j++)
                        for (int k = 0; k < N; k++) {
                            const vec3 q = v3(-reach + (k + 0.5) * 2 * reach / N,
                                              -reach + (j + 0.5) * 2 * reach / N, z);
                            ray r = {p, v3_normalize(v3_sub(q, p))};
                            if (trace_toward_scene_at(&c.lens, 0, c.lens.count - 1, nm[wi], &r,
                                                      NULL) != TRACE_PASSED)
                                continue;
                            passing++;
                            const pupil *pu = camera_pupil_at(&c, nm[wi]);
                            const double t = pu->z_mm / (q.z - p.z);
                            outside += !pupil_contains(pu, p, p.x + t * (q.x - p.x),
                                                       p.y + t * (q.y - p.y));
                        }
                    cr_expect_eq(outside, 0, "%s, stop x%g, film (%.2f, %.2f), %g nm: %ld of %ld "
                                 "passing rays outside the sampled region", names[li],
                                 stop, p.x, p.y, nm[wi], outside, passing);
                }
            }
            camera_free(&c);
        }
}

/* The samples of film pixels on a grid (every fourth pixel of 96x72, 32 each) through the
   camera: how many pass, and their mean weight. */
static void sample_film(const camera *c, double *passing, double *mean_weight)
{
    sample_batch *b = malloc(sizeof *b);
    cr_assert_not_null(b);
    long samples = 0, passed = 0;
    double weights = 0;
    for (int py = 0; py < 72; py += 4)
        for (int px = 0; px < 96; px += 4) {
            const sample_pixel pixel = sample_pattern_pixel(&c->samples, px, py);
            b->n = 0;
            for (int k = 0; k < c->samples.spp; k++) {
                const film_sample s = sample_pattern_sample(&c->samples, pixel, k);
                const int n = b->n++;
                b->film_point[n] = film_camera_from_raster(&c->film, px + s.offset_x, py + s.offset_y);
                b->u[n] = s.pupil_u, b->v[n] = s.pupil_v;
                b->wavelength_nm[n] = c->dispersion ? sample_pattern_wavelength(&c->samples, pixel, k).nm
                                                    : WAVELENGTH_D_NM;
            }
            camera_trace_batch(c, b);
            for (int k = 0; k < b->n; k++) {
                samples++;
                passed += b->passed[k];
                weights += b->passed[k] ? b->weight[k] : 0.0;
            }
        }
    free(b);
    *passing = (double)passed / (double)samples;
    *mean_weight = weights / (double)samples;
}

/* The share of samples that pass through a stop of diameter_mm on lens name, with and without
   dispersion: with it, at least least_ratio times as many, and mean weights within 2%. */
static void expect_most_pass(const char *name, double diameter_mm, double least_ratio)
{
    double passing[2], mean[2];
    for (int on = 0; on < 2; on++) {
        lens l;
        read_lens(name, &l);
        camera_options o;
        camera_options_default(&o);
        o.width = 96, o.height = 72, o.spp = 32;
        o.aperture_diameter_mm = diameter_mm;
        o.dispersion = on ? DISPERSION_ON : DISPERSION_OFF;
        camera c;
        l2p_error err;
        cr_assert_eq(camera_setup(&c, &l, &o, &err), 0, "%s", err.text);
        cr_expect(!on || c.spectral, "%s: no spectral pupils through a %g mm stop", name, diameter_mm);
        sample_film(&c, &passing[on], &mean[on]);
        camera_free(&c);
    }
    cr_log_info("%s at %g mm: %.1f%% of samples pass with dispersion, %.1f%% without; mean weight "
                "%.4f against %.4f", name, diameter_mm, 100 * passing[1], 100 * passing[0], mean[1],
                mean[0]);
    cr_expect_geq(passing[1], least_ratio * passing[0], "%s at %g mm: %.3f of samples pass with "
                  "dispersion, %.3f without", name, diameter_mm, passing[1], passing[0]);
    cr_expect(fabs(mean[1] / mean[0] - 1) < 0.02, "%s at %g mm: mean weight %.4f with dispersion, "
              "%.4f without", name, diameter_mm, mean[1], mean[0]);
}

/* Through a small stop the passing region moves with the wavelength by more than its own
   size. Samples are drawn from a pupil fitted near their own wavelength, so that about as many
   pass as without dispersion (one region for the whole spectrum passed a fifth as many), and
   the normalized weights average to what they do without dispersion: the stop's light is the
   same at every wavelength, to the 1% that the exit pupil's size changes with it (the
   normalization once took the d line's pupil for the whole spectrum's, 7% darker). */
Test(dispersion, a_small_stop_passes_most_samples_at_every_wavelength)
{
    expect_most_pass("petzval.50mm", 0.2, 0.5);
}

/* A stop ten times smaller: nine spectral pupils are too far apart in wavelength (6% of the
   samples passed, against 73% without dispersion), and their count is raised until covering
   its neighbours grows a pupil 1.5 times at most: over 40% as many pass as without. */
Test(dispersion, a_tiny_stop_brings_the_spectral_pupils_closer)
{
    expect_most_pass("petzval.50mm", 0.02, 0.4);
}

/* ---------------------------------------------------------------- pictures */

/* The paraxial height on the film (film_mm behind the rear vertex) of the chief ray from a
   point at infinity at angle theta: rays are linear in their height at the front, so the one
   through the stop's centre is found from two (y0 = 0 and 1). */
static double paraxial_chief_height_mm(const lens *l, double nm, double tan_theta, double film_mm)
{
    double at_stop[2], on_film[2];
    for (int k = 0; k < 2; k++)
        on_film[k] = paraxial_trace(l, nm, k, tan_theta, film_mm, &at_stop[k], NULL);
    const double y0 = -at_stop[0] / (at_stop[1] - at_stop[0]);
    return on_film[0] + y0 * (on_film[1] - on_film[0]);
}

/* Each channel's image is the images at every wavelength weighted by that channel's share of
   the observer (linear sRGB of the wavelength over its integral): its centroid is that mean of
   the chief ray's height. */
static void paraxial_channel_heights_mm(const lens *l, double tan_theta, double film_mm, double h[3])
{
    double sum[3] = {0, 0, 0}, weight[3] = {0, 0, 0};
    for (double nm = SPECTRUM_MIN_NM; nm <= SPECTRUM_MAX_NM; nm += 0.5) {
        double rgb[3];
        spectrum_linear_srgb(nm, rgb);
        const double y = paraxial_chief_height_mm(l, nm, tan_theta, film_mm);
        for (int c = 0; c < 3; c++)
            sum[c] += rgb[c] * y, weight[c] += rgb[c];
    }
    for (int c = 0; c < 3; c++)
        h[c] = sum[c] / weight[c];
}

/* The total and the x centroid (pixels of the image) of each channel of a picture. */
static void channel_centroids(const char *path, double sum[3], double x[3])
{
    int w, h;
    float *rgba;
    l2p_error err;
    cr_assert_eq(image_read_rgba(path, &w, &h, &rgba, &err), 0, "%s: %s", path, err.text);
    double moment[3] = {0, 0, 0};
    for (int c = 0; c < 3; c++)
        sum[c] = 0;
    for (int py = 0; py < h; py++)
        for (int px = 0; px < w; px++)
            for (int c = 0; c < 3; c++) {
                const double v = rgba[4 * ((size_t)py * w + px) + c];
                sum[c] += v;
                moment[c] += v * (px + 0.5);
            }
    free(rgba);
    for (int c = 0; c < 3; c++)
        x[c] = moment[c] / sum[c];
}

/* The film distance (behind the rear vertex) where a paraxial ray parallel to the axis
   crosses it at this wavelength: at height y0 on the rear vertex's plane with angle u', it
   crosses at -y0 / u'. */
static double paraxial_focus_mm(const lens *l, double nm)
{
    double u;
    const double y0 = paraxial_trace(l, nm, 1.0, 0.0, 0.0, NULL, &u);
    return -y0 / u;
}

/* Lateral colour: a white disk at infinity, 10 degrees off the axis, rendered through the
   retrofocus at f/8 with dispersion on a film fine enough to see it (5 um pixels). Its red
   image lies farther out than its blue one by the distance an independent paraxial trace
   predicts for the channels' shares of the spectrum, within 15%: the paraxial trace leaves
   out the change of distortion with wavelength, which grows as the angle squared (the render
   falls 8% short of it at 10 degrees, 13% at 15). Without dispersion the channels coincide. */
Test(dispersion, lateral_colour_lies_where_the_paraxial_trace_puts_it)
{
    lens l;
    read_lens("retrofocus.28mm", &l);
    const double film_mm = paraxial_focus_mm(&l, WAVELENGTH_D_NM), theta = 10.0 * M_PI / 180.0;
    double h[3];
    paraxial_channel_heights_mm(&l, tan(theta), film_mm, h);
    lens_free(&l);
    /* 6000 x 4000 on a 35 mm diagonal; the disk's image (0.9 m in radius at 1000 m, seen
       at f = 28 mm: about 5 pixels in radius) lies near x = 3000 + h / pitch, mirrored upright */
    const double pitch_mm = 35.0 / sqrt(1.0 + (4.0 / 6.0) * (4.0 / 6.0)) / 6000.0;
    const int x0 = (int)(3000.0 + h[1] / pitch_mm) - 60, x1 = x0 + 90;
    const char *dir = test_tmpdir();
    char scene[256], crop[64], film[32];
    snprintf(scene, sizeof scene, "%s", tmp_path(dir, "disk.pov"));
    FILE *f = fopen(scene, "w");
    cr_assert_not_null(f);
    fprintf(f, "#version 3.7;\nbackground { rgb 0 }\nsphere { <%.12g, 0, %.12g>, 0.9 pigment { rgb 1 } "
               "finish { ambient 0 diffuse 0 emission 1 } }\n", 1000 * sin(theta), 1000 * cos(theta));
    fclose(f);
    snprintf(crop, sizeof crop, "%d,1970,%d,2030", x0, x1);
    snprintf(film, sizeof film, "%.12g", film_mm);
    double shift[2];
    for (int on = 0; on < 2; on++) {
        const char *out = tmp_path(dir, on ? "on.exr" : "off.exr");
        run_lens2pov_ok("the disk", "render", scene, LENS_DIR "retrofocus.28mm.dat", "--sampling",
                        "pixel", "--width",
                        "6000", "--height", "4000", "--film-distance", film, "--f-number", "8",
                        "--crop", crop, "--spp", "64", "--dispersion", on ? "on" : "off",
                        "--quiet", "-o", out, NULL);
        double sum[3], x[3];
        channel_centroids(out, sum, x);
        cr_assert(sum[0] > 10 && sum[2] > 10, "the disk is in the crop: sums %g %g %g", sum[0],
                  sum[1], sum[2]);
        shift[on] = (x[0] - x[2]) * pitch_mm;
    }
    const double predicted = h[0] - h[2];
    cr_expect(fabs(shift[0]) < 1e-9, "without dispersion red and blue coincide: %g mm apart", shift[0]);
    cr_expect(predicted > 0.004, "the test needs lateral colour: %g mm", predicted);
    cr_expect(fabs(shift[1] - predicted) < 0.15 * predicted,
              "red lies %.2f um beyond blue, the paraxial trace says %.2f um", 1e3 * shift[1],
              1e3 * predicted);
}

/* A white background through lenses with dispersion stays white and neutral at every pixel,
   vignetted corners and a fisheye's image circle included, with both samplings: the channels
   agree within 1% (the band weights renormalized over the samples that pass; develop.c). At
   16 spp a single blocked sample would otherwise tint a pixel by up to a third. */
Test(dispersion, a_white_background_stays_neutral)
{
    const char *dir = test_tmpdir();
    const char *scene = tmp_path(dir, "white.pov");
    write_text(scene, "#version 3.7;\nbackground { rgb 1 }\n");
    const char *names[] = {"cooke-triplet.50mm", "fisheye-dx.10.5mm", "retrofocus.28mm"};
    for (int li = 0; li < 3; li++)
        for (int field = 0; field < 2; field++) {
            char path[512];
            snprintf(path, sizeof path, LENS_DIR "%s.dat", names[li]);
            const char *out = tmp_path(dir, "white.exr");
            run_lens2pov_ok("white", "render", scene, path, "--width", "48", "--height", "36",
                            "--spp", "16", "--f-number", "5.6", "--sampling",
                            field ? "field" : "pixel", "--quiet", "-o", out, NULL);
            int w, h;
            float *rgba;
            l2p_error err;
            cr_assert_eq(image_read_rgba(out, &w, &h, &rgba, &err), 0, "%s", err.text);
            int bright = 0;
            for (int i = 0; i < w * h; i++) {
                const float *p = rgba + 4 * i;
                bright += p[1] > 0.5f;
                cr_expect(fabsf(p[0] - p[1]) <= 0.01f * p[1] && fabsf(p[2] - p[1]) <= 0.01f * p[1],
                          "%s, %s sampling, pixel (%d, %d): %g %g %g", names[li],
                          field ? "field" : "pixel", i % w, i / w, p[0], p[1], p[2]);
            }
            cr_expect(bright > w * h / 2, "%s: %d of %d pixels bright", names[li], bright, w * h);
            free(rgba);
        }
}

/* Every ray of a trace with dispersion was traced at the wavelength its CSV row gives: traced
   back from the scene through the lens taken to that wavelength it lands on its film point
   (to 1e-6 mm), where at the d line it lands off it (or is blocked); every band of the
   spectrum is drawn as often. */
Test(dispersion, each_ray_is_traced_at_its_rows_wavelength)
{
    const char *dir = test_tmpdir();
    const char *prefix = tmp_path(dir, "t"), *csv = tmp_path(dir, "t.csv");
    run_lens2pov_ok("trace", "trace", LENS_DIR "cooke-triplet.50mm.dat", "--width", "12",
                    "--height", "9", "--spp", "8", "--rays", csv, "--quiet", "-o", prefix, NULL);
    char *text = read_text(csv, NULL);
    cr_assert_not_null(text);
    cr_assert(!strncmp(text, "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,dir_x,"
                             "dir_y,dir_z,weight,wavelength_nm\n", 87), "header: %.100s", text);
    camera c;
    test_camera(&c, "cooke-triplet.50mm", NULL);
    int rows = 0, off_at_d = 0, in_band[8] = {0};
    for (const char *line = strchr(text, '\n') + 1; *line; line = strchr(line, '\n') + 1) {
        double v[12];
        cr_assert_eq(sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1],
                            &v[2], &v[3], &v[4], &v[5], &v[6], &v[7], &v[8], &v[9], &v[10], &v[11]), 12);
        for (int b = 0; b < 8; b++)
            in_band[b] += v[11] >= spectrum_wavelength_nm(b / 8.0) &&
                          v[11] < spectrum_wavelength_nm((b + 1) / 8.0);
        double miss[2];
        for (int d_line = 0; d_line < 2; d_line++) {
            lens at;
            cr_assert_eq(lens_copy(&at, &c.lens), 0);
            lens_at_wavelength(&at, d_line ? WAVELENGTH_D_NM : v[11]);
            const vec3 dir_out = v3(v[7], v[8], v[9]);
            ray r = {v3_add(v3(v[4], v[5], v[6]), dir_out), v3_scale(dir_out, -1.0)};
            const trace_status st = trace_toward_film(&at, 0, at.count - 1, &r, NULL);
            cr_assert(st == TRACE_PASSED || d_line, "row %d does not get back through", rows);
            const double t = -r.o.z / r.d.z;
            miss[d_line] = st != TRACE_PASSED ? INFINITY
                                              : hypot(r.o.x + t * r.d.x - v[2], r.o.y + t * r.d.y - v[3]);
            lens_free(&at);
        }
        cr_expect(miss[0] < 1e-6, "row %d at %g nm lands %g mm from its film point", rows, v[11],
                  miss[0]);
        off_at_d += miss[1] > 1e-4;
        rows++;
    }
    camera_free(&c);
    free(text);
    cr_assert(rows > 400, "%d rows", rows);
    cr_expect(off_at_d > rows / 2, "at the d line only %d of %d rows land off their film points",
              off_at_d, rows);
    /* each pixel's 8 samples take the 8 bands once each: the bands are as full as each other,
       but for the few samples the lens blocks */
    for (int b = 0; b < 8; b++)
        cr_expect(fabs(in_band[b] - rows / 8.0) < 0.1 * rows / 8.0, "band %d holds %d of %d rows",
                  b, in_band[b], rows);
}
