/* render --sampling field --rays: the CSV lists every rendered pixel's exact ray, and the pixel
   of the POV-Ray render that carries it. Checked against rays traced here, against the
   includes read the way POV-Ray reads distribution 3 (src/field/povuv.c), and against the
   pictures the real POV-Ray wrote. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "field/sobol.h"
#include "field/fieldpixels.h"
#include "field/strata.h"
#include "field/subimage.h"
#include "image/image_io.h"
#include "support.h"

#define L2P(out, errtext, ...) run_lens2pov(out, errtext, __VA_ARGS__, (char *)NULL)

/* Every traced pixel white, every pixel without a face black (RGB 0, as POV-Ray leaves it). */
static const char *SCENE = "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\nbackground { rgb 1 }\n";

/* The fisheye, whose image circle blocks the film's corners, on a crop reaching into them;
   4 sub-images on 2 jobs make 2 renders. */
enum { FILM_W = 64, FILM_H = 48, CROP_X0 = 2, CROP_Y0 = 3, CROP_X1 = 50, CROP_Y1 = 40, SPP = 4, SEED = 5 };
#define TOLERANCE 0.05

static camera_options options(void)
{
    camera_options o;
    camera_options_default(&o);
    o.width = FILM_W, o.height = FILM_H, o.spp = SPP, o.seed = SEED;
    o.crop_x0 = CROP_X0, o.crop_y0 = CROP_Y0, o.crop_x1 = CROP_X1, o.crop_y1 = CROP_Y1;
    o.location = v3(0, 1, -4), o.look_at = v3(0, 1, 0);
    return o;
}

/* Renders with --rays and --keep-temp WORK, at SPP samples or with --adaptive at a mean of
   ADAPTIVE_SPP; returns the CSV's rows. */
enum { ADAPTIVE_SPP = 16 };

static field_csv_ray *render_with_rays(const char *dir, bool adaptive, size_t *n)
{
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char scene[1024], out[1024], csv[1024], work[1024];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    snprintf(out, sizeof out, "%s/out.exr", dir);
    snprintf(csv, sizeof csv, "%s/rays.csv", dir);
    snprintf(work, sizeof work, "%s/work", dir);
    char *errtext = NULL;
    int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "fisheye.10mm.dat", "--width", "64", "--height",
                 "48", "--crop", "2,3,50,40", "--spp", adaptive ? "16" : "4", "--seed", "5", "--location",
                 "0,1,-4", "--look-at", "0,1,0", "--sampling", "field", "--jobs", "2", "--keep-temp", work,
                 "--rays", csv, "--quiet", "-o", out, adaptive ? "--adaptive" : "--quiet");
    cr_assert_eq(st, 0, "render: %s", errtext ? errtext : "");
    free(errtext);
    return read_field_rays_csv(csv, n);
}

