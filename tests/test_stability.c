/* Numerical stability on stiff and extreme lenses (issue 5). `make stability` prints the
   table these tests write (tools/stability.sh); the figures are in the README.

   Every case writes a lens file (generated here: nothing stiff is committed) and runs
   `lens2pov trace LENS OPTIONS --rays CSV -o PREFIX` on a 32 x 24 film at 4 samples a pixel,
   then checks:

   - the exit status, and for a refusal: exit 2, one line on stderr that starts with
     "lens2pov: " and holds the expected words (with LENS:LINE when a line of the file is to
     blame), and no output and no temporary file at all;
   - no non-finite number anywhere: every CSV field, the include's vertex block (digits and
     punctuation only) and translate, and every face as POV-Ray will hold it (float32 vertices,
     the normal of the triangle);
   - the include is the CSV: each face, read the way POV-Ray reads it, is within 1e-5 of the
     lens's size and 1e-5 rad of its CSV row in world space;
   - the emitted rays are the camera's: the same options through cli_parse and camera_setup in
     this process reproduce every sample (camera_trace_batch, the tool's code path, in the
     tool's order), and the rays that pass are the CSV's rows bit for bit. The CSV is written
     with 17 digits, so what is said below of the in-process rays is said of the tool's output;
   - every emitted ray traced back: backed out of the lens along its direction, reversed, traced
     toward the film through every surface (double, trace_toward_film, as a user would check)
     and carried to z = 0, it lands on the film point it claims, within BACK_TRACE_BOUND = 1e-9
     of the larger of the lens's size and the film diagonal;
   - the precision reference: the same film ray (the film point and the direction toward the
     same pupil sample, both exact doubles) traced toward the scene by the double tracer and by
     the kernel built in long double (tests/precision_trace.c). Both execute the same formulas
     in the same order on the same numbers (the lens's numbers are doubles, exact in both), so
     the difference is the double tracer's own rounding error, to within 2^-11 of itself.
     Reported: the largest angle between the outgoing directions (radians) and the largest
     distance between the outgoing origins relative to the lens's size; both are asserted to be
     at most PRECISION_BOUND = 1e-9 on every ray that is not within a hair of grazing. The two
     precisions must agree on which samples pass, except within 1e-9 of the lens's size from a
     rim or within the hair;
   - the behaviour: which fraction of the samples passes, and why the others are blocked
     (missed a surface, clipped by an aperture, total internal reflection).

   The bound, and why it can be defended. Each surface costs the double tracer some 40
   roundings of 1.1e-16; refraction amplifies an error in the direction by up to 1 / cos of the
   refracted angle, and an intersection an error in the position by 1 / cos of the incidence.
   So on rays whose every cosine (incidence and refraction, at every surface) is at least
   HAIR_COS = 1e-3 - farther than 0.06 degrees from grazing or from the critical angle - the
   error is at most ~ 15 surfaces x 40 x 1.1e-16 x 1e3 ~ 7e-11, and 1e-9 holds with room to
   spare (measured: at most 2e-13, on the hemisphere's rim). Within the hair the problem itself
   is ill-conditioned whatever the precision; the sweeps at the end go there (down to
   cos 4e-8) and assert the error stays below SWEEP_BOUND / cos.
   Two limits of camera space, whose coordinates are absolute: a film Z mm behind the lens
   leaves each z coordinate ulp(Z), and the back trace's error grows like Z^2 (measured: 5e-8 mm
   at Z = 1e5 mm, 0.04 mm at 1e8, 20 mm at 1.3e10 mm, the film of the most nearly afocal lens
   thick_lens_of accepts). Such a film must be refused (cases film-too-far, afocal-whole-*):
   at most 1000 times the lens's size, where the back trace stays within 2e-10 of the film.

   With L2P_STABILITY_REPORT=FILE in the environment each case appends one line (tab-separated)
   to FILE: tools/stability.sh prints them as the table of `make stability`. No .timeout on
   these tests: see tests/test_povray.c (a .timeout leaks under AddressSanitizer with --jobs). */
#include <criterion/criterion.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <unistd.h>
#include "camera/camera.h"
#include "cli/cli.h"
#include "precision_trace.h"
#include "support.h"

#define HAIR_COS 1e-3
#define PRECISION_BOUND 1e-9
#define BACK_TRACE_BOUND 1e-9
#define BACK_TRACE_BOUND_HAIR 1e-6

/* ---------------------------------------------------------------- generated lenses */

static char *text_printf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static char *text_printf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    const int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *s = malloc((size_t)n + 1);
    va_start(ap, fmt);
    vsnprintf(s, (size_t)n + 1, fmt, ap);
    va_end(ap);
    return s;
}

/* A bundled lens with every length (radius, thickness, aperture) multiplied by scale and,
   when extra_front is not NULL, more rows in front of it. */
static char *bundled_scaled(const char *name, double scale, const char *extra_front,
                            const char *extra_rear)
{
    char path[512];
    snprintf(path, sizeof path, LENS_DIR "%s.dat", name);
    lens l;
    l2p_error err;
    cr_assert_eq(lens_read(path, &l, &err), 0, "%s", err.text);
    size_t cap = 8192, len = 0;
    char *s = malloc(cap);
    len += (size_t)snprintf(s + len, cap - len, "# %s x %g (generated by test_stability.c)\n%s",
                            name, scale, extra_front ? extra_front : "");
    for (int i = 0; i < l.count; i++) {
        const lens_surface *f = &l.surface[i];
        const double thickness = i == l.count - 1 && extra_rear ? 1.0 : f->thickness_mm;
        len += (size_t)snprintf(s + len, cap - len, "%.17g %.17g %.17g %.17g\n",
                                f->radius_mm * scale, thickness * scale,
                                f->radius_mm == 0.0 && f->ior == 1.0 ? 0.0 : f->ior,
                                f->aperture_diameter_mm * scale);
    }
    if (extra_rear)
        snprintf(s + len, cap - len, "%s", extra_rear);
    lens_free(&l);
    return s;
}

static char *lens_dgauss(void) { return bundled_scaled("dgauss.50mm", 1.0, NULL, NULL); }
static char *lens_fisheye(void) { return bundled_scaled("fisheye.10mm", 1.0, NULL, NULL); }
static char *lens_dgauss_milli(void) { return bundled_scaled("dgauss.50mm", 1e-3, NULL, NULL); }
static char *lens_dgauss_kilo(void) { return bundled_scaled("dgauss.50mm", 1e3, NULL, NULL); }

/* The double Gauss behind a window whose faces are near-flat (radius +-R), and in front of a
   near-flat field plate: four surfaces of |radius| R. */
static char *near_flat(double R)
{
    char *front = text_printf("%.17g 2 1.5 30\n%.17g 3 1 30\n", R, -R);
    char *rear = text_printf("%.17g 1 1.52 20\n%.17g 0 1 20\n", -R, R);
    char *s = bundled_scaled("dgauss.50mm", 1.0, front, rear);
    free(front);
    free(rear);
    return s;
}
static char *lens_flat_1e6(void) { return near_flat(1e6); }
static char *lens_flat_1e9(void) { return near_flat(1e9); }
static char *lens_flat_1e12(void) { return near_flat(1e12); }
static char *lens_flat_m1e12(void) { return near_flat(-1e12); }

