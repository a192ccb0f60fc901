/* lens2pov diagram and plot: the SVG is well-formed XML, draws one outline a glass element and
   rays that are the tracer's; the plot writes a PNG and a table that says what the optics say;
   bad requests exit 2. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/camera.h"
#include "support.h"

static char *diagram_of(const char *lens_name, const char *dir)
{
    const char *svg = tmp_path(dir, "lens.svg");
    run_lens2pov_ok("diagram", "diagram", lens_name, "-o", svg, NULL);
    char *text = read_text(svg, NULL);
    cr_assert(text, "no %s", svg);
    return text;
}

static int count_of(const char *text, const char *needle)
{
    int n = 0;
    for (const char *p = text; (p = strstr(p, needle)); p += strlen(needle))
        n++;
    return n;
}

/* xmllint (Debian's libxml2-utils, in the Makefile's packages) parses the whole document. */
Test(diagram, the_svg_is_well_formed_xml)
{
    static const char *const lenses[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm"};
    const char *dir = test_tmpdir();
    for (int i = 0; i < 3; i++) {
        free(diagram_of(lenses[i], dir));
        char command[1024];
        snprintf(command, sizeof command, "xmllint --noout '%s' 2>&1", tmp_path(dir, "lens.svg"));
        cr_assert_eq(system(command), 0, "%s: xmllint refuses the SVG", lenses[i]);
    }
}

Test(diagram, one_glass_outline_per_element)
{
    static const char *const lenses[] = {"dgauss.50mm", "wide.22mm", "fisheye.10mm"};
    const char *dir = test_tmpdir();
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, LENS_DIR "%s.dat", lenses[i]);
        lens l;
        l2p_error err;
        cr_assert_eq(lens_read(path, &l, &err), 0, "%s", err.text);
        int glass = 0;   /* a surface with glass behind it begins an element */
        for (int s = 0; s < l.count; s++)
            glass += l.surface[s].ior > 1.0;
        lens_free(&l);
        char *svg = diagram_of(lenses[i], dir);
        cr_assert_eq(count_of(svg, "class=\"element\""), glass, "%s", lenses[i]);
        cr_assert_eq(count_of(svg, "class=\"stop\""), 1);
        cr_assert_eq(count_of(svg, "class=\"film\""), 1);
        free(svg);
    }
}

/* A ray's polyline: its film height, pupil sample and points (z, y), from the film out. */
typedef struct drawn_ray {
    double film_y, v;
    double z[512], y[512];
    int n;
    bool blocked;
} drawn_ray;

static const char *next_ray(const char *p, drawn_ray *r)
{
    p = strstr(p, "<polyline class=\"ray ");
    if (!p)
        return NULL;
    const char *end = strstr(p, "/>");
    cr_assert(end);
    r->blocked = strstr(p, "blocked") && strstr(p, "blocked") < end;
    cr_assert_eq(sscanf(strstr(p, "data-film-y=\""), "data-film-y=\"%lf\"", &r->film_y), 1);
    cr_assert_eq(sscanf(strstr(p, "data-v=\""), "data-v=\"%lf\"", &r->v), 1);
    const char *q = strstr(p, "points=\"") + 8;
    int used;
    r->n = 0;
    while (q < end && r->n < 512 && sscanf(q, "%lf,%lf%n", &r->z[r->n], &r->y[r->n], &used) == 2) {
        r->n++;
        q += used;
    }
    return end;
}

/* Each drawn ray starts on the film at its film point, crosses every surface and leaves the
   front surface where camera_trace's ray (the one trace writes) starts, then goes on along it. */
/* Every drawn ray against camera_trace from the same film point and pupil sample: blocked or
   not, and where it leaves the front and in which direction; the number that pass. */
