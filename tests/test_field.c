/* Ray fields (--sampling field): the shared sample set's stratification, and the adaptive
   distribution-3 mesh of a sub-image read back through the model of POV-Ray
   (src/field/povuv.c) against the exact traced rays. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "field/sobol.h"
#include "support.h"

/* ---------------------------------------------------------------- the sample set */

static double dim_of(film_sample s, int d)
{
    return d == 0 ? s.offset_x : d == 1 ? s.offset_y : d == 2 ? s.pupil_u : s.pupil_v;
}

/* The first 2^m points put exactly one value in each interval [i/2^m, (i+1)/2^m) of every
   dimension. */
Test(field, shared_samples_are_stratified_in_each_dimension)
{
    for (uint64_t seed = 0; seed < 4; seed++)
        for (int m = 0; m <= 10; m++) {
            int n = 1 << m;
            for (int d = 0; d < 4; d++) {
                char *seen = calloc((size_t)n, 1);
                for (int k = 0; k < n; k++) {
                    double t = dim_of(sobol_shared_sample(seed, (uint32_t)k), d);
                    cr_assert(t >= 0 && t < 1);
                    int cell = (int)(t * n);
                    cr_assert(!seen[cell], "seed %d, 2^%d points, dim %d: interval %d twice",
                              (int)seed, m, d, cell);
                    seen[cell] = 1;
                }
                free(seen);
            }
        }
}

/* The pixel offsets (dimensions 0 and 1) form a (0, m, 2)-net: for every split m = a + b,
   each box of 2^-a x 2^-b holds exactly one of the first 2^m points. */
Test(field, shared_pixel_offsets_form_a_0_m_2_net)
{
    for (uint64_t seed = 0; seed < 4; seed++)
        for (int m = 0; m <= 10; m++)
            for (int a = 0; a <= m; a++) {
                int n = 1 << m, na = 1 << a, nb = 1 << (m - a);
                char *seen = calloc((size_t)n, 1);
                for (int k = 0; k < n; k++) {
                    film_sample s = sobol_shared_sample(seed, (uint32_t)k);
                    int box = (int)(s.offset_x * na) * nb + (int)(s.offset_y * nb);
                    cr_assert(!seen[box], "seed %d, m %d, a %d: box %d twice", (int)seed, m, a, box);
                    seen[box] = 1;
                }
                free(seen);
            }
}

Test(field, seeds_scramble_the_samples)
{
    film_sample a = sobol_shared_sample(1, 3), b = sobol_shared_sample(2, 3);
    cr_expect(a.offset_x != b.offset_x && a.pupil_u != b.pupil_u);
    film_sample c = sobol_shared_sample(1, 3);
    cr_expect(memcmp(&a, &c, sizeof a) == 0, "the same seed gives the same samples");
}

/* ---------------------------------------------------------------- a sub-image's mesh */

#include <stdio.h>
#include "field/subimage.h"

/* Builds the sub-image of camera c seen with shared sample s into m (at the crop's render
   size), writes its include and reads it back through the model into pm. */