/* A stop, a near-flat entrance face, and a full hemisphere (aperture = 2 |R|) facing the
   film: rays aimed at the rear rim (--pupil rear) meet the hemisphere at grazing incidence. */
static char *lens_hemisphere(void)
{
    return strdup("# full hemisphere facing the film, met at grazing incidence\n"
                  "0      2   0    12\n"
                  "1e15   10  1.5  20\n"
                  "-10    0   1    20\n");
}

/* A hemisphere toward the scene, a flat back, the stop behind it: rays from the film enter
   the glass through the flat and meet the hemisphere from inside, past the critical angle
   toward its rim. */
static char *lens_tir(void)
{
    return strdup("# hemisphere toward the scene, met from inside: total internal reflection\n"
                  "10     10  1.5  20\n"
                  "-1e15  2   1    20\n"
                  "0      0   0    16\n");
}

/* A ball lens (two hemispheres) with the stop behind it: a ray parallel to the axis just
   inside the rim meets the rear hemisphere at grazing incidence, and leaves the front one
   symmetrically (a sphere never reflects totally what it let in). */
static char *lens_ball(void)
{
    return strdup("# ball lens, stop behind it\n"
                  "10     20  1.5  20\n"
                  "-10    2   1    20\n"
                  "0      0   0    20\n");
}

static char *lens_stop_first(void)
{
    return strdup("0     3    0     10\n"
                  "30    5    1.6   20\n"
                  "-60   0    1     20\n");
}

static char *lens_stop_last(void)
{
    return strdup("30    5    1.6   20\n"
                  "-60   2    1     20\n"
                  "0     0    0     10\n");
}

/* A dummy surface behind the stop, air on both sides, as design programs export: it bends no
   ray, so the stop is its own exit pupil. */
static char *lens_dummy_after_stop(void)
{
    return strdup("50    6    1.5   25\n"
                  "-50   1    1     25\n"
                  "0     4.5  0     17.1\n"
                  "40    0    1     20\n");
}

/* One refracting surface: the film lies in the glass behind it. */
static char *lens_single_surface(void)
{
    return strdup("0     5    0     10\n"
                  "20    0    1.5   30\n");
}

/* A thick meniscus of index 1.5 and thickness 6 is afocal when R2 = R1 - (n - 1) t / n:
   R1 = 20, R2 = 18. Behind a positive singlet and the stop, R2 = 18 + 1e-6 gives a subsystem
   (the stop-image pupil's) whose focal length is some 1e8 mm, thirty million times its size. */
static char *nearly_afocal_behind_stop(const char *r2)
{
    return text_printf("50    4    1.6   20\n"
                       "-200  3    1     20\n"
                       "0     3    0     10\n"
                       "20    6    1.5   16\n"
                       "%s    0    1     16\n", r2);
}
static char *lens_afocal_rear_near(void) { return nearly_afocal_behind_stop("18.000001"); }

/* The whole lens nearly afocal: the meniscus alone behind a stop. */
static char *lens_afocal_whole_near(void)
{
    return strdup("0     3    0     10\n"
                  "20    6    1.5   16\n"
                  "18.0001 0  1     16\n");
}

static char *lens_afocal_whole_edge(void)
{
    return strdup("0     3    0     10\n"
                  "20    6    1.5   16\n"
                  "18.00000005 0 1  16\n");
}

static char *lens_afocal_whole_exact(void)
{
    return strdup("0     3    0     10\n"
                  "20    6    1.5   16\n"
                  "18    0    1     16\n");
}

/* A concave rear surface (radius > 0: its rim lies behind its vertex, toward the film): with
   the film at the rear vertex the film's off-axis points are inside the glass. */
static char *lens_concave_rear(void)
{
    return strdup("0     3    0     10\n"
                  "30    5    1.6   20\n"
                  "25    0    1     20\n");
}

/* ---------------------------------------------------------------- the cases */

typedef struct stab_case {
    const char *name;
    const char *what;
    char *(*lens)(void);           /* the lens file's text (malloc'd) */
    const char *args;              /* options after LENS, space-separated */
    const char *refusal;           /* words of the refusal (exit 2); NULL: traced */
    int refusal_line;              /* > 0: the refusal names LENS:refusal_line */
    double pass_min, pass_max;     /* fraction of the samples that pass */
    bool tir;                      /* some samples end in total internal reflection */
    bool closest_focus;            /* args get "--focus-distance D", D the closest possible */
} stab_case;

enum { WIDTH = 32, HEIGHT = 24, SPP = 4 };

/* ---------------------------------------------------------------- report */

typedef struct stab_result {
    long long samples, passed, missed, clipped, tir;
    long long hair;                /* passing rays within a hair of grazing */
    long long disagree, disagree_hair;  /* double and long double differ on passing */
    double max_angle, max_pos;     /* double vs long double, rays not within a hair */
    double max_angle_hair, max_pos_hair;
    double max_back, max_back_ld;  /* back-trace landing error / scale: double, long double */
    double scale_mm;
    double max_pov_pos, max_pov_angle;   /* the include as POV-Ray reads it vs the CSV */
    bool full;                           /* full simulation (else thick: no comparison) */
    char outcome[512];
} stab_result;

/* One line a case, tab-separated: name, what, traced|refused, behaviour, then for a traced
   case the largest angle and position differences against long double, the largest
   back-trace landing error, the largest angle between the CSV and the include as POV-Ray
   reads it, the rays within a hair of grazing (count and their largest angle difference),
   and the samples the two precisions disagree on (passing or blocked). */
static void report(const stab_case *sc, const stab_result *r)
{
    const char *file = getenv("L2P_STABILITY_REPORT");
    if (!file || !*file)
        return;
    char line[2048];
    int n;
    if (sc->refusal)
        n = snprintf(line, sizeof line, "%s\t%s\t%s\t%s\n", sc->name, sc->what,
                     strncmp(r->outcome, "FAILS", 5) ? "refused" : "FAILED",
                     r->outcome + (strncmp(r->outcome, "FAILS", 5) ? 0 : 7));
    else if (!r->full)
        n = snprintf(line, sizeof line,
                     "%s\t%s\ttraced\t%.1f%% pass (thick-lens tracing: no surface blocks)%s"
                     "\t-\t-\t-\t%.1e\t-\t-\n", sc->name, sc->what,
                     100.0 * (double)r->passed / (double)r->samples, r->outcome, r->max_pov_angle);
    else
        n = snprintf(line, sizeof line,
                     "%s\t%s\ttraced\t%.1f%% pass; blocked: %.1f%% clipped, %.1f%% missed, "
                     "%.1f%% TIR%s\t%.1e\t%.1e\t%.1e\t%.1e\t%lld (%.1e)\t%lld\n",
                     sc->name, sc->what, 100.0 * (double)r->passed / (double)r->samples,
                     100.0 * (double)r->clipped / (double)r->samples,
                     100.0 * (double)r->missed / (double)r->samples,
                     100.0 * (double)r->tir / (double)r->samples, r->outcome, r->max_angle,
                     r->max_pos, r->max_back, r->max_pov_angle, r->hair, r->max_angle_hair,
                     r->disagree);
    int fd = open(file, O_WRONLY | O_APPEND | O_CREAT, 0644);
    if (fd >= 0) {
        cr_expect_eq(write(fd, line, (size_t)n), n);
        close(fd);
    }
}

