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
Test(diagram, the_rays_drawn_are_the_traced_rays)
{
    const char *dir = test_tmpdir();
    char *svg = diagram_of("dgauss.50mm", dir);
    camera c;
    test_camera(&c, "dgauss.50mm", NULL);
    drawn_ray r;
    int passed = 0, field = 0;
    for (const char *p = svg; (p = next_ray(p, &r));) {
        cr_assert_eq(r.z[0], 0.0);
        cr_assert_eq(r.y[0], r.film_y);
        ray out;
        double w;
        const bool ok = camera_trace(&c, v3(0, r.film_y, 0), 0.5, r.v, &out, &w);
        cr_assert_eq(ok, !r.blocked, "film y %g, v %g", r.film_y, r.v);
        if (!ok)
            continue;
        passed++;
        field += r.film_y > 0.0;
        cr_assert_eq(r.n, c.lens.count + 2, "film, every surface, beyond");
        cr_assert(fabs(out.o.x) < 1e-9, "a meridional ray");
        const int front = c.lens.count;
        cr_assert(fabs(r.z[front] - out.o.z) < 1e-6 && fabs(r.y[front] - out.o.y) < 1e-6,
                  "film y %g, v %g: drawn (%.9g, %.9g), traced (%.9g, %.9g)", r.film_y, r.v,
                  r.z[front], r.y[front], out.o.z, out.o.y);
        const double dz = r.z[front + 1] - r.z[front], dy = r.y[front + 1] - r.y[front];
        cr_assert(fabs(dz * out.d.y - dy * out.d.z) < 1e-6 * hypot(dz, dy) && dz * out.d.z + dy * out.d.y > 0,
                  "the last segment follows the outgoing ray");
    }
    cr_assert_eq(passed, 14, "two fans of 7 rays pass the double-Gauss");
    cr_assert_eq(field, 7);
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
}