static void build_and_read_back(const camera *c, film_sample s, const field_tolerance *t, field_mesh *m,
                                field_stats *st, povuv_mesh *pm)
{
    field_mesh_init(m, field_render_size(c->crop_x1 - c->crop_x0), field_render_size(c->crop_y1 - c->crop_y0));
    l2p_error err;
    cr_assert_eq(field_build_subimage(c, s, 1.0, t, FIELD_COARSEST_CELL, m, NULL, st, &err), L2P_OK, "%s", err.text);
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    static const double world[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    cr_assert_eq(field_mesh_write_include(f, m, "Field_Test", world, NULL), 0);
    fclose(f);
    read_field_include(text, pm);
    free(text);
}

/* Builds the sub-image of shared sample k, writes its include, reads it back through the
   model, and checks every pixel of the crop against its exact traced ray. */
static void check_subimage(const char *lens, camera_options *o, double tol, uint32_t k, field_stats *st)
{
    camera c;
    test_camera(&c, lens, o);
    field_tolerance t;
    field_tolerance_of(&c, tol, &t);
    const int w = c.crop_x1 - c.crop_x0, h = c.crop_y1 - c.crop_y0;
    film_sample s = sobol_shared_sample(o->seed, k);
    field_mesh m;
    povuv_mesh pm;
    build_and_read_back(&c, s, &t, &m, st, &pm);
    const double front = c.lens.surface[0].vertex_z_mm;
    long rendered = 0, passed = 0;
    double worst = 0, affine_apart = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            vec3 fp = film_camera_from_raster(&c.film, c.crop_x0 + x + s.offset_x, c.crop_y0 + y + s.offset_y);
            ray r;
            double weight;
            bool pass = pupil_reaches(&c.pupil, fp) && camera_trace(&c, fp, s.pupil_u, s.pupil_v, &r, &weight);
            double u, v;
            povuv_pixel_uv(m.render_w, m.render_h, x, y, &u, &v);
            int face = povuv_mesh_find(&pm, u, v);
            cr_assert_eq(face >= 0, pass, "%s pixel %d,%d: rendered %d, passes %d", lens, x, y, face >= 0, pass);
            passed += pass;
            if (face < 0)
                continue;
            rendered++;
            r.o.z -= front;
            {
                vec3 mo, md;
                cr_assert(povuv_face_ray(&pm.face[face], u, v, &mo, &md));
                double angle = atan2(v3_length(v3_cross(r.d, md)), v3_dot(r.d, md));
                vec3 e = v3_sub(mo, r.o);
                double across = v3_length(v3_sub(e, v3_scale(r.d, v3_dot(e, r.d))));
                double err_px = fmax(angle / t.angle_rad, across / t.origin_mm) * tol;
                cr_assert(err_px <= tol, "%s pixel %d,%d: error %g px", lens, x, y, err_px);
                worst = fmax(worst, err_px);
                /* the builder's affine form of the same ray, in tolerances */
                vec3 ao, ar;
                cr_assert(pm.face[face].has_affine);
                povuv_affine_ray(&pm.face[face], u, v, &ao, &ar);
                double turn = atan2(v3_length(v3_cross(ar, md)), v3_dot(ar, md));
                affine_apart = fmax(affine_apart, fmax(turn / t.angle_rad, v3_length(v3_sub(ao, mo)) / t.origin_mm));
            }
        }
    cr_log_info("%s %dx%d f/%g: %d faces (%d lone), %ld of %ld pixels pass, worst %.3g px (tolerance %g), "
                "affine form %.3g tolerances from the model", lens, w, h, c.f_number, st->faces,
                st->lone_faces, passed, (long)w * h, worst, tol, affine_apart);
    cr_expect_leq(affine_apart, FIELD_AFFINE_MARGIN / 10, "%s: the affine form is %g tolerances from the model",
                  lens, affine_apart);
    cr_expect_eq(passed, st->passed);
    cr_expect(rendered == passed);
    povuv_mesh_free(&pm);
    field_mesh_free(&m);
    camera_free(&c);
}

static camera_options small(int w, int h)
{
    camera_options o;
    camera_options_default(&o);
    o.width = w, o.height = h, o.spp = 1, o.seed = 7;
    o.location = v3(0, 1, -4), o.look_at = v3(0, 1, 0);
    return o;
}

Test(field, dgauss_full_aperture_every_pixel_within_the_tolerance)
{
    camera_options o = small(160, 120);
    field_stats st;
    for (uint32_t k = 0; k < 2; k++)
        check_subimage("dgauss.50mm", &o, 0.05, k, &st);
}

Test(field, dgauss_stopped_down_every_pixel_within_the_tolerance)
{
    camera_options o = small(160, 120);
    o.f_number = 8;
    field_stats st;
    check_subimage("dgauss.50mm", &o, 0.05, 1, &st);
}

Test(field, fisheye_every_pixel_within_the_tolerance)
{
    camera_options o = small(160, 120);
    field_stats st;
    for (uint32_t k = 0; k < 2; k++)
        check_subimage("fisheye.10mm", &o, 0.05, k, &st);
    cr_expect(st.blocked > 0, "the fisheye's image circle blocks the corners");
}