/* ---------------------------------------------------------------- checks */

/* Nothing but the lens file in dir: no output and no temporary file. */
static void expect_no_outputs(const char *dir)
{
    DIR *d = opendir(dir);
    cr_assert_not_null(d);
    for (struct dirent *e; (e = readdir(d)) != NULL;)
        cr_expect(!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") ||
                      !strcmp(e->d_name, "case.dat"),
                  "a refused run left %s/%s", dir, e->d_name);
    closedir(d);
}

/* Every number of the include finite, as POV-Ray will hold it (vertices as float32). */
static size_t check_include(const char *path)
{
    size_t n;
    pov_ray *rays = read_include_as_povray(path, &n);
    for (size_t k = 0; k < n; k++)
        cr_assert(v3_isfinite(rays[k].o) && v3_isfinite(rays[k].d),
                  "%s: face %zu is not finite for POV-Ray", path, k);
    free(rays);
    char *text = read_text(path, NULL);
    /* The vertex block holds numbers and punctuation only (no "nan", no "inf"). */
    const char *numbers = strstr(text, "vertex_vectors {"), *faces = strstr(text, "face_indices");
    cr_assert(numbers && faces && faces > numbers);
    numbers += strlen("vertex_vectors {");
    const size_t span = strspn(numbers, "0123456789<>,.+-eE \n}");
    cr_assert_geq(numbers + span, faces - 2, "%s: a non-number in the ray table: '%.20s'", path,
                  numbers + span);
    const char *t = strstr(faces, "translate <");
    cr_assert_not_null(t);
    char *end;
    t += strlen("translate <");
    for (int k = 0; k < 3; k++, t = end + 1) {
        cr_assert(isfinite(strtod(t, &end)) && end != t, "%s: translate not finite", path);
    }
    free(text);
    return n;
}

static double ld_dist(long double ax, long double ay, long double az, vec3 b)
{
    const long double x = ax - b.x, y = ay - b.y, z = az - b.z;
    return (double)sqrtl(x * x + y * y + z * z);
}

/* Lens size: the longest of its length and its widest aperture. */
static double lens_size_mm(const lens *l)
{
    double s = lens_total_length_mm(l);
    for (int i = 0; i < l->count; i++)
        s = fmax(s, l->surface[i].aperture_diameter_mm);
    return s;
}

/* Where an emitted ray lands on the film when traced back: in double, or in long double. */
static bool back_trace(const lens *l, const csv_ray *row, double back_mm, double *miss_mm)
{
    ray r = {v3_madd(row->o, row->d, back_mm), v3_scale(row->d, -1.0)};
    if (trace_toward_film(l, 0, l->count - 1, &r, NULL) != TRACE_PASSED || !(r.d.z < 0.0))
        return false;
    const double t = -r.o.z / r.d.z;
    *miss_mm = hypot(r.o.x + t * r.d.x - row->film_x, r.o.y + t * r.d.y - row->film_y);
    return isfinite(*miss_mm);
}

static bool back_trace_ld(const lens *l, const csv_ray *row, double back_mm, double *miss_mm)
{
    ld_ray r = {{(long double)row->o.x + (long double)row->d.x * back_mm,
                 (long double)row->o.y + (long double)row->d.y * back_mm,
                 (long double)row->o.z + (long double)row->d.z * back_mm},
                {-(long double)row->d.x, -(long double)row->d.y, -(long double)row->d.z}};
    if (precision_trace_range(l, 0, l->count - 1, false, &r, NULL) != TRACE_PASSED ||
        !(r.d.z < 0))
        return false;
    const long double t = -r.o.z / r.d.z;
    *miss_mm = (double)hypotl(r.o.x + t * r.d.x - row->film_x, r.o.y + t * r.d.y - row->film_y);
    return isfinite(*miss_mm);
}

/* Traces every sample of the camera in process (the tool's order: rows, pixels, samples) and
   checks them against the CSV, the back trace and the long double reference. */
