#include "optics/thicklens.h"

#include <float.h>

/* Probing height as a fraction of the smallest semi-aperture: small enough that aberrations
   (relative size ~ (h/f)^2) stay below 1e-10, large enough that the traced ray's slope keeps
   at least ten significant digits. */
static const double PROBE_FRACTION = 1e-5;

/* A system whose focal length is this many times its own size is treated as afocal. */
static const double AFOCAL_RATIO = 1e9;

static double smallest_semi_aperture(const lens *l, int first, int last)
{
    double a = DBL_MAX;
    for (int i = first; i <= last; i++)
        if (lens_semi_aperture_mm(l, i) < a)
            a = lens_semi_aperture_mm(l, i);
    return a;
}

static double system_size_mm(const lens *l, int first, int last)
{
    double size = l->surface[first].vertex_z_mm - l->surface[last].vertex_z_mm;
    for (int i = first; i <= last; i++)
        size = fmax(size, l->surface[i].aperture_diameter_mm);
    return size;
}

/* z where the ray reaches height y (the ray lies in the y-z plane). */
static double z_at_height(const ray *r, double y)
{
    return r->o.z + (y - r->o.y) * r->d.z / r->d.y;
}

static int blocked(l2p_error *err, const lens *l, int at, trace_status st)
{
    return l2p_fail(err, L2P_BAD_INPUT, l->path, l->surface[at].line,
                    "no thick lens: a ray parallel to the axis near it is %s at this surface",
                    st == TRACE_TIR ? "totally reflected" : "blocked");
}

int thick_lens_of(const lens *l, int first, int last, thick_lens *out, l2p_error *err)
{
    if (first > last || first < 0 || last >= l->count)
        return l2p_fail(err, L2P_BAD_INPUT, l->path, 0, "no thick lens of an empty subsystem");
    const double h = PROBE_FRACTION * smallest_semi_aperture(l, first, last);
    const double size = system_size_mm(l, first, last);
    int at = 0;

    ray from_scene = {v3(0, h, l->surface[first].vertex_z_mm + size), v3(0, 0, -1)};
    trace_status st = trace_toward_film(l, first, last, &from_scene, &at);
    if (st != TRACE_PASSED)
        return blocked(err, l, at, st);
    ray from_film = {v3(0, h, l->surface[last].vertex_z_mm - size), v3(0, 0, 1)};
    st = trace_toward_scene(l, first, last, &from_film, &at);
    if (st != TRACE_PASSED)
        return blocked(err, l, at, st);

    if (!(fabs(from_scene.d.y) * AFOCAL_RATIO * size > h) ||
        !(fabs(from_film.d.y) * AFOCAL_RATIO * size > h))
        return l2p_fail(err, L2P_BAD_INPUT, l->path, l->surface[first].line,
                        "no thick lens: surfaces on lines %d to %d form an afocal system",
                        l->surface[first].line, l->surface[last].line);
    out->f2_z_mm = z_at_height(&from_scene, 0.0);
    out->p2_z_mm = z_at_height(&from_scene, h);
    out->f1_z_mm = z_at_height(&from_film, 0.0);
    out->p1_z_mm = z_at_height(&from_film, h);
    out->front_focal_length_mm = out->f1_z_mm - out->p1_z_mm;
    out->rear_focal_length_mm = out->p2_z_mm - out->f2_z_mm;
    return L2P_OK;
}

bool thick_real_from_image(const thick_lens *t, vec3 image, vec3 *real)
{
    const double xi = t->f2_z_mm - image.z;             /* x' */
    if (xi == 0.0)
        return false;
    const double scale = -t->rear_focal_length_mm / xi; /* real / image heights */
    *real = v3(image.x * scale, image.y * scale,
               t->f1_z_mm + t->front_focal_length_mm * t->rear_focal_length_mm / xi);
    return v3_isfinite(*real);
}

bool thick_image_from_real(const thick_lens *t, vec3 real, vec3 *image)
{
    const double x = real.z - t->f1_z_mm;
    if (x == 0.0)
        return false;
    const double scale = -t->front_focal_length_mm / x;
    *image = v3(real.x * scale, real.y * scale,
                t->f2_z_mm - t->front_focal_length_mm * t->rear_focal_length_mm / x);
    return v3_isfinite(*image);
}

bool thick_trace_toward_scene(const thick_lens *t, ray *r)
{
    if (!(r->d.z > 0.0))
        return false;
    const double to_p2 = (t->p2_z_mm - r->o.z) / r->d.z;
    const double hx = r->o.x + r->d.x * to_p2, hy = r->o.y + r->d.y * to_p2;
    const double ratio = t->rear_focal_length_mm / t->front_focal_length_mm;
    const double sx = ratio * r->d.x / r->d.z - hx / t->front_focal_length_mm;
    const double sy = ratio * r->d.y / r->d.z - hy / t->front_focal_length_mm;
    r->o = v3(hx, hy, t->p1_z_mm);
    r->d = v3_normalize(v3(sx, sy, 1.0));
    return v3_isfinite(r->o) && v3_isfinite(r->d);
}