static bool same_vec(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* Sub-image by sub-image and row by row, one row for each crop pixel whose ray, traced here
   with the shared sample, passes the lens (and whose film point the lens reaches), and none
   for the others; each row holds that ray. The CSV prints %.17g, which reads back exactly,
   and the batch tracer that made it agrees bit for bit with camera_trace (tests/test_trace.c),
   so the values must be equal; the weight is the trace's times its sub-image's stratum factor
   (src/field/strata.c). */
Test(field_rays, the_rows_are_the_passing_pixels_with_their_exact_rays)
{
    const char *dir = test_tmpdir();
    size_t n;
    field_csv_ray *rows = render_with_rays(dir, false, &n);
    camera_options o = options();
    camera c;
    test_camera(&c, "fisheye.10mm", &o);
    field_strata t;
    field_strata_count(&c, c.samples.spp, &t);
    size_t next = 0, blocked = 0;
    for (uint32_t k = 0; k < SPP; k++) {
        film_sample s = sobol_shared_sample(SEED, k);
        const double scale = field_strata_place(&t, &s);   /* the sub-image's stratum */
        for (int y = CROP_Y0; y < CROP_Y1; y++)
            for (int x = CROP_X0; x < CROP_X1; x++) {
                const double rx = x + s.offset_x, ry = y + s.offset_y;
                const vec3 fp = film_camera_from_raster(&c.film, rx, ry);
                ray r;
                double weight;
                if (!(pupil_reaches(&c.pupil, fp) && camera_trace(&c, fp, s.pupil_u, s.pupil_v, &r, &weight))) {
                    blocked++;
                    continue;
                }
                cr_assert_lt(next, n, "sub-image %u pixel %d,%d passes but has no row", k, x, y);
                const csv_ray *row = &rows[next++].ray;
                cr_assert(row->raster_x == rx && row->raster_y == ry,
                          "row %zu: raster %.17g,%.17g, expected sub-image %u pixel %d,%d (%.17g,%.17g)",
                          next - 1, row->raster_x, row->raster_y, k, x, y, rx, ry);
                cr_assert(row->film_x == fp.x && row->film_y == fp.y, "row %zu: film point", next - 1);
                cr_assert(same_vec(row->o, r.o) && same_vec(row->d, r.d), "row %zu: ray", next - 1);
                cr_assert(row->weight == weight * scale, "row %zu: weight %.17g, expected %.17g", next - 1,
                          row->weight, weight * scale);
            }
    }
    cr_expect_eq(next, n, "%zu rows beyond the passing pixels", n - next);
    cr_expect_gt(blocked, 0, "the crop reaches beyond the fisheye's image circle");
    cr_log_info("%zu rows, %zu pixels blocked", n, blocked);
    free(rows);
    camera_free(&c);
}

/* One render of the workspace: its include through the model, its size, its picture. */
typedef struct render_files {
    povuv_mesh mesh;
    int w, h;          /* the final picture; POV-Ray renders one more each way */
    float *rgba;       /* (w + 1) x (h + 1), as POV-Ray wrote it */
    char *claimed;     /* final pixels some row names */
} render_files;

static bool load_render(const char *work, int r, render_files *f)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/field.f%03d.inc", work, r);
    char *text = read_text(path, NULL);
    if (!text)
        return false;
    read_field_include(text, &f->mesh);
    free(text);
    snprintf(path, sizeof path, "%s/field.f%03d.ini", work, r);
    char *ini = read_text(path, NULL);
    cr_assert_not_null(ini, "no %s", path);
    const char *wp = strstr(ini, "\nWidth="), *hp = strstr(ini, "\nHeight=");
    cr_assert(wp && hp, "%s has no size", path);
    f->w = atoi(wp + 7) - 1, f->h = atoi(hp + 8) - 1;
    free(ini);
    snprintf(path, sizeof path, "%s/field.f%03d.exr", work, r);
    int iw, ih;
    l2p_error err;
    cr_assert_eq(image_read_rgba(path, &iw, &ih, &f->rgba, &err), 0, "%s", err.text);
    cr_assert(iw == f->w + 1 && ih == f->h + 1, "%s is %dx%d", path, iw, ih);
    f->claimed = calloc((size_t)f->w * f->h, 1);
    return true;
}

/* The error of a ray against the exact one, in pixels (as src/field/subimage.c measures it). */
static double error_px(const field_tolerance *t, const ray *exact, vec3 o, vec3 d)
{
    const double angle = atan2(v3_length(v3_cross(exact->d, d)), v3_dot(exact->d, d));
    const vec3 e = v3_sub(o, exact->o);
    const double across = v3_length(v3_sub(e, v3_scale(exact->d, v3_dot(e, exact->d))));
    return fmax(angle / t->angle_rad, across / t->origin_mm) * t->pixels;
}

/* Each row names a pixel of a render (image, image_x, image_y, row 0 the top of the picture
   POV-Ray writes): read the way POV-Ray reads distribution 3, that render's include gives
   that pixel the row's ray within the tolerance (neighbouring pixels' rays are a pixel
   apart); no two rows name the same pixel, and every pixel any include traces is named by a
   row. In the pictures the real POV-Ray wrote, exactly the named pixels are lit. Returns the
   number of renders. */
