/* The model of distribution 3 (src/field/povuv.c) against the real POV-Ray 3.7.0.10: a small
   curved field of rays (a few faces, a hole, a sliver) rendered with a scene whose colour
   encodes where each ray crosses the plane z = 1000: red and green the fractional parts of x
   and y there, blue 1 where a ray was traced. Half-float EXR resolves the fraction to 2^-11,
   2e-6 rad at that distance; a half-pixel slip of the UV moves the hits by tens of units. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "field/fieldmesh.h"
#include "image/image_io.h"
#include "support.h"

enum { W = 15, H = 7 };   /* the final picture; POV-Ray renders 16 x 8 */

static const char *SCENE =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 ambient_light 1 }\n"
    "plane { z, 1000 pigment { average pigment_map {\n"
    "  [1 function { x + 10000 - floor(x + 10000) } color_map { [0 rgb 0] [1 rgb <3,0,0>] }]\n"
    "  [1 function { y + 10000 - floor(y + 10000) } color_map { [0 rgb 0] [1 rgb <0,3,0>] }]\n"
    "  [1 rgb <0,0,3>] } } finish { ambient 1 diffuse 0 } }\n"
    "#include \"field.inc\"\n";

/* A vertex at final pixel (px, py): origin on a curved cap, direction a nonlinear fan. */
static int vertex_at(field_mesh *m, int px, int py)
{
    double x = px - 7.0, y = 3.0 - py;
    vec3 o = v3(0.7 * x, 0.9 * y, 0.05 * (x * x + y * y));
    vec3 d = v3(0.06 * x + 0.004 * x * y, 0.07 * y + 0.002 * x * x, 1.0);
    return field_mesh_vertex(m, o, d, px, py);
}

static void build(field_mesh *m)
{
    static const int xs[] = {0, 4, 8, 12, 14}, ys[] = {0, 3, 6};
    int id[3][5];
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 5; i++)
            id[j][i] = vertex_at(m, xs[i], ys[j]);
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 4; i++) {
            if (i == 2 && j == 1)
                continue;   /* a hole: its pixels are not traced */
            field_mesh_face(m, id[j][i], id[j][i + 1], id[j + 1][i]);
            field_mesh_face(m, id[j][i + 1], id[j + 1][i + 1], id[j + 1][i]);
        }
    /* a sliver in the hole, one pixel high */
    int a = vertex_at(m, 8, 4), b = vertex_at(m, 12, 4), c = vertex_at(m, 9, 5);
    field_mesh_face(m, a, b, c);
}

static double wrap(double t) { return t - floor(t + 0.5); }