static void check_rays(const stab_case *sc, const camera *cam, const csv_ray *rows, size_t nrows,
                       stab_result *res)
{
    const lens *l = &cam->lens;
    const double size = lens_size_mm(l);
    const double scale = fmax(size, cam->film.diagonal_mm);
    res->scale_mm = scale;
    res->full = cam->trace == TRACE_KIND_FULL;
    size_t next_row = 0;
    for (int py = cam->crop_y0; py < cam->crop_y1; py++) {
        /* One film row at a time, CAMERA_BATCH samples a batch, as raytable.c batches them. */
        const int row_samples = (cam->crop_x1 - cam->crop_x0) * cam->samples.spp;
        for (int b = 0; b < row_samples; b += CAMERA_BATCH) {
            const int m = row_samples - b < CAMERA_BATCH ? row_samples - b : CAMERA_BATCH;
            sample_batch batch = {.n = m};
            vec3 *film = batch.film_point;
            const double *u = batch.u, *v = batch.v, *w = batch.weight;
            const ray *out = batch.out;
            const bool *passed = batch.passed;
            for (int k = 0; k < m; k++) {
                const int px = cam->crop_x0 + (b + k) / cam->samples.spp;
                const film_sample fs = sample_pattern_get(&cam->samples, px, py,
                                                          (b + k) % cam->samples.spp);
                film[k] = film_camera_from_raster(&cam->film, px + fs.offset_x, py + fs.offset_y);
                batch.u[k] = fs.pupil_u;
                batch.v[k] = fs.pupil_v;
            }
            camera_trace_batch(cam, &batch);
                for (int k = 0; k < m; k++) {
                    res->samples++;
                    /* The same film ray, traced one at a time in double and in long double. */
                    vec3 d0;
                    const double w0 = pupil_film_ray(&cam->pupil, film[k], u[k], v[k], &d0);
                    ray rd = {film[k], d0};
                    int at = -1;
                    trace_status sd = w0 > 0 ? trace_toward_scene(l, 0, l->count - 1, &rd, &at)
                                             : TRACE_MISSED;
                    if (cam->trace == TRACE_KIND_FULL) {
                        cr_assert_eq(sd == TRACE_PASSED, passed[k],
                                     "%s: the batch and the one-ray tracer disagree on a sample",
                                     sc->name);
                    }
                    if (!passed[k]) {
                        res->missed += sd == TRACE_MISSED;
                        res->clipped += sd == TRACE_CLIPPED;
                        res->tir += sd == TRACE_TIR;
                        if (sd == TRACE_PASSED)
                            res->missed++;   /* thick trace: no real-lens reason */
                    }
                    const ld_ray start = {{film[k].x, film[k].y, film[k].z}, {d0.x, d0.y, d0.z}};
                    ld_ray rl = start;
                    trace_status sl = precision_trace_range(l, 0, l->count - 1, true, &rl, NULL);
                    precision_margin margin;
                    precision_margin_toward_scene(l, start, &margin);
                    const bool hair = margin.min_cos < HAIR_COS;
                    if (cam->trace == TRACE_KIND_FULL && w0 > 0) {
                        if ((sd == TRACE_PASSED) != (sl == TRACE_PASSED)) {
                            /* Only at the edge of an aperture or of a surface. */
                            res->disagree++;
                            const bool rim = fabsl(margin.min_rim_gap_mm) <= 1e-9L * size;
                            res->disagree_hair += hair || rim;
                            cr_expect(hair || rim,
                                      "%s: double says %d, long double %d, %Lg from a rim, "
                                      "cos %Lg", sc->name, sd, sl, margin.min_rim_gap_mm,
                                      margin.min_cos);
                        } else if (sd == TRACE_PASSED) {
                            const long double ex = rd.d.x - rl.d.x, ey = rd.d.y - rl.d.y,
                                              ez = rd.d.z - rl.d.z;
                            const double angle = (double)sqrtl(ex * ex + ey * ey + ez * ez);
                            const double pos = ld_dist(rl.o.x, rl.o.y, rl.o.z, rd.o) / size;
                            if (hair) {
                                res->hair++;
                                res->max_angle_hair = fmax(res->max_angle_hair, angle);
                                res->max_pos_hair = fmax(res->max_pos_hair, pos);
                            } else {
                                res->max_angle = fmax(res->max_angle, angle);
                                res->max_pos = fmax(res->max_pos, pos);
                                cr_expect_leq(angle, PRECISION_BOUND,
                                              "%s: direction off by %g rad (cos %Lg)", sc->name,
                                              angle, margin.min_cos);
                                cr_expect_leq(pos, PRECISION_BOUND,
                                              "%s: origin off by %g of the lens size", sc->name,
                                              pos);
                            }
                        }
                    }
                    if (!passed[k])
                        continue;
                    res->passed++;
                    /* The CSV's next row is this ray, bit for bit. */
                    cr_assert_lt(next_row, nrows, "%s: fewer CSV rows than rays that pass",
                                 sc->name);
                    const csv_ray *row = &rows[next_row++];
                    cr_assert(row->film_x == film[k].x && row->film_y == film[k].y &&
                                  row->o.x == out[k].o.x && row->o.y == out[k].o.y &&
                                  row->o.z == out[k].o.z && row->d.x == out[k].d.x &&
                                  row->d.y == out[k].d.y && row->d.z == out[k].d.z &&
                                  row->weight == w[k],
                              "%s: CSV row %zu is not the camera's ray", sc->name, next_row - 1);
                    cr_assert(isfinite(w[k]) && w[k] > 0, "%s: weight %g", sc->name, w[k]);
                    cr_assert_float_eq(v3_length(out[k].d), 1.0, 1e-15, "%s: |d| != 1", sc->name);
                    if (cam->trace != TRACE_KIND_FULL)
                        continue;
                    double miss = INFINITY, miss_ld = INFINITY;
                    const bool back = back_trace(l, row, size, &miss);
                    const bool back_ld = back_trace_ld(l, row, size, &miss_ld);
                    cr_expect(back || hair, "%s: CSV row %zu does not trace back (cos %Lg)",
                              sc->name, next_row - 1, margin.min_cos);
                    cr_expect(back_ld || hair,
                              "%s: CSV row %zu does not trace back in long double", sc->name,
                              next_row - 1);
                    if (back) {
                        res->max_back = fmax(res->max_back, miss / scale);
                        cr_expect_leq(miss / scale, hair ? BACK_TRACE_BOUND_HAIR : BACK_TRACE_BOUND,
                                      "%s: CSV row %zu lands %g mm off (cos %Lg)", sc->name,
                                      next_row - 1, miss, margin.min_cos);
                    }
                    if (back_ld)
                        res->max_back_ld = fmax(res->max_back_ld, miss_ld / scale);
                }
            }
        }
    cr_assert_eq(next_row, nrows, "%s: %zu CSV rows, %zu rays pass in process", sc->name, nrows,
                 next_row);
}

/* "... the closest is 1234.5 (film plane ..." -> 1234.5 */
static double closest_focus_of(const char *lens_path)
{
    char *errtext = NULL;
    const int st = run_lens2pov(NULL, &errtext, "info", lens_path, "--unit-mm", "1",
                                "--focus-distance", "1e-9", NULL);
    cr_assert_eq(st, 2, "focusing at 1e-9 mm: %s", errtext);
    const char *p = strstr(errtext, "the closest is ");
    cr_assert_not_null(p, "%s", errtext);
    const double d = strtod(p + 15, NULL);
    free(errtext);
    return d;
}

/* The command line of a case: trace LENS, the film, the case's options, --rays, -o.
   argv points into words and the other buffers of a. */
typedef struct case_args {
    char *argv[64];
    int argc;
    char words[512], size[3][16], closest[64];
} case_args;

static void build_args(const stab_case *sc, const char *lens_path, const char *prefix,
                       const char *csv, case_args *a)
{
    char **v = a->argv;
    int n = 0;
    v[n++] = "trace";
    v[n++] = (char *)lens_path;
    snprintf(a->size[0], 16, "%d", WIDTH);
    snprintf(a->size[1], 16, "%d", HEIGHT);
    snprintf(a->size[2], 16, "%d", SPP);
    v[n++] = "--width", v[n++] = a->size[0];
    v[n++] = "--height", v[n++] = a->size[1];
    v[n++] = "--spp", v[n++] = a->size[2];
    snprintf(a->words, sizeof a->words, "%s", sc->args ? sc->args : "");
    for (char *w = strtok(a->words, " "); w; w = strtok(NULL, " ")) {
        cr_assert_lt(n, 50, "%s: too many words", sc->name);
        v[n++] = w;
    }
    if (sc->closest_focus) {
        /* The message rounds to 6 digits: a millionth further is within reach. */
        snprintf(a->closest, sizeof a->closest, "%.9g", closest_focus_of(lens_path) * (1 + 1e-6));
        v[n++] = "--focus-distance";
        v[n++] = a->closest;
    }
    v[n++] = "--rays", v[n++] = (char *)csv;
    v[n++] = "-o", v[n++] = (char *)prefix;
    v[n++] = "--quiet";
    v[n] = NULL;
    a->argc = n;
}

/* A refused case: exit 2, one line "lens2pov: [LENS:LINE: ]..." with the case's words, and
   nothing written. */
