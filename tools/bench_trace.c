/* Benchmarks of the tracer and the ray-table writer (figures, not tests): rays per second of
   each trace method and pupil on each lens on one core; the stop-image pupil's passing share,
   fit time and cost a sample; bytes and time per ray of writing the include. Medians of five
   runs. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include "camera/camera.h"
#include "raytable/raytable.h"
#include "optics/trace_batch.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median5(double v[5])
{
    qsort(v, 5, sizeof v[0], by_value);
    return v[2];
}

static double median3(double v[3])
{
    qsort(v, 3, sizeof v[0], by_value);
    return v[1];
}

static int blades_for_bench;   /* the next camera's aperture blades (0: round) */
static dispersion_mode dispersion_for_bench;   /* the next camera's --dispersion */

static int make_camera(camera *c, const char *lens_path, pupil_kind p, trace_kind t, int w, int h, int spp)
{
    lens l;
    l2p_error err;
    camera_options o;
    camera_options_default(&o);
    o.width = w;
    o.height = h;
    o.spp = spp;
    o.pupil = p;
    o.trace = t;
    o.look_at = v3(0, 0, 10);
    o.aperture_blades = blades_for_bench;
    o.dispersion = dispersion_for_bench;
    if (lens_read(lens_path, &l, &err) || camera_setup(c, &l, &o, &err)) {
        fprintf(stderr, "bench: %s\n", err.text);
        return 1;
    }
    return 0;
}

/* Samples of a 256 x 192 film at 16 spp: everything a film sample costs but the writing. */
static double bench_trace(const char *lens_path, pupil_kind p, trace_kind t)
{
    camera c;
    if (make_camera(&c, lens_path, p, t, 256, 192, 16))
        return NAN;
    double rate[5], passed_fraction = 0;
    sample_batch batch;
    for (int run = 0; run < 5; run++) {
        long long n = 0, passed = 0;
        int b = 0;
        const double start = now();
        for (int py = 0; py < c.film.height; py++)
            for (int px = 0; px < c.film.width; px++) {
                const sample_pixel pixel = sample_pattern_pixel(&c.samples, px, py);
                for (int k = 0; k < c.samples.spp; k++) {
                    film_sample s = sample_pattern_sample(&c.samples, pixel, k);
                    batch.film_point[b] = film_camera_from_raster(&c.film, px + s.offset_x,
                                                                  py + s.offset_y);
                    if (!pupil_reaches(&c.pupil, batch.film_point[b]))
                        continue;   /* as the ray table does: not a sample */
                    batch.u[b] = s.pupil_u;
                    batch.v[b] = s.pupil_v;
                    if (c.dispersion)   /* as the ray table does */
                        batch.wavelength_nm[b] = sample_pattern_wavelength(&c.samples, pixel, k).nm;
                    if (++b < CAMERA_BATCH)
                        continue;
                    batch.n = b;
                    camera_trace_batch(&c, &batch);
                    for (int j = 0; j < b; j++)
                        passed += batch.passed[j];
                    n += b;
                    b = 0;
                }
            }
        rate[run] = (double)n / (now() - start);
        passed_fraction = (double)passed / (double)n;
    }
    printf("%-22s %-11s %-6s %8.2f M samples/s  %5.1f%% pass\n", c.lens.name,
           pupil_kind_name(p), t == TRACE_KIND_THICK ? "thick" : "full", median5(rate) / 1e6,
           100 * passed_fraction);
    camera_free(&c);
    return median5(rate);
}

/* The share of samples that pass, over a 35 mm film of 4:3 and at its centre, for the
   stop-image pupil at the given f-number (NAN: full opening); the time to fit the pupil and
   the time per sample of the pupil alone (sample to film ray and weight). */