Test(field_povray, the_model_gives_the_rays_povray_traces)
{
    field_mesh m;
    field_mesh_init(&m, W, H);
    build(&m);
    const char *dir = test_tmpdir();
    static const double world[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0.25, -0.5, -5};
    FILE *f = fopen(tmp_path(dir, "field.inc"), "w");
    cr_assert_not_null(f);
    cr_assert_eq(field_mesh_write_include(f, &m, "Field_Rays", world, NULL), 0);
    fclose(f);
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +Iscene.pov +Oout.exr +FE +W%d +H%d +SR2 +EC%d -A -D -P -UA -GS -GR "
             "-V +WT1 >povray.log 2>&1", dir, W + 1, H + 1, W);
    cr_assert_eq(system_povray(cmd), 0, "povray failed, see %s/povray.log", dir);

    int iw, ih;
    float *px;
    l2p_error err;
    cr_assert_eq(image_read_rgba(tmp_path(dir, "out.exr"), &iw, &ih, &px, &err), 0, "%s", err.text);
    cr_assert(iw == W + 1 && ih == H + 1);

    povuv_face *faces = malloc(sizeof *faces * (size_t)m.faces);
    for (int k = 0; k < m.faces; k++)
        field_mesh_povuv_face(&m, k, &faces[k]);
    povuv_mesh pm;
    cr_assert_eq(povuv_mesh_init(&pm, faces, m.faces), 0);
    int traced = 0, holes = 0;
    double worst = 0;
    for (int py = 0; py < H; py++)
        for (int x = 0; x < W; x++) {
            const float *c = px + 4 * ((size_t)(py + 1) * iw + x);
            double u, v;
            povuv_pixel_uv(W, H, x, py, &u, &v);
            int k = povuv_mesh_find(&pm, u, v);
            if (k < 0) {
                cr_expect(c[0] == 0 && c[1] == 0 && c[2] == 0, "pixel %d,%d should be untraced", x, py);
                holes++;
                continue;
            }
            vec3 o, d;
            cr_assert(povuv_face_ray(&pm.face[k], u, v, &o, &d));
            o = v3_add(o, v3(world[9], world[10], world[11]));
            double t = (1000 - o.z) / d.z;
            double hx = o.x + t * d.x, hy = o.y + t * d.y;
            cr_expect(fabs(c[2] - 1) < 1e-3, "pixel %d,%d should be traced", x, py);
            double ex = fabs(wrap(c[0] - (hx + 10000 - floor(hx + 10000))));
            double ey = fabs(wrap(c[1] - (hy + 10000 - floor(hy + 10000))));
            worst = fmax(worst, fmax(ex, ey));
            traced++;
        }
    cr_log_info("distribution 3 model: %d traced, %d untraced, worst hit error %.3g units at 1000",
                traced, holes, worst);
    cr_expect(traced > 60 && holes >= 4, "%d traced, %d untraced", traced, holes);
    for (int y = 0; y <= H; y++)   /* +EC<W>: the last column is not rendered */
        cr_expect(px[4 * ((size_t)y * iw + W) + 2] == 0, "column %d, row %d was rendered", W, y);
    cr_expect(worst < 2e-3, "worst hit error %g", worst);
    povuv_mesh_free(&pm);
    field_mesh_free(&m);
    free(px);
}

/* ---------------------------------------------------------------- a lens's field */

#include "field/sobol.h"
#include "field/subimage.h"

/* The crossing of plane z = Z, in units of PERIOD: a colour holds its fraction. */
enum { FAR = 100000, PERIOD = 16 };

static const char *LENS_SCENE =
    "#version 3.7;\n"
    "global_settings { assumed_gamma 1.0 ambient_light 1 }\n"
    "plane { z, 100000 pigment { average pigment_map {\n"
    "  [1 function { x / 16 + 10000 - floor(x / 16 + 10000) } color_map { [0 rgb 0] [1 rgb <3,0,0>] }]\n"
    "  [1 function { y / 16 + 10000 - floor(y / 16 + 10000) } color_map { [0 rgb 0] [1 rgb <0,3,0>] }]\n"
    "  [1 rgb <0,0,3>] } } finish { ambient 1 diffuse 0 } }\n"
    "#include \"field.inc\"\n";

/* A sub-image of the fisheye (image circle, strong distortion), its include rendered by the
   real POV-Ray: every pixel whose exact ray passes is traced and crosses the far plane where
   the exact ray does, within the tolerance's angle; every other pixel is black. World =
   camera space in millimetres. */