static void check_refusal(const stab_case *sc, const char *dir, const char *lens_path,
                          const char *errtext)
{
    cr_assert(strncmp(errtext, "lens2pov: ", 10) == 0, "%s: %s", sc->name, errtext);
    cr_assert_not_null(strstr(errtext, sc->refusal), "%s: '%s' not in: %s", sc->name,
                       sc->refusal, errtext);
    if (sc->refusal_line > 0) {
        char where[600];
        snprintf(where, sizeof where, "lens2pov: %s:%d: ", lens_path, sc->refusal_line);
        cr_assert(strncmp(errtext, where, strlen(where)) == 0, "%s: expected '%s' in: %s",
                  sc->name, where, errtext);
    }
    cr_assert(strchr(errtext, '\n') == errtext + strlen(errtext) - 1, "%s: one line: %s",
              sc->name, errtext);
    expect_no_outputs(dir);
    stab_result res;
    memset(&res, 0, sizeof res);
    snprintf(res.outcome, sizeof res.outcome, "%.*s", (int)strcspn(errtext + 10, "\n"),
             errtext + 10);
    /* Shorten the temporary folder out of the message. */
    char *p = strstr(res.outcome, dir);
    if (p)
        memmove(p, p + strlen(dir) + 1, strlen(p + strlen(dir) + 1) + 1);
    report(sc, &res);
}

/* What POV-Ray will see (float32 vertices, the normal of each triangle) against the CSV in
   world space: within 1e-5 of the lens's size, and 1e-5 rad. A face's vertices lie within 128
   lone-triangle sizes (half the widest aperture) of the mesh's origin, so float32 moves its
   centroid by at most sqrt(3) 2^-24 128 / 2 = 6.6e-6 of the size. */
static void check_include_rays(const stab_case *sc, const camera *cam, const char *inc,
                               const csv_ray *rows, size_t nrows, stab_result *res)
{
    size_t nfaces;
    pov_ray *seen = read_include_as_povray(inc, &nfaces);
    const double size_units = lens_size_mm(&cam->lens) / cam->unit_mm;
    for (size_t k = 0; k < nrows; k++) {
        const vec3 o = camera_world_from_camera_point(cam, rows[k].o);
        const vec3 d = camera_world_from_camera_dir(cam, rows[k].d);
        const double off = v3_length(v3_sub(seen[k].o, o)) / size_units;
        const double angle = v3_length(v3_sub(seen[k].d, d));
        res->max_pov_pos = fmax(res->max_pov_pos, off);
        res->max_pov_angle = fmax(res->max_pov_angle, angle);
        cr_expect(off <= 1e-5 && angle <= 1e-5,
                  "%s: face %zu is %g of the lens size and %g rad off its CSV row", sc->name, k,
                  off, angle);
    }
    free(seen);
}

/* A traced case: finite numbers everywhere, one face a ray, every ray against long double
   and traced back (check_rays), the include against the CSV, the share that passes. */
static void check_traced(const stab_case *sc, const case_args *a, const char *lens_path,
                         const char *prefix, const char *csv)
{
    stab_result res;
    memset(&res, 0, sizeof res);
    char *info_err = NULL;   /* a lens trace takes, info describes */
    const int info_st = run_lens2pov(NULL, &info_err, "info", lens_path, NULL);
    cr_expect_eq(info_st, 0, "%s: trace takes the lens, info refuses it: %s", sc->name, info_err);
    free(info_err);
    size_t nrows;
    csv_ray *rows = read_rays_csv(csv, &nrows);
    for (size_t k = 0; k < nrows; k++) {
        const csv_ray *r = &rows[k];
        cr_assert(isfinite(r->raster_x) && isfinite(r->raster_y) && isfinite(r->film_x) &&
                      isfinite(r->film_y) && v3_isfinite(r->o) && v3_isfinite(r->d) &&
                      isfinite(r->weight),
                  "%s: CSV row %zu has a non-finite number", sc->name, k);
    }
    char inc[600];
    snprintf(inc, sizeof inc, "%s.inc", prefix);
    const size_t faces = check_include(inc);
    cr_assert_eq(faces, nrows ? nrows : 1, "%s: one face a ray", sc->name);

    /* The same camera in process. */
    cli c;
    l2p_error err;
    char *argv[66] = {"lens2pov"};
    memcpy(argv + 1, a->argv, sizeof a->argv);
    cr_assert_eq(cli_parse(&c, a->argc + 1, argv, 2, &err), 0, "%s", err.text);
    lens l;
    cr_assert_eq(lens_read(lens_path, &l, &err), 0, "%s", err.text);
    camera cam;
    cr_assert_eq(camera_setup(&cam, &l, &c.cam, &err), 0, "%s", err.text);
    check_rays(sc, &cam, rows, nrows, &res);
    check_include_rays(sc, &cam, inc, rows, nrows, &res);
    free(rows);

    const double pass = (double)res.passed / (double)res.samples;
    cr_expect(pass >= sc->pass_min && pass <= sc->pass_max,
              "%s: %.2f%% of the rays pass, expected %.2f%% .. %.2f%%", sc->name, 100 * pass,
              100 * sc->pass_min, 100 * sc->pass_max);
    if (sc->tir)
        cr_expect_gt(res.tir, 0, "%s: no total internal reflection", sc->name);
    snprintf(res.outcome, sizeof res.outcome, "; film distance %.6g mm", cam.lens.film_distance_mm);
    report(sc, &res);
    cr_log_info("%s: %.1f%% pass, angle %.2e pos %.2e back %.2e (hair %lld: %.2e %.2e) "
                "disagree %lld/%lld back_ld %.2e", sc->name, 100 * pass, res.max_angle,
                res.max_pos, res.max_back, res.hair, res.max_angle_hair, res.max_pos_hair,
                res.disagree, res.disagree_hair, res.max_back_ld);
    camera_free(&cam);
}

static void run_case(const stab_case *sc)
{
    const char *dir = test_tmpdir();
    char lens_path[512], prefix[512], csv[512];
    snprintf(lens_path, sizeof lens_path, "%s/case.dat", dir);
    snprintf(prefix, sizeof prefix, "%s/out", dir);
    snprintf(csv, sizeof csv, "%s/out.csv", dir);
    char *text = sc->lens();
    write_text(lens_path, text);
    free(text);
    case_args a;
    build_args(sc, lens_path, prefix, csv, &a);
    char *stderr_text = NULL;
    const int st = run_lens2pov_argv(NULL, &stderr_text, a.argv);
    /* A copy on the stack: a failed assertion leaves the test without freeing anything. */
    char errtext[2048];
    snprintf(errtext, sizeof errtext, "%s", stderr_text ? stderr_text : "");
    free(stderr_text);
    const int expected = sc->refusal ? 2 : 0;
    if (st != expected) {
        /* Into the table too, so that `make stability` shows what happens instead. */
        const stab_case shown = {.name = sc->name, .what = sc->what, .refusal = ""};
        stab_result res;
        memset(&res, 0, sizeof res);
        snprintf(res.outcome, sizeof res.outcome, "FAILS: exit %d, expected %d%s%.*s", st,
                 expected, *errtext ? ": " : "", (int)strcspn(errtext, "\n"), errtext);
        report(&shown, &res);
    }
    cr_assert_eq(st, expected, "%s: exit %d, expected %d: %s", sc->name, st, expected, errtext);
    if (sc->refusal)
        check_refusal(sc, dir, lens_path, errtext);
    else
        check_traced(sc, &a, lens_path, prefix, csv);
}