/* Where only the image circle's rim limits the faces (a tolerance no lens needs here), the rim
   is drawn by long faces along it: fewer faces than rim pixels (passing pixels with a blocked
   neighbour). Split down to single pixels, it took three to four faces a rim pixel. */
Test(field, the_image_circles_rim_takes_fewer_faces_than_its_pixels)
{
    camera_options o = small(160, 120);
    camera c;
    test_camera(&c, "fisheye.10mm", &o);
    for (uint32_t k = 0; k < 2; k++) {
        field_stats st;
        check_subimage("fisheye.10mm", &o, 20, k, &st);
        const film_sample s = sobol_shared_sample(o.seed, k);
        bool pass[120][160];
        for (int y = 0; y < 120; y++)
            for (int x = 0; x < 160; x++) {
                vec3 fp = film_camera_from_raster(&c.film, x + s.offset_x, y + s.offset_y);
                ray r;
                double weight;
                pass[y][x] = pupil_reaches(&c.pupil, fp) && camera_trace(&c, fp, s.pupil_u, s.pupil_v, &r, &weight);
            }
        int rim = 0;
        for (int y = 0; y < 120; y++)
            for (int x = 0; x < 160; x++)
                rim += pass[y][x] && ((x > 0 && !pass[y][x - 1]) || (x < 159 && !pass[y][x + 1]) ||
                                      (y > 0 && !pass[y - 1][x]) || (y < 119 && !pass[y + 1][x]));
        cr_log_info("fisheye sample %u: %d rim pixels, %d faces", k, rim, st.faces);
        cr_expect(rim > 100, "the image circle lies inside the film");
        cr_expect(st.faces < rim, "%d faces for %d rim pixels", st.faces, rim);
    }
    camera_free(&c);
}

/* A field that bends little (the telephoto's) is drawn by cells larger than the base grid:
   fewer faces than the base grid's two a cell, every pixel still checked against its exact
   ray by check_subimage. */
Test(field, a_gentle_field_takes_cells_larger_than_the_base_grid)
{
    camera_options o = small(320, 240);
    field_stats st;
    check_subimage("telephoto.250mm", &o, 0.05, 1, &st);
    const int base = 2 * ((320 - 1 + FIELD_BASE_CELL - 1) / FIELD_BASE_CELL) *
                     ((240 - 1 + FIELD_BASE_CELL - 1) / FIELD_BASE_CELL);
    cr_expect(st.faces < base / 2, "%d faces, the base grid alone %d", st.faces, base);
}

Test(field, a_crop_every_pixel_within_the_tolerance)
{
    camera_options o = small(320, 240);
    o.crop_x0 = 200, o.crop_y0 = 150, o.crop_x1 = 300, o.crop_y1 = 230;
    field_stats st;
    check_subimage("wide.22mm", &o, 0.05, 3, &st);
    check_subimage("fisheye.10mm", &o, 0.05, 2, &st);
}

/* The exact direction through film raster point (rx, ry) with sample s, or false. */
static bool exact_direction(const camera *c, film_sample s, double rx, double ry, vec3 *d)
{
    ray r;
    double weight;
    const vec3 fp = film_camera_from_raster(&c->film, rx, ry);
    if (!pupil_reaches(&c->pupil, fp) || !camera_trace(c, fp, s.pupil_u, s.pupil_v, &r, &weight))
        return false;
    *d = r.d;
    return true;
}

/* Where on the film (raster) the exact field has direction want, by Newton's method from
   (*rx, *ry) with central differences of 1e-3 pixel: the film point whose subject, far away,
   the direction sees. False when it does not converge. */