static int check_drawn_rays(const char *svg, const camera *c)
{
    drawn_ray r;
    int passed = 0, field = 0;
    for (const char *p = svg; (p = next_ray(p, &r));) {
        cr_assert_eq(r.z[0], 0.0);
        cr_assert_eq(r.y[0], r.film_y);
        ray out;
        double w;
        const bool ok = camera_trace(c, v3(0, r.film_y, 0), 0.5, r.v, &out, &w);
        cr_assert_eq(ok, !r.blocked, "film y %g, v %g", r.film_y, r.v);
        if (!ok)
            continue;
        passed++;
        field += r.film_y > 0.0;
        cr_assert_eq(r.n, c->lens.count + 2, "film, every surface, beyond");
        cr_assert(fabs(out.o.x) < 1e-9, "a meridional ray");
        const int front = c->lens.count;
        cr_assert(fabs(r.z[front] - out.o.z) < 1e-6 && fabs(r.y[front] - out.o.y) < 1e-6,
                  "film y %g, v %g: drawn (%.9g, %.9g), traced (%.9g, %.9g)", r.film_y, r.v,
                  r.z[front], r.y[front], out.o.z, out.o.y);
        const double dz = r.z[front + 1] - r.z[front], dy = r.y[front + 1] - r.y[front];
        cr_assert(fabs(dz * out.d.y - dy * out.d.z) < 1e-6 * hypot(dz, dy) && dz * out.d.z + dy * out.d.y > 0,
                  "the last segment follows the outgoing ray");
    }
    return passed * 100 + field;
}

Test(diagram, the_rays_drawn_are_the_traced_rays)
{
    const char *dir = test_tmpdir();
    char *svg = diagram_of("dgauss.50mm", dir);
    camera c;
    test_camera(&c, "dgauss.50mm", NULL);
    const int counts = check_drawn_rays(svg, &c);
    cr_assert_eq(counts / 100, 14, "two fans of 7 rays pass the double-Gauss");
    cr_assert_eq(counts % 100, 7);
    camera_free(&c);
    free(svg);
}

/* Through a 0.2 mm stop the triplet's samples come from spectral pupils (dispersion is on for
   a lens with Abbe numbers), and the diagram draws from the one camera_trace uses at the d
   line: drawn from the pupil for the whole spectrum, most of its rays were blocked. */
Test(diagram, the_rays_drawn_through_a_small_stop_are_the_traced_rays)
{
    const char *dir = test_tmpdir();
    const char *path = tmp_path(dir, "lens.svg");
    run_lens2pov_ok("diagram", "diagram", "cooke-triplet.50mm", "--aperture-diameter", "0.2", "-o", path, NULL);
    char *svg = read_text(path, NULL);
    cr_assert(svg, "no %s", path);
    camera_options o;
    camera_options_default(&o);
    o.aperture_diameter_mm = 0.2;
    camera c;
    test_camera(&c, "cooke-triplet.50mm", &o);
    cr_assert(c.spectral, "spectral pupils through a 0.2 mm stop");
    const int counts = check_drawn_rays(svg, &c);
    cr_expect_geq(counts / 100, 10, "%d of 14 rays pass", counts / 100);
    camera_free(&c);
    free(svg);
}

Test(diagram, bad_requests_exit_2)
{
    const char *dir = test_tmpdir();
    const char *svg = tmp_path(dir, "x.svg");
    char *err = NULL;
    cr_assert_eq(run_lens2pov(NULL, &err, "diagram", "dgauss.50mm", NULL), 2);
    cr_assert(strstr(err, "-o"), "%s", err);
    free(err);
    cr_assert_eq(run_lens2pov(NULL, &err, "diagram", "no-such-lens", "-o", svg, NULL), 2);
    free(err);
    /* The telephoto cannot focus on the default look-at point, 1 m away. */
    cr_assert_eq(run_lens2pov(NULL, &err, "diagram", "telephoto.250mm", "-o", svg, NULL), 2);
    cr_assert(strstr(err, "focus"), "%s", err);
    free(err);
    cr_assert_not(file_exists(svg));
    cr_assert_eq(run_lens2pov(NULL, &err, "diagram", "dgauss.50mm", "--spp", "4", "-o", svg, NULL), 2);
    free(err);
    /* the name says what the file is: SVG, and plot's PNG */
    const char *png = tmp_path(dir, "x.png");
    cr_assert_eq(run_lens2pov(NULL, &err, "diagram", "dgauss.50mm", "-o", png, NULL), 2);
    cr_assert(err && strstr(err, "SVG") && strstr(err, png), "%s", err);
    free(err);
    cr_assert_eq(run_lens2pov(NULL, &err, "plot", "dgauss.50mm", "--what", "distortion", "-o", svg, NULL), 2);
    cr_assert(err && strstr(err, "PNG") && strstr(err, svg), "%s", err);
    free(err);
    cr_assert_not(file_exists(png));
    cr_assert_not(file_exists(svg));
}

/* ---- plot */