/* ---------------------------------------------------------------- the table */

static const stab_case CASES[] = {
    {.name = "flat-1e6",
     .what = "near-flat surfaces |R| = 1e6 (window and plate around the double Gauss)",
     .lens = lens_flat_1e6, .args = "--focus-distance 3", .pass_min = 0.5, .pass_max = 1.0},
    {.name = "flat-1e9", .what = "near-flat surfaces |R| = 1e9", .lens = lens_flat_1e9,
     .args = "--focus-distance 3", .pass_min = 0.5, .pass_max = 1.0},
    {.name = "flat-1e12", .what = "near-flat surfaces |R| = 1e12", .lens = lens_flat_1e12,
     .args = "--focus-distance 3", .pass_min = 0.5, .pass_max = 1.0},
    {.name = "flat-m1e12", .what = "near-flat surfaces |R| = 1e12, signs swapped",
     .lens = lens_flat_m1e12, .args = "--focus-distance 3", .pass_min = 0.5, .pass_max = 1.0},
    {.name = "hemisphere", .what = "full hemisphere facing the film, rear pupil on its rim",
     .lens = lens_hemisphere, .args = "--pupil rear --focus-distance inf --film-diagonal 20",
     .pass_min = 0.05, .pass_max = 1.0},
    {.name = "tir", .what = "total internal reflection inside the field", .lens = lens_tir,
     .args = "--focus-distance inf --film-diagonal 60 --pupil stop", .pass_min = 0.05,
     .pass_max = 0.95, .tir = true},
    {.name = "fisheye-corners", .what = "fisheye, full-frame film (43.3 mm): its corners",
     .lens = lens_fisheye, .args = "--film-diagonal 43.3 --focus-distance 3", .pass_min = 0.2,
     .pass_max = 1.0},
    /* Film points beyond the image circle produce no samples (the pupil's reach): the samples
       left are those inside it, near its rim. */
    {.name = "fisheye-beyond", .what = "fisheye, 200 mm film: far beyond its image circle",
     .lens = lens_fisheye, .args = "--film-diagonal 200 --focus-distance 3 --pupil rear",
     .pass_min = 0.001, .pass_max = 1.0},
    {.name = "scale-1e-3", .what = "double Gauss scaled by 1e-3 (f = 50 um)",
     .lens = lens_dgauss_milli, .args = "--film-diagonal 0.035 --unit-mm 1 --focus-distance 3",
     .pass_min = 0.5, .pass_max = 1.0},
    {.name = "scale-1e3", .what = "double Gauss scaled by 1e3 (f = 50 m)",
     .lens = lens_dgauss_kilo, .args = "--film-diagonal 35000 --unit-mm 1 --focus-distance 3e6",
     .pass_min = 0.5, .pass_max = 1.0},
    /* The stop-image pupil is fitted with real rays: it follows a 1 um stop off axis, where
       the stop's paraxial image misses it (pupil aberration). */
    {.name = "aperture-1um", .what = "aperture 1e-3 mm (stop-image pupil)", .lens = lens_dgauss,
     .args = "--aperture-diameter 0.001", .pass_min = 0.005, .pass_max = 1.0},
    {.name = "focus-inf", .what = "focus at infinity", .lens = lens_dgauss,
     .args = "--focus-distance inf", .pass_min = 0.5, .pass_max = 1.0},
    {.name = "focus-closest", .what = "focus at the closest distance the lens allows",
     .lens = lens_dgauss, .args = "--unit-mm 1", .pass_min = 0.2, .pass_max = 1.0,
     .closest_focus = true},
    {.name = "focus-too-close", .what = "focus closer than the lens allows", .lens = lens_dgauss,
     .args = "--focus-distance 0.05",
     .refusal = "closer than this lens can focus: the closest is "},
    /* Without --focus-distance the look-at point sets it, and the refusal says so. */
    {.name = "look-at-too-close", .what = "look-at point closer than the lens focuses",
     .lens = lens_dgauss, .args = "--look-at 0,0,0.05",
     .refusal = "the look-at point, 0.05 away, is closer than this lens can focus (the closest "
                "is "},
    {.name = "afocal-rear-near",
     .what = "nearly afocal subsystem behind the stop (stop-image pupil)",
     .lens = lens_afocal_rear_near, .args = "--focus-distance 3", .pass_min = 0.05,
     .pass_max = 1.0},
    {.name = "afocal-whole", .what = "afocal whole lens", .lens = lens_afocal_whole_exact,
     .args = "--focus-distance inf", .refusal = "form an afocal system", .refusal_line = 1},
    /* Camera space is absolute: a film 6.5e6 mm behind the lens leaves each coordinate
       ulp(6.5e6) = 1e-9 mm, and the error grows like (film distance)^2 on the way back to the
       film (0.04 mm at 1e8 mm, 20 mm at 1.3e10 mm, the most thick_lens_of accepts). Such a
       film is refused: at most FILM_DISTANCE_MAX_RATIO (1000) times the lens's size. */
    {.name = "afocal-whole-near",
     .what = "nearly afocal whole lens (f = 7e6 mm), focus at infinity",
     .lens = lens_afocal_whole_near, .args = "--focus-distance inf", .refusal = "too far",
     .refusal_line = 1},
    {.name = "afocal-whole-edge",
     .what = "nearly afocal whole lens (f = 1.3e10 mm, the most accepted as focal)",
     .lens = lens_afocal_whole_edge, .args = "--focus-distance inf", .refusal = "too far",
     .refusal_line = 1},
    {.name = "film-far", .what = "film 1e4 mm behind the double Gauss (300 times its size)",
     .lens = lens_dgauss, .args = "--film-distance 1e4", .pass_min = 0.2, .pass_max = 1.0},
    {.name = "film-too-far", .what = "film 1e5 mm behind the double Gauss (3000 times its size)",
     .lens = lens_dgauss, .args = "--film-distance 1e5", .refusal = "too far"},
    {.name = "stop-first", .what = "the stop as the first surface", .lens = lens_stop_first,
     .args = "--focus-distance 3", .pass_min = 0.5, .pass_max = 1.0},
    {.name = "stop-last", .what = "the stop as the last surface", .lens = lens_stop_last,
     .args = "--focus-distance 3", .pass_min = 0.5, .pass_max = 1.0},
    {.name = "dummy-after-stop", .what = "an air-to-air surface behind the stop",
     .lens = lens_dummy_after_stop, .args = "--focus-distance 3", .pass_min = 0.9, .pass_max = 1.0},
    {.name = "single-surface", .what = "a single refracting surface (film in the glass)",
     .lens = lens_single_surface, .args = "--focus-distance 3 --film-diagonal 10", .pass_min = 0.5,
     .pass_max = 1.0},
    /* The stop-image pupil is fitted to the passing rays and aims at none that reflect;
       the rear pupil (next) aims at them. */
    {.name = "film-distance-0", .what = "film distance 0 (film on the rear vertex)",
     .lens = lens_dgauss, .args = "--film-distance 0", .pass_min = 0.05, .pass_max = 1.0},
    {.name = "film-distance-0-rear", .what = "film distance 0, rear pupil", .lens = lens_dgauss,
     .args = "--film-distance 0 --pupil rear", .pass_min = 0.0005, .pass_max = 1.0, .tir = true},
    {.name = "film-distance-0-stop-last",
     .what = "film distance 0 with the stop last: pupil in the film plane", .lens = lens_stop_last,
     .args = "--film-distance 0", .refusal = "lies in the film plane", .refusal_line = 3},
    {.name = "film-in-glass", .what = "film distance 0 behind a concave rear surface",
     .lens = lens_concave_rear, .args = "--film-distance 0", .refusal = "inside the lens",
     .refusal_line = 3},
    /* The extremes of --unit-mm: the include must stay within float32 for POV-Ray. */
    {.name = "unit-um", .what = "scene units of 1 um (--unit-mm 1e-3), lens x 1e3",
     .lens = lens_dgauss_kilo, .args = "--film-diagonal 35000 --unit-mm 1e-3 --focus-distance 3e9",
     .pass_min = 0.5, .pass_max = 1.0},
    {.name = "unit-1000km", .what = "scene units of 1000 km (--unit-mm 1e9), lens x 1e-3",
     .lens = lens_dgauss_milli,
     .args = "--film-diagonal 0.035 --unit-mm 1e9 --focus-distance 3e-9", .pass_min = 0.5,
     .pass_max = 1.0},
    {.name = "thick-trace", .what = "thick-lens tracing of the fisheye, 200 mm film",
     .lens = lens_fisheye, .args = "--trace thick --film-diagonal 200", .pass_min = 0.0,
     .pass_max = 1.0},
};