static bool film_point_of(const camera *c, film_sample s, vec3 want, double *rx, double *ry)
{
    const vec3 side = fabs(want.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
    const vec3 e1 = v3_normalize(v3_cross(want, side)), e2 = v3_cross(want, e1);
    const double h = 1e-3;
    for (int it = 0; it < 20; it++) {
        vec3 d, dxp, dxm, dyp, dym;
        if (!exact_direction(c, s, *rx, *ry, &d) || !exact_direction(c, s, *rx + h, *ry, &dxp) ||
            !exact_direction(c, s, *rx - h, *ry, &dxm) || !exact_direction(c, s, *rx, *ry + h, &dyp) ||
            !exact_direction(c, s, *rx, *ry - h, &dym))
            return false;
        const double f1 = v3_dot(d, e1), f2 = v3_dot(d, e2);
        const double a = (v3_dot(dxp, e1) - v3_dot(dxm, e1)) / (2 * h), b = (v3_dot(dyp, e1) - v3_dot(dym, e1)) / (2 * h);
        const double cc = (v3_dot(dxp, e2) - v3_dot(dxm, e2)) / (2 * h), dd = (v3_dot(dyp, e2) - v3_dot(dym, e2)) / (2 * h);
        const double det = a * dd - b * cc;
        const double sx = (dd * f1 - b * f2) / det, sy = (a * f2 - cc * f1) / det;
        *rx -= sx, *ry -= sy;
        if (fabs(sx) + fabs(sy) < 1e-9)
            return v3_dot(d, want) > 0;
    }
    return false;
}

/* The tolerance is a distance on the film (docs/fields.md, "The tolerance"): the direction the
   model of POV-Ray gives each pixel is the exact direction of a film point at most the
   tolerance from the pixel's, found by inverting the exact field (Newton's method on the
   tracer). Through the 22 mm wide angle a pixel at the film's corners spans 0.6 times the
   angle of one at its centre, so an error of the centre's angular tolerance would move a
   corner's subject 1.6 times as far. */
Test(field, a_model_ray_lands_within_the_tolerance_on_the_film)
{
    camera_options o = small(96, 64);
    o.focus_distance_units = INFINITY;
    camera c;
    test_camera(&c, "wide.22mm", &o);
    field_tolerance t;
    field_tolerance_of(&c, 0.05, &t);
    const int w = 96, h = 64;
    const film_sample s = sobol_shared_sample(o.seed, 1);
    field_mesh m;
    field_stats st;
    povuv_mesh pm;
    build_and_read_back(&c, s, &t, &m, &st, &pm);
    double worst = 0, worst_centre_angle = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double u, v;
            povuv_pixel_uv(m.render_w, m.render_h, x, y, &u, &v);
            const int face = povuv_mesh_find(&pm, u, v);
            cr_assert_geq(face, 0, "pixel %d,%d is not rendered", x, y);
            vec3 mo, md;
            cr_assert(povuv_face_ray(&pm.face[face], u, v, &mo, &md));
            const double rx0 = x + s.offset_x, ry0 = y + s.offset_y;
            double rx = rx0, ry = ry0;
            cr_assert(film_point_of(&c, s, md, &rx, &ry), "pixel %d,%d: no film point sees its ray", x, y);
            worst = fmax(worst, hypot(rx - rx0, ry - ry0));
            vec3 exact;
            cr_assert(exact_direction(&c, s, rx0, ry0, &exact));
            worst_centre_angle = fmax(worst_centre_angle, atan2(v3_length(v3_cross(exact, md)), v3_dot(exact, md)) /
                                                              t.angle_rad * t.pixels);
        }
    cr_log_info("wide.22mm: %d faces, the model's rays land at most %.4f px from their pixels (%.4f px in "
                "the centre's angle)", st.faces, worst, worst_centre_angle);
    cr_assert_leq(worst, 0.05 * 1.01, "a ray lands %g px from its pixel", worst);
    povuv_mesh_free(&pm);
    field_mesh_free(&m);
    camera_free(&c);
}

/* Two sub-images moved side by side into one render and their faces put largest first (as
   field_render.c writes them): read back through the model, every pixel of each still gets its
   exact ray within the tolerance, and the pixels between and beyond them none. */
