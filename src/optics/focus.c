#include "optics/focus.h"

#include "optics/thicklens.h"
#include "optics/trace.h"

/* Height of the refining ray at the lens, as a fraction of the smallest semi-aperture (see
   thicklens.c for the same trade-off). */
static const double PROBE_FRACTION = 1e-5;

static double probe_height_mm(const lens *l)
{
    double a = INFINITY;
    for (int i = 0; i < l->count; i++)
        a = fmin(a, lens_semi_aperture_mm(l, i));
    return PROBE_FRACTION * a;
}

/* Axial crossing (camera z) of a real near-axial ray from the object point, or NAN. */
static double axial_image_z(const lens *l, double object_z_mm)
{
    const double h = probe_height_mm(l);
    const double front_z = l->surface[0].vertex_z_mm;
    ray r;
    if (isinf(object_z_mm)) {
        r.o = v3(0, h, front_z + 1.0);
        r.d = v3(0, 0, -1);
    } else {
        r.o = v3(0, 0, object_z_mm);
        r.d = v3_normalize(v3(0, h, front_z - object_z_mm));
    }
    if (trace_toward_film(l, 0, l->count - 1, &r, NULL) != TRACE_PASSED || r.d.y == 0.0)
        return NAN;
    return r.o.z - r.o.y * r.d.z / r.d.y;
}

int focus_check_real_image(const lens *l, const thick_lens *t, l2p_error *err)
{
    if (!(t->rear_focal_length_mm > 0.0))
        return l2p_fail(err, L2P_BAD_INPUT, l->path, l->surface[0].line,
                        "the lens diverges light (focal length %g mm): it forms no real image",
                        t->rear_focal_length_mm);
    return L2P_OK;
}

/* Newton's x x' = f1 f2 with the lens at film distance d: x = D - (F1_0 + d),
   x' = F2_0 + d. With e = x' and S = D - F1_0 + F2_0: e^2 - S e + f1 f2 = 0, whose smaller
   root e = 2 f1 f2 / (S + sqrt(S^2 - 4 f1 f2)) keeps the film near the rear focal plane. */
static int thick_estimate(lens *l, double object_mm, double unit_mm, bool from_look_at, double *d,
                          l2p_error *err)
{
    lens_set_film_distance(l, 0.0);
    thick_lens t;
    int st = thick_lens_of(l, 0, l->count - 1, &t, err);
    if (st)
        return st;
    const double ff = t.front_focal_length_mm * t.rear_focal_length_mm;
    if ((st = focus_check_real_image(l, &t, err)) != 0)
        return st;
    double e = 0.0;
    if (!isinf(object_mm)) {
        const double S = object_mm - t.f1_z_mm + t.f2_z_mm;
        const double disc = S * S - 4.0 * ff;
        if (!(S > 0.0) || !(disc >= 0.0)) {
            const double closest = (2.0 * sqrt(ff) + t.f1_z_mm - t.f2_z_mm) / unit_mm;
            return from_look_at
                       ? l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "the look-at point, %g away, is "
                                  "closer than this lens can focus (the closest is %.6g, film "
                                  "plane to subject, scene units): give --focus-distance, or "
                                  "look at something farther", object_mm / unit_mm, closest)
                       : l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "focus distance %g is closer "
                                  "than this lens can focus: the closest is %.6g (film plane to "
                                  "subject, scene units)", object_mm / unit_mm, closest);
        }
        e = 2.0 * ff / (S + sqrt(disc));
    }
    *d = e - t.f2_z_mm;
    return L2P_OK;
}

int focus_set(lens *l, double object_distance_mm, double unit_mm, bool from_look_at,
              l2p_error *err)
{
    double d = 0.0;
    int st = thick_estimate(l, object_distance_mm, unit_mm, from_look_at, &d, err);
    if (st)
        return st;
    /* Moving the lens by delta moves a distant object's image by about delta, so the first
       step assumes slope 1; secant steps follow. */
    lens_set_film_distance(l, d);
    double r = axial_image_z(l, object_distance_mm);
    double d_prev = d, r_prev = r;
    const double tolerance = 1e-13 * (1.0 + d + lens_total_length_mm(l));
    for (int k = 0; k < 30 && isfinite(r) && fabs(r) > tolerance; k++) {
        const double slope = k == 0 ? 1.0 : (r - r_prev) / (d - d_prev);
        if (!(fabs(slope) > 1e-6))
            break;
        d_prev = d;
        r_prev = r;
        d -= r / slope;
        lens_set_film_distance(l, d);
        r = axial_image_z(l, object_distance_mm);
    }
    if (!isfinite(r)) {
        d = d_prev;    /* keep the last good step: the estimate is paraxially exact already */
        lens_set_film_distance(l, d);
    }
    if (!(d >= 0.0))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "focusing at %g would put the film %g mm inside the lens",
                        object_distance_mm / unit_mm, -d);
    return L2P_OK;
}

double focus_distance_mm(const lens *l)
{
    thick_lens t;
    if (thick_lens_of(l, 0, l->count - 1, &t, NULL) != L2P_OK)
        return NAN;
    vec3 conjugate;
    if (!thick_real_from_image(&t, v3(0, 0, 0), &conjugate))
        return INFINITY;
    return conjugate.z;
}