/* The PNG signature and the IHDR chunk's width and height (big-endian, bytes 16-23). */
static void check_png_size(const char *path, unsigned width, unsigned height)
{
    size_t n;
    unsigned char *png = (unsigned char *)read_text(path, &n);
    cr_assert(png && n > 24, "no PNG %s", path);
    cr_assert(!memcmp(png, "\x89PNG\r\n\x1a\n", 8) && !memcmp(png + 12, "IHDR", 4));
    const unsigned w = (unsigned)png[16] << 24 | png[17] << 16 | png[18] << 8 | png[19];
    const unsigned h = (unsigned)png[20] << 24 | png[21] << 16 | png[22] << 8 | png[23];
    cr_assert(w == width && h == height, "%ux%u, expected %ux%u", w, h, width, height);
    free(png);
}

/* The table plot prints: rows of numbers after the comment lines. */
static int read_table(const char *text, double rows[][5], int columns)
{
    int n = 0;
    for (const char *line = text; line && *line; line = strchr(line, '\n') ? strchr(line, '\n') + 1 : NULL) {
        if (*line == '#' || *line == '\n')
            continue;
        const char *p = line;
        for (int k = 0; k < columns; k++) {
            char *end;
            rows[n][k] = strtod(p, &end);
            cr_assert(end != p, "a short row: %.40s", line);
            p = end;
        }
        n++;
    }
    return n;
}

/* The double-Gauss at full aperture: E(0)/E(0) is 1, and the light falls toward the corner
   (the table's grid measures to a few 1e-4, the fall is far larger). */
Test(plot, vignetting_falls_from_1_toward_the_corner)
{
    const char *png = tmp_path(test_tmpdir(), "v.png");
    char *out = NULL;
    cr_assert_eq(run_lens2pov(&out, NULL, "plot", "dgauss.50mm", "--what", "vignetting", "-o", png, NULL), 0);
    check_png_size(png, 800, 500);
    double rows[64][5];
    const int n = read_table(out, rows, 5);   /* radius, full, f/4, f/8, f/16 */
    cr_assert_eq(n, 25);
    cr_assert_eq(rows[0][0], 0.0);
    for (int k = 1; k < 5; k++)
        cr_assert_eq(rows[0][k], 1.0);
    for (int i = 1; i < n; i++)
        cr_assert_lt(rows[i][1], rows[i - 1][1] + 1e-3, "full aperture, row %d", i);
    cr_assert_lt(rows[n - 1][1], 0.8 * rows[n - 1][4], "wide open vignettes more than f/16");
    free(out);
}

/* A small stop's cone is narrower than the coarse grid's cells that find it (at f/50 and
   beyond they missed it: E(0) was 0, the table inf or nan, exit 0). From f/16 on the
   double-Gauss's relative illumination hardly changes: f/64 and f/200 stay within 5e-3 of
   f/16 at every radius (the grids measure to a few 1e-4 of the wide cone, 1e-3 of these). */
Test(plot, vignetting_of_a_small_stop_is_measured)
{
    const char *png = tmp_path(test_tmpdir(), "vs.png");
    char *wide = NULL;
    cr_assert_eq(run_lens2pov(&wide, NULL, "plot", "dgauss.50mm", "--what", "vignetting", "-o",
                              png, NULL), 0);
    double w[64][5];
    const int n = read_table(wide, w, 5);
    const char *const stops[] = {"64", "200"};
    for (int k = 0; k < 2; k++) {
        char *out = NULL;
        cr_assert_eq(run_lens2pov(&out, NULL, "plot", "dgauss.50mm", "--what", "vignetting",
                                  "--f-number", stops[k], "-o", png, NULL), 0);
        double r[64][5];
        cr_assert_eq(read_table(out, r, 2), n);
        for (int i = 0; i < n; i++)
            cr_expect(fabs(r[i][1] - w[i][4]) < 5e-3, "f/%s at %g mm: %g, f/16 %g", stops[k],
                      r[i][0], r[i][1], w[i][4]);
        free(out);
    }
    free(wide);
}

/* --trace thick plots the thick lens's own light (its exit pupil's disk, which test_pupil.c
   checks against its samples): the full lens's vignetting is gone, only the disk's falloff is
   left, about cos^4 at the corner, far above the full lens wide open. */