static void bench_pupil(const char *lens_path, double f_number)
{
    lens l;
    l2p_error err;
    camera_options o;
    camera_options_default(&o);
    o.width = 256;
    o.height = 192;
    o.f_number = f_number;
    o.look_at = v3(0, 0, 10);
    camera c;
    if (lens_read(lens_path, &l, &err) || camera_setup(&c, &l, &o, &err)) {
        printf("%-16s f/%-5g %s\n", l.name ? l.name : lens_path, f_number, err.text);
        return;
    }
    double fit[5], per_sample[5];
    for (int run = 0; run < 5; run++) {
        pupil p = c.pupil;
        const double start = now();
        pupil_fit(&p, &c.lens, 0.5 * c.film.diagonal_mm);
        fit[run] = now() - start;
    }
    enum { N = 4096 };
    static vec3 fp[N], d[N];
    static double u[N], v[N], w[N];
    uint64_t h = 1;
    for (int k = 0; k < N; k++) {
        h = h * 6364136223846793005ULL + 1442695040888963407ULL;
        fp[k] = film_camera_from_raster(&c.film, (h >> 40) % 256 + 0.5, (h >> 20) % 192 + 0.5);
        u[k] = (double)((h >> 11) & 0xffff) / 65536.0;
        v[k] = (double)((h >> 27) & 0xffff) / 65536.0;
    }
    for (int run = 0; run < 5; run++) {
        const double start = now();
        for (int rep = 0; rep < 50; rep++)
            pupil_film_rays(&c.pupil, N, fp, u, v, d, w);
        per_sample[run] = (now() - start) / (50.0 * N);
    }
    long long n = 0, passed = 0, cn = 0, cpassed = 0;
    sample_batch batch;
    for (int py = 0; py < c.film.height; py++)
        for (int px = 0; px < c.film.width; px += CAMERA_BATCH / 16) {
            int b = 0;
            for (int k = 0; k < CAMERA_BATCH; k++) {
                const sample_pixel pixel = sample_pattern_pixel(&c.samples, px + k / 16, py);
                const film_sample s = sample_pattern_sample(&c.samples, pixel, k % 16);
                batch.film_point[b] = film_camera_from_raster(&c.film, px + k / 16 + s.offset_x,
                                                              py + s.offset_y);
                batch.u[b] = s.pupil_u;
                batch.v[b] = s.pupil_v;
                b += pupil_reaches(&c.pupil, batch.film_point[b]);
            }
            batch.n = b;
            camera_trace_batch(&c, &batch);
            for (int k = 0; k < b; k++)
                passed += batch.passed[k];
            n += b;
        }
    for (int k = 0; k < 65536; k++) {   /* jittered strata: a regular grid misses the rim */
        ray rr;
        double ww;
        h = h * 6364136223846793005ULL + 1442695040888963407ULL;
        const double ju = (double)((h >> 11) & 0xffff) / 65536.0, jv = (double)(h >> 48) / 65536.0;
        cpassed += camera_trace(&c, v3(0, 0, 0), ((k & 255) + ju) / 256.0, ((k >> 8) + jv) / 256.0,
                                &rr, &ww);
        cn++;
    }
    printf("%-16s f/%-5.3g %5.1f%% pass over the film  %5.1f%% at the centre  fit %5.1f ms  "
           "%4.0f ns/sample\n", c.lens.name, c.f_number, 100.0 * (double)passed / (double)n,
           100.0 * (double)cpassed / (double)cn, 1e3 * median5(fit), 1e9 * median5(per_sample));
    camera_free(&c);
}