Test(field, sub_images_moved_into_a_render_keep_their_rays)
{
    camera_options o = small(120, 90);
    camera c;
    test_camera(&c, "fisheye.10mm", &o);
    field_tolerance t;
    field_tolerance_of(&c, 0.05, &t);
    const int w = 120, h = 90, rw = field_render_size(2 * w + 7), rh = field_render_size(h);
    field_mesh render;
    field_mesh_init(&render, rw, rh);
    const int dx[2] = {0, w + 7};
    for (int k = 0; k < 2; k++) {
        field_mesh m;
        field_stats st;
        l2p_error err;
        field_mesh_init(&m, field_render_size(w), field_render_size(h));
        cr_assert_eq(field_build_subimage(&c, sobol_shared_sample(o.seed, (uint32_t)k), 1.0, &t, FIELD_COARSEST_CELL,
                                          &m, NULL, &st, &err), L2P_OK);
        cr_assert_eq(field_mesh_append(&render, &m, dx[k], 0), 0);
        field_mesh_free(&m);
    }
    cr_assert_eq(field_mesh_sort_faces_by_area(&render), 0);
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    static const double world[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    cr_assert_eq(field_mesh_write_include(f, &render, "Field_Test", world, NULL), 0);
    fclose(f);
    povuv_mesh pm;
    read_field_include(text, &pm);
    const double front = c.lens.surface[0].vertex_z_mm;
    for (int y = 0; y < rh; y++)
        for (int x = 0; x < rw; x++) {
            double u, v;
            povuv_pixel_uv(rw, rh, x, y, &u, &v);
            int face = povuv_mesh_find(&pm, u, v);
            int k = x < w ? 0 : x >= dx[1] && x < dx[1] + w ? 1 : -1;
            if (k < 0 || y >= h) {
                cr_assert(face < 0, "pixel %d,%d outside the sub-images is traced", x, y);
                continue;
            }
            film_sample s = sobol_shared_sample(o.seed, (uint32_t)k);
            vec3 fp = film_camera_from_raster(&c.film, x - dx[k] + s.offset_x, y + s.offset_y);
            ray r;
            double weight;
            bool pass = pupil_reaches(&c.pupil, fp) && camera_trace(&c, fp, s.pupil_u, s.pupil_v, &r, &weight);
            cr_assert_eq(face >= 0, pass, "pixel %d,%d: rendered %d, passes %d", x, y, face >= 0, pass);
            if (face < 0)
                continue;
            vec3 mo, md;
            cr_assert(povuv_face_ray(&pm.face[face], u, v, &mo, &md));
            r.o.z -= front;
            double angle = atan2(v3_length(v3_cross(r.d, md)), v3_dot(r.d, md));
            vec3 e = v3_sub(mo, r.o);
            double across = v3_length(v3_sub(e, v3_scale(r.d, v3_dot(e, r.d))));
            cr_assert(angle <= t.angle_rad && across <= t.origin_mm, "pixel %d,%d: %g rad, %g mm", x, y,
                      angle, across);
        }
    free(text);
    povuv_mesh_free(&pm);
    field_mesh_free(&render);
    camera_free(&c);
}

/* Sorting keeps every face (its three vertices in their order) and puts them largest first. */
Test(field, faces_sorted_largest_first_are_the_same_faces)
{
    field_mesh m;
    field_mesh_init(&m, 63, 63);
    const double at[6][2] = {{0, 0}, {1, 0}, {0, 1}, {8, 0}, {0, 8}, {3, 4}};
    for (int i = 0; i < 6; i++)
        cr_assert_geq(field_mesh_vertex(&m, v3(i, 0, 0), v3(0, 0, 1), at[i][0], at[i][1]), 0);
    const int tri[4][3] = {{0, 1, 2}, {0, 3, 4}, {1, 5, 2}, {3, 5, 4}};
    for (int k = 0; k < 4; k++)
        cr_assert_geq(field_mesh_face(&m, tri[k][0], tri[k][1], tri[k][2]), 0);
    cr_assert_eq(field_mesh_sort_faces_by_area(&m), 0);
    /* twice the areas: 1, 64, 6, 8 (the shoelace formula by hand) */
    const int want[4] = {1, 3, 2, 0};
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 3; j++)
            cr_assert_eq(m.tri[k][j], tri[want[k]][j], "face %d vertex %d", k, j);
    field_mesh_free(&m);
}