enum { CASE_COUNT = sizeof CASES / sizeof CASES[0] };

static const stab_case *find_case(const char *name)
{
    for (int i = 0; i < CASE_COUNT; i++)
        if (!strcmp(CASES[i].name, name))
            return &CASES[i];
    cr_assert_fail("no case %s", name);
    return NULL;
}

#define STAB_TEST(id, name) \
    Test(stability, id) { run_case(find_case(name)); }

STAB_TEST(near_flat_1e6, "flat-1e6")
STAB_TEST(near_flat_1e9, "flat-1e9")
STAB_TEST(near_flat_1e12, "flat-1e12")
STAB_TEST(near_flat_minus_1e12, "flat-m1e12")
STAB_TEST(hemisphere_rim, "hemisphere")
STAB_TEST(total_internal_reflection, "tir")
STAB_TEST(fisheye_corners, "fisheye-corners")
STAB_TEST(fisheye_film_beyond_image_circle, "fisheye-beyond")
STAB_TEST(lens_scaled_1e_minus_3, "scale-1e-3")
STAB_TEST(lens_scaled_1e3, "scale-1e3")
STAB_TEST(aperture_1um, "aperture-1um")
STAB_TEST(focus_at_infinity, "focus-inf")
STAB_TEST(focus_at_the_closest_distance, "focus-closest")
STAB_TEST(focus_closer_than_possible_is_refused, "focus-too-close")
STAB_TEST(look_at_closer_than_possible_is_refused, "look-at-too-close")
STAB_TEST(nearly_afocal_subsystem_behind_the_stop, "afocal-rear-near")
STAB_TEST(afocal_whole_lens_is_refused, "afocal-whole")
STAB_TEST(nearly_afocal_whole_lens_is_refused, "afocal-whole-near")
STAB_TEST(nearly_afocal_whole_lens_at_the_limit_is_refused, "afocal-whole-edge")
STAB_TEST(film_far_behind_the_lens, "film-far")
STAB_TEST(film_too_far_behind_the_lens_is_refused, "film-too-far")
STAB_TEST(stop_first, "stop-first")
STAB_TEST(stop_last, "stop-last")
STAB_TEST(dummy_surface_behind_the_stop, "dummy-after-stop")
STAB_TEST(single_refracting_surface, "single-surface")
STAB_TEST(film_distance_0, "film-distance-0")
STAB_TEST(film_distance_0_rear_pupil, "film-distance-0-rear")
STAB_TEST(film_distance_0_pupil_in_film_plane_is_refused, "film-distance-0-stop-last")
STAB_TEST(film_inside_the_glass_is_refused, "film-in-glass")
STAB_TEST(thick_trace_far_field, "thick-trace")
STAB_TEST(scene_units_of_a_micrometre, "unit-um")
STAB_TEST(scene_units_of_1000_km, "unit-1000km")

/* Every case's ray on the axis (film centre, pupil centre) stays exactly on the axis, in
   double and in long double. */
Test(stability, rays_exactly_on_the_axis_stay_on_it)
{
    char *(*makers[])(void) = {lens_dgauss, lens_fisheye, lens_flat_1e12, lens_hemisphere,
                               lens_tir, lens_stop_first, lens_stop_last, lens_single_surface,
                               lens_dgauss_milli, lens_dgauss_kilo, lens_afocal_rear_near};
    for (size_t i = 0; i < sizeof makers / sizeof makers[0]; i++) {
        char *text = makers[i]();
        lens l;
        l2p_error err;
        cr_assert_eq(lens_parse(text, strlen(text), "axis.dat", &l, &err), 0, "%s", err.text);
        free(text);
        camera_options o;
        camera_options_default(&o);
        o.focus_distance_units = INFINITY;
        o.weighting = WEIGHTING_PHYSICAL;
        camera cam;
        cr_assert_eq(camera_setup(&cam, &l, &o, &err), 0, "lens %zu: %s", i, err.text);
        ray r;
        double w;
        cr_assert(camera_trace(&cam, v3(0, 0, 0), 0.5, 0.5, &r, &w), "lens %zu: axis blocked", i);
        cr_expect(r.o.x == 0 && r.o.y == 0 && r.d.x == 0 && r.d.y == 0 && r.d.z == 1,
                  "lens %zu: axis ray leaves at (%g %g %g) along (%g %g %g)", i, r.o.x, r.o.y,
                  r.o.z, r.d.x, r.d.y, r.d.z);
        cr_expect_eq(r.o.z, cam.lens.surface[0].vertex_z_mm, "lens %zu: on the front vertex", i);
        long double o3[3] = {0, 0, 0}, d3[3] = {0, 0, 1};
        cr_assert_eq(precision_trace_toward_scene(&cam.lens, o3, d3), TRACE_PASSED);
        cr_expect(o3[0] == 0 && o3[1] == 0 && d3[0] == 0 && d3[1] == 0 && d3[2] == 1,
                  "lens %zu: long double axis ray off the axis", i);
        /* And back toward the film. */
        ray back = {v3(0, 0, r.o.z + 10), v3(0, 0, -1)};
        cr_assert_eq(trace_toward_film(&cam.lens, 0, cam.lens.count - 1, &back, NULL), TRACE_PASSED);
        cr_expect(back.o.x == 0 && back.o.y == 0 && back.d.x == 0 && back.d.y == 0 && back.d.z == -1);
        camera_free(&cam);
    }
}