/* lens2pov trace of about 1e6 rays into dir: time and bytes per ray. */
static void bench_write(const char *lens_path, const char *dir)
{
    camera c;
    if (make_camera(&c, lens_path, PUPIL_STOP_IMAGE, TRACE_KIND_FULL, 1024, 1024, 1))
        return;
    char prefix[512], inc[600];
    snprintf(prefix, sizeof prefix, "%s/bench", dir);
    snprintf(inc, sizeof inc, "%s.inc", prefix);
    double t[5];
    raytable_stats st = {0, 0, 0, 0};
    const raytable_request q = {prefix, NULL, 0, false, NULL, NULL};
    for (int run = 0; run < 5; run++) {
        l2p_error err;
        if (raytable_write(&c, &q, &st, &err)) {
            fprintf(stderr, "bench: %s\n", err.text);
            return;
        }
        t[run] = st.seconds;
    }
    struct stat sb;
    stat(inc, &sb);
    const double m = median5(t);
    printf("trace+write %lld rays: %.3f s median, %.0f ns/ray, %.1f bytes/ray (include %.1f MB)\n",
           st.passed, m, 1e9 * m / (double)st.passed, (double)sb.st_size / (double)st.passed,
           (double)sb.st_size / 1e6);
    camera_free(&c);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: bench_trace LENS_DIR OUT_DIR\n");
        return 2;
    }
    const char *lenses[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm"};
    const char *best = trace_batch_isa();
    const char *isas[] = {"avx512", "avx2", "sse2", "scalar"};
    printf("== full simulation by instruction set, one core (dgauss.50mm, stop-image pupil)\n");
    for (int i = 0; i < 4; i++)
        if (trace_batch_use_isa(isas[i]) == 0) {
            printf("%-7s ", isas[i]);
            char path[512];
            snprintf(path, sizeof path, "%s/dgauss.50mm.dat", argv[1]);
            bench_trace(path, PUPIL_STOP_IMAGE, TRACE_KIND_FULL);
        }
    trace_batch_use_isa(best);
    printf("== tracing with %s, one core, 256x192 film, 16 spp, focus 10 m (median of 5)\n", best);
    for (int i = 0; i < 4; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s.dat", argv[1], lenses[i]);
        for (int p = 0; p < 3; p++)
            bench_trace(path, (pupil_kind)p, TRACE_KIND_FULL);
        bench_trace(path, PUPIL_STOP_IMAGE, TRACE_KIND_THICK);
    }
    printf("== the stop-image pupil: passing samples, fit time, pupil time per sample\n");
    for (int i = 0; i < 4; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s.dat", argv[1], lenses[i]);
        const double f_numbers[] = {NAN, 8.0, 16.0};
        for (int f = 0; f < 3; f++)
            bench_pupil(path, f_numbers[f]);
    }
    printf("== blades: samples a second through a round stop and through 6 and 9 blades, "
           "alternating (dgauss.50mm, stop-image pupil)\n");
    {
        char path[512];
        snprintf(path, sizeof path, "%s/dgauss.50mm.dat", argv[1]);
        const int counts[] = {0, 6, 9};
        double rates[3][3];
        for (int run = 0; run < 3; run++)
            for (int k = 0; k < 3; k++) {
                blades_for_bench = counts[k];
                printf("%2d blades  ", counts[k]);
                rates[k][run] = bench_trace(path, PUPIL_STOP_IMAGE, TRACE_KIND_FULL);
            }
        blades_for_bench = 0;
        for (int k = 1; k < 3; k++) {
            double a[3] = {rates[0][0], rates[0][1], rates[0][2]};
            double b[3] = {rates[k][0], rates[k][1], rates[k][2]};
            printf("%d blades: a sample costs %.3f times a round stop's (medians of 3 runs)\n",
                   counts[k], median3(a) / median3(b));
        }
    }
    printf("== dispersion: samples a second with and without, alternating (takumar.50mm, "
           "stop-image pupil)\n");
    {
        char path[512];
        snprintf(path, sizeof path, "%s/takumar.50mm.dat", argv[1]);
        const dispersion_mode modes[2] = {DISPERSION_OFF, DISPERSION_ON};
        double rates[2][3];
        for (int run = 0; run < 3; run++)
            for (int k = 0; k < 2; k++) {
                dispersion_for_bench = modes[k];
                printf("dispersion %-3s  ", k ? "on" : "off");
                rates[k][run] = bench_trace(path, PUPIL_STOP_IMAGE, TRACE_KIND_FULL);
            }
        dispersion_for_bench = DISPERSION_AUTO;
        double a[3] = {rates[0][0], rates[0][1], rates[0][2]};
        double b[3] = {rates[1][0], rates[1][1], rates[1][2]};
        printf("dispersion: a sample costs %.3f times one without (medians of 3 runs; goal 1.10 "
               "or less)\n", median3(a) / median3(b));
    }
    printf("== writing the ray table (dgauss.50mm, 1024x1024, 1 spp)\n");
    char path[512];
    snprintf(path, sizeof path, "%s/dgauss.50mm.dat", argv[1]);
    bench_write(path, argv[2]);
    return 0;
}
