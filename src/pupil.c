#include "pupil.h"

#include <string.h>
#include "thicklens.h"

static const char *const names[] = {"stop", "rear", "stop-image"};

const char *pupil_kind_name(pupil_kind k) { return names[k]; }

int pupil_kind_parse(const char *name, pupil_kind *k)
{
    for (int i = 0; i < 3; i++)
        if (strcmp(name, names[i]) == 0) {
            *k = (pupil_kind)i;
            return 0;
        }
    return -1;
}

/* The stop imaged by the surfaces behind it: its centre's conjugate gives the plane, its rim's
   conjugate the radius. */
static int stop_image(const lens *l, pupil *out, l2p_error *err)
{
    const lens_surface *stop = &l->surface[l->stop];
    if (l->stop == l->count - 1) {
        out->z_mm = stop->vertex_z_mm;
        out->radius_mm = 0.5 * l->stop_diameter_mm;
        return L2P_OK;
    }
    thick_lens t;
    int st = thick_lens_of(l, l->stop + 1, l->count - 1, &t, err);
    if (st)
        return st;
    vec3 rim;
    if (!thick_image_from_real(&t, v3(0.5 * l->stop_diameter_mm, 0, stop->vertex_z_mm), &rim))
        return l2p_fail(err, L2P_BAD_INPUT, l->path, stop->line,
                        "the stop lies in the front focal plane of the surfaces behind it: its "
                        "image is at infinity (use --pupil rear)");
    out->z_mm = rim.z;
    out->radius_mm = fabs(rim.x);
    return L2P_OK;
}

int pupil_make(const lens *l, pupil_kind kind, pupil *out, l2p_error *err)
{
    out->kind = kind;
    if (kind == PUPIL_STOP) {
        out->z_mm = l->surface[l->stop].vertex_z_mm;
        out->radius_mm = 0.5 * l->stop_diameter_mm;
    } else if (kind == PUPIL_REAR) {
        const lens_surface *rear = &l->surface[l->count - 1];
        out->radius_mm = 0.5 * rear->aperture_mm;
        out->z_mm = rear->vertex_z_mm + lens_sag_mm(rear, out->radius_mm);
    } else {
        int st = stop_image(l, out, err);
        if (st)
            return st;
    }
    if (!(fabs(out->z_mm) > 1e-9 * (1.0 + out->radius_mm)) || !(out->radius_mm > 0.0))
        return l2p_fail(err, L2P_BAD_INPUT, l->path, 0,
                        "the %s exit pupil lies in the film plane; choose another --pupil or "
                        "film distance", pupil_kind_name(kind));
    return L2P_OK;
}

void concentric_disk(double u, double v, double *x, double *y)
{
    const double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0) {
        *x = *y = 0.0;
        return;
    }
    double r, phi;
    if (fabs(a) > fabs(b)) {
        r = a;
        phi = (M_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = M_PI / 2.0 - (M_PI / 4.0) * (a / b);
    }
    *x = r * cos(phi);
    *y = r * sin(phi);
}

double pupil_film_ray(const pupil *pu, vec3 film_point, double u, double v, vec3 *direction)
{
    double dx, dy;
    concentric_disk(u, v, &dx, &dy);
    const vec3 target = v3(dx * pu->radius_mm, dy * pu->radius_mm, pu->z_mm);
    /* A pupil behind the film is a virtual one: the ray leaves the film away from it. */
    vec3 d = v3_sub(target, film_point);
    if (pu->z_mm < 0.0)
        d = v3_scale(d, -1.0);
    *direction = v3_normalize(d);
    const double cos_theta = direction->z;
    const double area = M_PI * pu->radius_mm * pu->radius_mm;
    return area * (cos_theta * cos_theta) * (cos_theta * cos_theta) / (pu->z_mm * pu->z_mm);
}