Test(field_povray, povray_renders_a_lens_field_within_the_tolerance)
{
    camera_options o;
    camera_options_default(&o);
    o.width = 96, o.height = 72, o.spp = 1, o.seed = 3, o.unit_mm = 1;
    o.location = v3(0, 0, 0), o.look_at = v3(0, 0, 1000);
    camera c;
    test_camera(&c, "fisheye.10mm", &o);
    field_tolerance t;
    field_tolerance_of(&c, 0.05, &t);
    const int w = 96, h = 72, rw = field_render_size(w), rh = field_render_size(h);
    film_sample s = sobol_shared_sample(o.seed, 0);
    field_mesh m;
    field_stats st;
    l2p_error err;
    field_mesh_init(&m, rw, rh);
    cr_assert_eq(field_build_subimage(&c, s, 1.0, &t, FIELD_COARSEST_CELL, &m, NULL, &st, &err), L2P_OK);
    /* mesh space (camera space less the front vertex) to the world, as field_render.c does */
    const double front = c.lens.surface[0].vertex_z_mm;
    vec3 ax[3] = {camera_world_from_camera_offset(&c, v3(1, 0, 0)), camera_world_from_camera_offset(&c, v3(0, 1, 0)),
                  camera_world_from_camera_offset(&c, v3(0, 0, 1))};
    vec3 t0 = camera_world_from_camera_point(&c, v3(0, 0, front));
    double world[12] = {ax[0].x, ax[0].y, ax[0].z, ax[1].x, ax[1].y, ax[1].z, ax[2].x, ax[2].y, ax[2].z, t0.x, t0.y, t0.z};
    const char *dir = test_tmpdir();
    FILE *f = fopen(tmp_path(dir, "field.inc"), "w");
    cr_assert_not_null(f);
    cr_assert_eq(field_mesh_write_include(f, &m, "Field_Rays", world, NULL), 0);
    fclose(f);
    write_text(tmp_path(dir, "scene.pov"), LENS_SCENE);
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +Iscene.pov +Oout.exr +FE +W%d +H%d +SR2 +EC%d -A -D -P -UA -GS -GR "
             "-V +WT1 >povray.log 2>&1", dir, rw + 1, rh + 1, rw);
    cr_assert_eq(system_povray(cmd), 0, "povray failed, see %s/povray.log", dir);
    int iw, ih;
    float *px;
    cr_assert_eq(image_read_rgba(tmp_path(dir, "out.exr"), &iw, &ih, &px, &err), 0, "%s", err.text);
    long traced = 0, black = 0;
    double worst = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *col = px + 4 * ((size_t)(y + 1) * iw + x);
            vec3 fp = film_camera_from_raster(&c.film, x + s.offset_x, y + s.offset_y);
            ray r;
            double weight;
            bool pass = pupil_reaches(&c.pupil, fp) && camera_trace(&c, fp, s.pupil_u, s.pupil_v, &r, &weight);
            if (!pass || r.d.z <= 0.1) {   /* the plane is not seen: only check blackness */
                if (!pass)
                    cr_expect(col[0] == 0 && col[1] == 0 && col[2] == 0, "blocked pixel %d,%d traced", x, y);
                black += !pass;
                continue;
            }
            vec3 o2 = camera_world_from_camera_point(&c, r.o), d2 = camera_world_from_camera_dir(&c, r.d);
            double k = (FAR - o2.z) / d2.z;
            double hx = (o2.x + k * d2.x) / PERIOD, hy = (o2.y + k * d2.y) / PERIOD;
            cr_expect(fabs(col[2] - 1) < 1e-3, "passing pixel %d,%d not traced", x, y);
            double ex = fabs(wrap(col[0] - (hx - floor(hx)))), ey = fabs(wrap(col[1] - (hy - floor(hy))));
            /* the crossing's error over the distance travelled: an angle */
            double angle = fmax(ex, ey) * PERIOD * d2.z / (FAR - o2.z);
            worst = fmax(worst, angle);
            traced++;
        }
    cr_log_info("fisheye field through POV-Ray: %ld traced, %ld blocked, %d faces, worst %.3g rad "
                "(tolerance %.3g rad)", traced, black, st.faces, worst, t.angle_rad);
    cr_expect(traced > 1000 && black > 100);
    /* the tolerance, plus the EXR's half-float steps (2^-11 of a period) */
    cr_expect(worst < t.angle_rad + PERIOD * 1e-3 / FAR, "worst %g rad", worst);
    free(px);
    field_mesh_free(&m);
    camera_free(&c);
}