static int expect_rows_name_their_render_pixels(const char *dir, const field_csv_ray *rows, size_t n)
{
    camera_options o = options();
    camera c;
    test_camera(&c, "fisheye.10mm", &o);
    field_tolerance tol;
    field_tolerance_of(&c, TOLERANCE, &tol);
    const double front = c.lens.surface[0].vertex_z_mm;
    char work[1024];
    snprintf(work, sizeof work, "%s/work", dir);
    enum { MOST = 64 };
    render_files f[MOST];
    int renders = 0;
    while (renders < MOST && load_render(work, renders, &f[renders]))
        renders++;
    double worst = 0;
    for (size_t i = 0; i < n; i++) {
        const field_csv_ray *row = &rows[i];
        cr_assert(row->image >= 0 && row->image < renders, "row %zu: image %d", i, row->image);
        render_files *rf = &f[row->image];
        const int px = row->image_x, py = row->image_y - 1;
        cr_assert(px >= 0 && px < rf->w && py >= 0 && py < rf->h, "row %zu: pixel %d,%d outside", i, px,
                  row->image_y);
        cr_assert(!rf->claimed[py * rf->w + px], "row %zu: pixel %d,%d of image %d named twice", i, px,
                  row->image_y, row->image);
        rf->claimed[py * rf->w + px] = 1;
        double u, v;
        povuv_pixel_uv(rf->w, rf->h, px, py, &u, &v);
        const int face = povuv_mesh_find(&rf->mesh, u, v);
        cr_assert_geq(face, 0, "row %zu: image %d pixel %d,%d has no face", i, row->image, px, row->image_y);
        vec3 mo, md;
        cr_assert(povuv_face_ray(&rf->mesh.face[face], u, v, &mo, &md));
        const ray exact = {v3(row->ray.o.x, row->ray.o.y, row->ray.o.z - front), row->ray.d};
        const double e = error_px(&tol, &exact, mo, md);
        cr_assert_leq(e, TOLERANCE, "row %zu: the include's ray is %g px off", i, e);
        worst = fmax(worst, e);
    }
    long lit = 0;
    for (int r = 0; r < renders; r++) {
        const render_files *rf = &f[r];
        for (int y = 0; y <= rf->h; y++)
            for (int x = 0; x <= rf->w; x++) {
                const bool inside = y >= 1 && x < rf->w, named = inside && rf->claimed[(y - 1) * rf->w + x];
                if (inside) {
                    double u, v;
                    povuv_pixel_uv(rf->w, rf->h, x, y - 1, &u, &v);
                    cr_assert_eq(povuv_mesh_find(&rf->mesh, u, v) >= 0, named,
                                 "image %d pixel %d,%d: traced %d, named by a row %d", r, x, y, !named, named);
                }
                const float red = rf->rgba[4 * ((size_t)y * (rf->w + 1) + x)];
                cr_assert_eq(red > 0.5f, named, "image %d pixel %d,%d as POV-Ray wrote it: %g, named %d", r, x,
                             y, red, named);
                lit += named;
            }
    }
    cr_expect_eq(lit, (long)n);
    cr_log_info("%zu rows in %d renders, worst %.3g px", n, renders, worst);
    for (int r = 0; r < renders; r++)
        povuv_mesh_free(&f[r].mesh), free(f[r].rgba), free(f[r].claimed);
    camera_free(&c);
    return renders;
}

Test(field_rays, each_row_names_the_render_pixel_that_carries_its_ray)
{
    const char *dir = test_tmpdir();
    size_t n;
    field_csv_ray *rows = render_with_rays(dir, false, &n);
    const int renders = expect_rows_name_their_render_pixels(dir, rows, n);
    cr_expect_eq(renders, 2, "4 sub-images on 2 jobs: 2 renders, found %d", renders);
    free(rows);
}

