/* The SVG of a lens in its meridional section. Lengths are drawn in camera-space millimetres
   inside one group whose transform puts the scene on the left and the film on the right
   (svg x = margin + (zmax - z) s, svg y = margin + (ymax - y) s), so that the points written
   are the traced ones; text is placed outside that group, in pixels, so that it reads upright. */
#include "draw/diagram.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "draw/svg.h"
#include "optics/pupil.h"

/* Width of the drawing in pixels, and the margin around it. */
#define DIAGRAM_WIDTH_PX 960.0
#define DIAGRAM_MARGIN_PX 40.0
/* Points along a surface's outline: its sag is smooth, 64 chords are invisible at this size. */
#define SURFACE_STEPS 64

double diagram_field_height_mm(const camera *c)
{
    const double half_diagonal = 0.5 * c->film.diagonal_mm;
    return isfinite(c->pupil.reach_mm) ? fmin(half_diagonal, 0.98 * c->pupil.reach_mm)
                                       : half_diagonal;
}

/* Just inside the rim of the region, where the rays graze the lens's limits. */
double diagram_fan_v(int k)
{
    return 0.02 + 0.96 * k / (DIAGRAM_FAN_RAYS - 1);
}

int diagram_ray_points(const camera *c, double film_y, double v, vec3 *points, bool *passed,
                       vec3 *direction)
{
    const lens *l = &c->lens;
    ray r = {v3(0, film_y, 0), v3(0, 0, 1)};
    int n = 0;
    points[n++] = r.o;
    *passed = false;
    /* The same film ray camera_trace sends, then the full simulation one surface at a time,
       which crosses the surfaces exactly as trace_toward_scene over the whole lens does. */
    if (!(pupil_film_ray(camera_pupil_at(c, WAVELENGTH_D_NM), r.o, 0.5, v, &r.d) > 0.0))
        return n;
    for (int i = l->count - 1; i >= 0; i--) {
        int blocked;
        if (trace_toward_scene(l, i, i, &r, &blocked) != TRACE_PASSED)
            return n;
        points[n++] = r.o;
    }
    *passed = true;
    if (direction)
        *direction = r.d;
    return n;
}

/* ---- Extent and scale. */

typedef struct fan {
    double film_y;
    const char *name;
    vec3 points[DIAGRAM_FAN_RAYS][DIAGRAM_MAX_SURFACES + 1];
    vec3 end[DIAGRAM_FAN_RAYS];   /* beyond the front surface, on the outgoing ray */
    int count[DIAGRAM_FAN_RAYS];
    bool passed[DIAGRAM_FAN_RAYS];
} fan;

typedef struct scene {
    const camera *c;
    thick_lens t;
    double ep_z, ep_r, xp_z, xp_r;   /* entrance and exit pupils */
    double extend_mm;                /* how far rays are drawn beyond the front surface */
    fan fans[2];
    svg_view v;
} scene;

static void grow(svg_view *v, double z, double y)
{
    v->zmin = fmin(v->zmin, z);
    v->zmax = fmax(v->zmax, z);
    v->ymax = fmax(v->ymax, fabs(y));
}

/* Every point drawn: the lens, the film, the marks, the rays and their extensions. */
static void fit_view(scene *s)
{
    const lens *l = &s->c->lens;
    svg_view *v = &s->v;
    v->zmin = v->zmax = 0.0;
    v->ymax = 0.5 * s->c->film.diagonal_mm;
    for (int i = 0; i < l->count; i++)
        grow(v, l->surface[i].vertex_z_mm + lens_sag_mm(&l->surface[i], lens_semi_aperture_mm(l, i)),
             0.5 * l->surface[i].aperture_diameter_mm);
    const double marks[] = {s->t.p1_z_mm, s->t.p2_z_mm, s->t.f1_z_mm, s->t.f2_z_mm, s->ep_z, s->xp_z};
    for (int i = 0; i < 6; i++)
        if (isfinite(marks[i]))
            grow(v, marks[i], 0.0);
    grow(v, s->ep_z, s->ep_r);
    grow(v, s->xp_z, s->xp_r);
    for (int f = 0; f < 2; f++)
        for (int k = 0; k < DIAGRAM_FAN_RAYS; k++) {
            const fan *fa = &s->fans[f];
            const vec3 *p = fa->points[k];
            for (int j = 0; j < fa->count[k]; j++)
                grow(v, p[j].z, p[j].y);
            if (fa->passed[k])
                grow(v, fa->end[k].z, fa->end[k].y);
        }
    const double pad = 0.06 * (v->zmax - v->zmin);
    v->zmin -= pad;
    v->zmax += pad;
    v->ymax *= 1.12;
    v->margin_px = DIAGRAM_MARGIN_PX;
    v->scale = DIAGRAM_WIDTH_PX / (v->zmax - v->zmin);
}