Test(plot, vignetting_follows_trace_thick)
{
    const char *png = tmp_path(test_tmpdir(), "vt.png");
    char *full = NULL, *thick = NULL;
    cr_assert_eq(run_lens2pov(&full, NULL, "plot", "dgauss.50mm", "--what", "vignetting", "-o", png, NULL), 0);
    cr_assert_eq(run_lens2pov(&thick, NULL, "plot", "dgauss.50mm", "--what", "vignetting", "--trace",
                              "thick", "-o", png, NULL), 0);
    double f[64][5], t[64][5];
    const int n = read_table(full, f, 5);
    cr_assert_eq(read_table(thick, t, 5), n);
    cr_assert_gt(t[n - 1][1], 1.5 * f[n - 1][1], "thick %g, full %g at the corner", t[n - 1][1], f[n - 1][1]);
    cr_assert_gt(t[n - 1][1], 0.7);
    free(full), free(thick);
}

Test(plot, distortion_is_0_on_the_axis)
{
    const char *png = tmp_path(test_tmpdir(), "d.png");
    char *out = NULL;
    cr_assert_eq(run_lens2pov(&out, NULL, "plot", "dgauss.50mm", "--what", "distortion", "-o", png, NULL), 0);
    check_png_size(png, 800, 500);
    double rows[64][5];
    const int n = read_table(out, rows, 4);   /* radius, angle, paraxial height, distortion */
    cr_assert_eq(n, 25);
    cr_assert_eq(rows[0][3], 0.0);
    cr_assert(fabs(rows[1][3]) < 0.1, "near the axis %g%%", rows[1][3]);
    free(out);
}

Test(plot, bad_requests_exit_2_and_a_missing_gnuplot_1)
{
    const char *dir = test_tmpdir();
    const char *png = tmp_path(dir, "x.png");
    char *err = NULL;
    cr_assert_eq(run_lens2pov(NULL, &err, "plot", "dgauss.50mm", "--what", "mtf", "-o", png, NULL), 2);
    cr_assert(strstr(err, "mtf"), "%s", err);
    free(err);
    cr_assert_eq(run_lens2pov(NULL, &err, "plot", "dgauss.50mm", "-o", png, NULL), 2);
    cr_assert(strstr(err, "--what"), "%s", err);
    free(err);
    cr_assert_eq(run_lens2pov(NULL, &err, "plot", "dgauss.50mm", "--what", "distortion", NULL), 2);
    free(err);
    cr_assert_eq(run_lens2pov(NULL, &err, "plot", "telephoto.250mm", "--what", "distortion", "-o", png, NULL), 2);
    free(err);
    cr_assert_eq(run_lens2pov(NULL, &err, "diagram", "dgauss.50mm", "--what", "distortion", "-o", png, NULL), 2);
    free(err);
    setenv("PATH", "/nonexistent", 1);
    cr_assert_eq(run_lens2pov(NULL, &err, "plot", "dgauss.50mm", "--what", "distortion", "-o", png, NULL), 1);
    cr_assert(strstr(err, "gnuplot"), "%s", err);
    free(err);
    cr_assert_not(file_exists(png));
}

/* With blades the section cuts the stop where the polygon reaches: 5 blades with a corner at
   +y (rotation 90) reach the full radius R above the axis and the apothem R cos(36 deg) below;
   a round stop reaches R both ways. */
Test(diagram, the_stop_is_drawn_as_the_blades_cut_it)
{
    const char *dir = test_tmpdir();
    const char *svg_path = tmp_path(dir, "blades.svg");
    for (int blades = 0; blades < 2; blades++) {
        run_lens2pov_ok("diagram", "diagram", "dgauss.50mm", "--f-number", "4",
                        "--aperture-blades", blades ? "5" : "0", "--blade-rotation", "90", "-o",
                        svg_path, NULL);
        char *svg = read_text(svg_path, NULL);
        const char *stop = strstr(svg, "class=\"stop\" d=\"M ");
        cr_assert_not_null(stop);
        double z0, above, z1, outer, z2, below;
        cr_assert_eq(sscanf(stop, "class=\"stop\" d=\"M %lf,%lf L %lf,%lf M %lf,%lf", &z0, &above,
                            &z1, &outer, &z2, &below), 6);
        const double r = above;   /* a corner: the opening's radius */
        if (blades)
            cr_expect(fabs(-below - r * cos(M_PI / 5)) < 1e-9 * r,
                      "below the axis the stop reaches %g, the apothem is %g", -below,
                      r * cos(M_PI / 5));
        else
            cr_expect(fabs(-below - r) < 1e-12 * r, "round: %g and %g", above, -below);
        free(svg);
    }
}