/* ---------------------------------------------------------------- sweeps to grazing */

/* Rays parallel to the axis from the film at heights h_k = edge (1 -+ 10^-k), k = 1 .. 15,
   toward a surface that they meet ever closer to grazing incidence (the rim of a ball lens's
   hemisphere) or to the critical angle (inside the glass, toward the hemisphere of lens_tir).
   The error of the double tracer against long double grows like 1 / cos (cos: the smallest
   cosine of incidence or refraction on the path); asserted: angle and position error at most
   SWEEP_BOUND / cos, every passing ray finite, and the double and long double tracers agree
   on passing unless cos < 1e-6. Measured (see the --verbose log): angle x cos stays below
   3e-15.
   The back trace: a ray that leaves a surface at cos ~ 1e-5 carries an error of ~ 1e-10 in
   cos^2, the margin by which it escapes total internal reflection on the way back: below
   SWEEP_BACK_COS = 1e-4 the reversed ray may not get back at all (observed from cos 1.4e-5
   down), which is the problem's conditioning, not the tracer's. At or above it the back trace
   must land within BACK_TRACE_BOUND of the lens size. */
#define SWEEP_BOUND 1e-13
#define SWEEP_BACK_COS 1e-4

static void sweep(const char *name, const char *what, char *(*make_lens)(void),
                  double film_distance_mm, double edge_mm, double sign)
{
    double worst_scaled = 0, worst_angle = 0, lowest_cos = 1, back_fails_at = 0;
    int passed = 0, blocked = 0;
    char *text = make_lens();
    lens l;
    l2p_error err;
    cr_assert_eq(lens_parse(text, strlen(text), name, &l, &err), 0, "%s", err.text);
    free(text);
    lens_set_film_distance(&l, film_distance_mm);
    const double size = lens_size_mm(&l);
    for (int k = 1; k <= 15; k++) {
        const double h = edge_mm * (1 + sign * pow(10.0, -k));
        ray rd = {v3(0, h, 0), v3(0, 0, 1)};
        const ld_ray start = {{0, h, 0}, {0, 0, 1}};
        ld_ray rl = start;
        const trace_status sd = trace_toward_scene(&l, 0, l.count - 1, &rd, NULL);
        const trace_status sl = precision_trace_range(&l, 0, l.count - 1, true, &rl, NULL);
        precision_margin m;
        precision_margin_toward_scene(&l, start, &m);
        if (sd != TRACE_PASSED || sl != TRACE_PASSED) {
            cr_expect(sd == sl || m.min_cos < 1e-6,
                      "%s k=%d: double %d, long double %d, cos %Lg", name, k, sd, sl, m.min_cos);
            cr_log_info("%s h=edge(1%+.0e): double %d long double %d, cos %.2Le", name,
                        sign * pow(10.0, -k), sd, sl, m.min_cos);
            blocked++;
            continue;
        }
        cr_assert(v3_isfinite(rd.o) && v3_isfinite(rd.d), "%s k=%d: not finite", name, k);
        const long double ex = rd.d.x - rl.d.x, ey = rd.d.y - rl.d.y, ez = rd.d.z - rl.d.z;
        const double angle = (double)sqrtl(ex * ex + ey * ey + ez * ez);
        const double pos = ld_dist(rl.o.x, rl.o.y, rl.o.z, rd.o) / size;
        cr_expect_leq(angle * (double)m.min_cos, SWEEP_BOUND, "%s k=%d: angle %g at cos %Lg", name,
                      k, angle, m.min_cos);
        cr_expect_leq(pos * (double)m.min_cos, SWEEP_BOUND, "%s k=%d: position %g at cos %Lg",
                      name, k, pos, m.min_cos);
        const csv_ray row = {0, 0, 0, h, rd.o, rd.d, 1};
        double miss = NAN;
        const bool back = back_trace(&l, &row, size, &miss);
        cr_log_info("%s h=edge(1%+.0e): cos %.2Le angle %.2e pos %.2e back %s %.2e", name,
                    sign * pow(10.0, -k), m.min_cos, angle, pos, back ? "lands" : "blocked",
                    miss / size);
        passed++;
        worst_scaled = fmax(worst_scaled, fmax(angle, pos) * (double)m.min_cos);
        worst_angle = fmax(worst_angle, angle);
        lowest_cos = fmin(lowest_cos, (double)m.min_cos);
        if (!back || !(miss <= BACK_TRACE_BOUND * size))
            back_fails_at = fmax(back_fails_at, (double)m.min_cos);
        if (m.min_cos >= SWEEP_BACK_COS)
            cr_expect(back && miss <= BACK_TRACE_BOUND * size,
                      "%s k=%d: cos %Lg, traced back %s %g mm off", name, k, m.min_cos,
                      back ? "lands" : "is blocked", miss);
    }
    lens_free(&l);
    const char *file = getenv("L2P_STABILITY_REPORT");
    FILE *f = file && *file ? fopen(file, "a") : NULL;
    if (f) {
        char back[160] = "every one traced back onto its film point";
        if (back_fails_at > 0)
            snprintf(back, sizeof back, "traced back onto its film point down to cos %.0e "
                     "(asserted); the first that is not: cos %.1e", SWEEP_BACK_COS, back_fails_at);
        if (passed)
            fprintf(f, "%s\t%s\tsweep\t%d pass (down to cos %.1e), %d blocked; %s; "
                       "error x cos <= %.1e\t%.1e\n", name, what, passed, lowest_cos, blocked,
                    back, worst_scaled, worst_angle);
        else
            fprintf(f, "%s\t%s\tsweep\tall %d blocked, in double and in long double\n", name,
                    what, blocked);
        fclose(f);
    }
}

Test(stability, sweep_to_grazing_incidence_on_a_hemisphere)
{
    sweep("sweep-grazing", "ball lens: rays 1e-1 .. 1e-15 inside the rim, toward grazing",
          lens_ball, 20.0, 10.0, -1);
}

Test(stability, sweep_to_the_critical_angle)
{
    /* Inside n = 1.5 toward the hemisphere R = 10: critical at h = R / n. */
    sweep("sweep-critical", "inside glass toward the critical angle (1e-1 .. 1e-15 below it)",
          lens_tir, 10.0, 10.0 / 1.5, -1);
    sweep("sweep-tir", "just past the critical angle (1e-1 .. 1e-15 beyond it)", lens_tir, 10.0,
          10.0 / 1.5, +1);
}