/* The same of --adaptive, whose second round renders single tiles: on a white background the
   tiles' estimates still differ where the weights do (the image circle's edge, cos^4), so
   some pixels get more samples than others. Each pixel's rows then add up to its irradiance
   as the picture counts it: their weights over the mean count, each pixel the mean of its
   tile's samples. */
Test(field_rays, each_adaptive_row_names_the_render_pixel_that_carries_its_ray)
{
    const char *dir = test_tmpdir();
    size_t n;
    field_csv_ray *rows = render_with_rays(dir, true, &n);
    expect_rows_name_their_render_pixels(dir, rows, n);
    enum { W = CROP_X1 - CROP_X0, H = CROP_Y1 - CROP_Y0 };
    static int count[W * H];
    static double weight[W * H];
    for (size_t i = 0; i < n; i++) {
        const int x = (int)floor(rows[i].ray.raster_x) - CROP_X0, y = (int)floor(rows[i].ray.raster_y) - CROP_Y0;
        cr_assert(x >= 0 && y >= 0 && x < W && y < H, "row %zu: raster %g,%g", i, rows[i].ray.raster_x,
                  rows[i].ray.raster_y);
        count[y * W + x]++;
        weight[y * W + x] += rows[i].ray.weight / ADAPTIVE_SPP;
    }
    int least = n > 0 ? count[0] : 0, most = least;
    for (int i = 0; i < W * H; i++)
        least = count[i] < least ? count[i] : least, most = count[i] > most ? count[i] : most;
    cr_expect_gt(most, ADAPTIVE_SPP, "no pixel got more than the mean: no second round");
    /* the picture, white seen through the lens: each pixel its rows' weights over the mean
       count (half floats: 2^-11 relative) */
    const float *px = NULL;
    int w, h;
    l2p_error err;
    cr_assert_eq(image_read_rgba(tmp_path(dir, "out.exr"), &w, &h, (float **)&px, &err), 0, "%s", err.text);
    cr_assert(w == W && h == H);
    for (int i = 0; i < W * H; i++)
        cr_assert(fabs(px[4 * i] - weight[i]) <= 1e-3 * weight[i] + 1e-6,
                  "pixel %d,%d (%d rows): the picture %g, the rows' weights %g", i % W, i / W, count[i],
                  px[4 * i], weight[i]);
    free((float *)px);
    free(rows);
}

/* The CSV is complete or absent: a render that fails (here the scene does not parse) leaves a
   previous file at --rays as it was, and no temporary file beside it. */
Test(field_rays, a_failed_render_leaves_the_previous_csv)
{
    const char *dir = test_tmpdir();
    char scene[1024], csv[1024], out[1024];
    snprintf(scene, sizeof scene, "%s/bad.pov", dir);
    snprintf(csv, sizeof csv, "%s/rays.csv", dir);
    snprintf(out, sizeof out, "%s/out.png", dir);
    write_text(scene, "#version 3.7;\nsphere { <0, 0, 0> 1 pigment { rgb 1 }\n");   /* no closing brace */
    write_text(csv, "before\n");
    char *errtext = NULL;
    int st = L2P(NULL, &errtext, "render", scene, LENS_DIR "dgauss.50mm.dat", "--width", "16", "--height", "12",
                 "--spp", "2", "--location", "0,1,-4", "--look-at", "0,1,0", "--sampling", "field", "--rays", csv,
                 "--quiet", "-o", out);
    cr_expect_eq(st, 2, "exit %d: %s", st, errtext ? errtext : "");
    free(errtext);
    char *text = read_text(csv, NULL);
    cr_expect(text && !strcmp(text, "before\n"), "the CSV was replaced: %s", text ? text : "(gone)");
    free(text);
    char listing[1024];
    cr_expect_eq(count_entries(dir, NULL, listing, sizeof listing), 2, "left: %s", listing);
}
