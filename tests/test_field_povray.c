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
    cr_assert_eq(field_mesh_write_include(f, &m, "Field_Rays", world), 0);
    fclose(f);
    write_text(tmp_path(dir, "scene.pov"), SCENE);
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +Iscene.pov +Oout.exr +FE +W%d +H%d +SR2 +EC%d -A -D -P -UA -GS -GR "
             "-V +WT1 >povray.log 2>&1", dir, W + 1, H + 1, W);
    cr_assert_eq(system(cmd), 0, "povray failed, see %s/povray.log", dir);

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