/* ---- The drawing. */

/* The outline of surface i from -a to +a (or back), continuing a path. */
static void surface_outline(FILE *out, const lens *l, int i, bool up)
{
    const double a = lens_semi_aperture_mm(l, i);
    for (int k = 0; k <= SURFACE_STEPS; k++) {
        const double y = a * (up ? -1.0 + 2.0 * k / SURFACE_STEPS : 1.0 - 2.0 * k / SURFACE_STEPS);
        fprintf(out, " %.12g,%.12g", l->surface[i].vertex_z_mm + lens_sag_mm(&l->surface[i], y), y);
    }
}

/* A surface with glass behind it begins an element that ends at the next surface: its front
   surface up, the back surface down, joined at the rims. */
static void draw_elements(FILE *out, const lens *l)
{
    for (int i = 0; i + 1 < l->count; i++) {
        if (!(lens_ior_behind(l, i) > 1.0) || i == l->stop)
            continue;
        fprintf(out, "<path class=\"element\" data-surface=\"%d\" d=\"M", i);
        surface_outline(out, l, i, true);
        fputs(" L", out);
        surface_outline(out, l, i + 1, false);
        fputs(" Z\"/>\n", out);
    }
}

/* Two bars, from the opening at `above` (+y) and `below` (-y) of the axis out to `outer`. */
static void draw_bars_apart(FILE *out, const char *class, double z, double above, double below,
                            double outer)
{
    fprintf(out, "<path class=\"%s\" d=\"M %.12g,%.12g L %.12g,%.12g M %.12g,%.12g L %.12g,%.12g\"/>\n",
            class, z, above, z, outer, z, -below, z, -outer);
}

/* Two bars from the opening out to the stop's largest opening and a little beyond. */
static void draw_bars(FILE *out, const char *class, double z, double inner, double outer)
{
    draw_bars_apart(out, class, z, inner, inner, outer);
}

static void draw_rays(FILE *out, const scene *s)
{
    for (int f = 0; f < 2; f++) {
        const fan *fa = &s->fans[f];
        for (int k = 0; k < DIAGRAM_FAN_RAYS; k++) {
            const vec3 *p = fa->points[k];
            const int n = fa->count[k];
            fprintf(out, "<polyline class=\"ray %s%s\" data-film-y=\"%.17g\" data-v=\"%.17g\" points=\"",
                    fa->name, fa->passed[k] ? "" : " blocked", fa->film_y, diagram_fan_v(k));
            for (int j = 0; j < n; j++)
                fprintf(out, "%s%.17g,%.17g", j ? " " : "", p[j].z, p[j].y);
            if (fa->passed[k])
                fprintf(out, " %.17g,%.17g", fa->end[k].z, fa->end[k].y);
            fputs("\"/>\n", out);
        }
    }
}

/* A tick across the axis with its label above. */
static void draw_mark(FILE *out, const svg_view *v, const char *class, const char *label,
                      double z, double half_height)
{
    if (!isfinite(z))
        return;
    fprintf(out, "<line class=\"%s\" x1=\"%.6f\" y1=\"%.6f\" x2=\"%.6f\" y2=\"%.6f\"/>\n", class,
            svg_x(v, z), svg_y(v, half_height), svg_x(v, z), svg_y(v, -half_height));
    svg_text(out, "label", svg_x(v, z), svg_y(v, half_height) - 4.0, label);
}

static void draw_labels(FILE *out, const scene *s)
{
    const svg_view *v = &s->v;
    const lens *l = &s->c->lens;
    const double tick = 0.05 * v->ymax;
    draw_mark(out, v, "mark", "P1", s->t.p1_z_mm, tick);
    draw_mark(out, v, "mark", "P2", s->t.p2_z_mm, 2.2 * tick);
    draw_mark(out, v, "mark", "F1", s->t.f1_z_mm, tick);
    draw_mark(out, v, "mark", "F2", s->t.f2_z_mm, 2.2 * tick);
    svg_text(out, "label", svg_x(v, s->ep_z), svg_y(v, -s->ep_r) + 14.0, "EP");
    svg_text(out, "label", svg_x(v, s->xp_z), svg_y(v, -s->xp_r) + 14.0, "XP");
    const double a = lens_semi_aperture_mm(l, l->stop), big = 0.5 * l->surface[l->stop].aperture_diameter_mm;
    svg_text(out, "label", svg_x(v, l->surface[l->stop].vertex_z_mm),
             svg_y(v, fmax(a, big) + 0.1 * v->ymax) - 4.0, "stop");
    svg_text(out, "label", svg_x(v, 0.0), svg_y(v, 0.5 * s->c->film.diagonal_mm) - 4.0, "film");
    char title[512], focus[64];
    /* Focused at infinity, the film distance is the rear focal one to rounding, and the
       conjugate it gives is some 1e12 film distances away, of either sign. */
    if (fabs(s->c->focus_distance_units * s->c->unit_mm) < 1e6 * l->film_distance_mm)
        snprintf(focus, sizeof focus, "%.4g units", s->c->focus_distance_units);
    else
        snprintf(focus, sizeof focus, "infinity");
    snprintf(title, sizeof title, "%s: f/%.3g, focus at %s, film %.4g mm from the rear vertex",
             l->name, s->c->f_number, focus, l->film_distance_mm);
    svg_text(out, "title", v->margin_px, 20.0, title);
}

static void draw(FILE *out, const scene *s)
{
    const svg_view *v = &s->v;
    const lens *l = &s->c->lens;
    svg_begin(out, v);
    fprintf(out, "<line class=\"axis\" x1=\"%.12g\" y1=\"0\" x2=\"%.12g\" y2=\"0\"/>\n", v->zmin, v->zmax);
    draw_elements(out, l);
    const double a = lens_semi_aperture_mm(l, l->stop), big = 0.5 * l->surface[l->stop].aperture_diameter_mm;
    /* the section (x = 0) cuts blades where the polygon reaches along +y and -y */
    draw_bars_apart(out, "stop", l->surface[l->stop].vertex_z_mm, lens_stop_reach_mm(l, 0, 1),
                    lens_stop_reach_mm(l, 0, -1), fmax(a, big) + 0.1 * v->ymax);
    draw_bars(out, "pupil", s->ep_z, s->ep_r, s->ep_r + 0.04 * v->ymax);
    draw_bars(out, "pupil", s->xp_z, s->xp_r, s->xp_r + 0.04 * v->ymax);
    const double film = 0.5 * s->c->film.diagonal_mm;
    fprintf(out, "<line class=\"film\" x1=\"0\" y1=\"%.12g\" x2=\"0\" y2=\"%.12g\"/>\n", film, -film);
    draw_rays(out, s);
    svg_end_group(out);
    draw_labels(out, s);
    svg_scale_bar(out, v);
    svg_finish(out);
}

static void trace_fan(const camera *c, fan *f, double film_y, const char *name, double extend_mm)
{
    f->film_y = film_y;
    f->name = name;
    for (int k = 0; k < DIAGRAM_FAN_RAYS; k++) {
        vec3 d = v3(0, 0, 1);
        const int n = diagram_ray_points(c, film_y, diagram_fan_v(k), f->points[k], &f->passed[k], &d);
        f->count[k] = n;
        f->end[k] = v3_add(f->points[k][n - 1], v3_scale(d, extend_mm));
    }
}

int diagram_write_svg(FILE *out, const camera *c, l2p_error *err)
{
    const lens *l = &c->lens;
    if (l->count > DIAGRAM_MAX_SURFACES)
        return l2p_fail(err, L2P_BAD_INPUT, l->path, 0, "%d surfaces: the diagram draws at most %d",
                        l->count, DIAGRAM_MAX_SURFACES);
    scene *s = calloc(1, sizeof *s);
    if (!s)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    s->c = c;
    int st = thick_lens_of(l, 0, l->count - 1, &s->t, err);
    if (!st)
        st = pupil_stop_image(l, false, &s->ep_z, &s->ep_r, err);
    if (!st)
        st = pupil_stop_image(l, true, &s->xp_z, &s->xp_r, err);
    if (!st) {
        s->extend_mm = 0.3 * (l->surface[0].vertex_z_mm + 0.5 * c->film.diagonal_mm);
        trace_fan(c, &s->fans[0], 0.0, "axial", s->extend_mm);
        trace_fan(c, &s->fans[1], diagram_field_height_mm(c), "field", s->extend_mm);
        fit_view(s);
        draw(out, s);
    }
    free(s);
    return st;
}
