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

int pupil_stop_image(const lens *l, bool toward_film, double *z_mm, double *radius_mm,
                     l2p_error *err)
{
    const lens_surface *stop = &l->surface[l->stop];
    const int first = toward_film ? l->stop + 1 : 0, last = toward_film ? l->count - 1 : l->stop - 1;
    if (first > last) {           /* nothing on that side: the stop is its own image */
        *z_mm = stop->vertex_z_mm;
        *radius_mm = 0.5 * l->stop_diameter_mm;
        return L2P_OK;
    }
    thick_lens t;
    int st = thick_lens_of(l, first, last, &t, err);
    if (st)
        return st;
    const vec3 rim = v3(0.5 * l->stop_diameter_mm, 0, stop->vertex_z_mm);
    vec3 image;
    if (!(toward_film ? thick_image_from_real(&t, rim, &image) : thick_real_from_image(&t, rim, &image)))
        return l2p_fail(err, L2P_BAD_INPUT, l->path, stop->line,
                        "the %s pupil is at infinity: the stop lies in a focal plane of the "
                        "surfaces %s it%s", toward_film ? "exit" : "entrance",
                        toward_film ? "behind" : "in front of",
                        toward_film ? " (use --pupil rear)" : "");
    *z_mm = image.z;
    *radius_mm = fabs(image.x);
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
        int st = pupil_stop_image(l, true, &out->z_mm, &out->radius_mm, err);
        if (st)
            return st;
    }
    out->node_spacing_mm = 0.0;
    out->reach_mm = INFINITY;
    if (!(fabs(out->z_mm) > 1e-9 * (1.0 + out->radius_mm)) || !(out->radius_mm > 0.0))
        return l2p_fail(err, L2P_BAD_INPUT, l->path,
                        l->surface[kind == PUPIL_REAR ? l->count - 1 : l->stop].line,
                        "the %s exit pupil lies in the film plane; choose another --pupil or "
                        "film distance", pupil_kind_name(kind));
    return L2P_OK;
}

/* Shirley and Chiu's concentric map ("A low distortion map between disk and square", 1997). */
static inline void disk_point(double u, double v, double *x, double *y)
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

void concentric_disk(double u, double v, double *x, double *y) { disk_point(u, v, x, y); }

vec3 pupil_direction(const pupil *pu, vec3 film_point, double x_mm, double y_mm)
{
    /* A pupil behind the film is a virtual one: the ray leaves the film away from it. */
    const vec3 d = v3_sub(v3(x_mm, y_mm, pu->z_mm), film_point);
    return v3_normalize(pu->z_mm < 0.0 ? v3_scale(d, -1.0) : d);
}

bool pupil_shape_at(const pupil *pu, double r_mm, pupil_shape *out)
{
    if (!(r_mm <= pu->reach_mm))
        return false;
    if (!(pu->node_spacing_mm > 0.0)) {
        *out = (pupil_shape){0.0, pu->radius_mm, pu->radius_mm};
        return true;
    }
    const double t = r_mm / pu->node_spacing_mm;
    const int j = t < PUPIL_NODES - 1 ? (int)t : PUPIL_NODES - 1;
    const double f = fmin(t - j, 1.0);
    const pupil_shape *a = &pu->node[j], *b = &pu->node[j + 1];
    out->centre_mm = a->centre_mm + f * (b->centre_mm - a->centre_mm);
    out->radial_mm = a->radial_mm + f * (b->radial_mm - a->radial_mm);
    out->tangential_mm = a->tangential_mm + f * (b->tangential_mm - a->tangential_mm);
    return true;
}

/* The shape for film point p and the unit vector (c, s) from the axis toward p; (1, 0) on the
   axis, where the shape is a disk about it. */
static bool shape_for(const pupil *pu, vec3 p, pupil_shape *shape, double *c, double *s)
{
    const double r = sqrt(p.x * p.x + p.y * p.y);
    if (!pupil_shape_at(pu, r, shape))
        return false;
    *c = r > 0.0 ? p.x / r : 1.0;
    *s = r > 0.0 ? p.y / r : 0.0;
    return true;
}

/* The unit disk's point d goes to centre + M d with M = R diag(radial, tangential) R^T, R the
   turn by phi: a uniform map onto the ellipse (|det M| = radial tangential is constant) that
   does not turn d itself, so that a fixed sample moves continuously with the film point, also
   across the axis, where M tends to a multiple of the identity. */
bool pupil_point(const pupil *pu, vec3 film_point, double u, double v, double *x_mm,
                 double *y_mm, double *area_mm2)
{
    pupil_shape e;
    double c, s, dx, dy;
    if (!shape_for(pu, film_point, &e, &c, &s))
        return false;
    disk_point(u, v, &dx, &dy);
    const double radial = e.radial_mm * (c * dx + s * dy);
    const double tangential = e.tangential_mm * (c * dy - s * dx);
    *x_mm = c * (e.centre_mm + radial) - s * tangential;
    *y_mm = s * (e.centre_mm + radial) + c * tangential;
    *area_mm2 = M_PI * e.radial_mm * e.tangential_mm;
    return true;
}

bool pupil_contains(const pupil *pu, vec3 film_point, double x_mm, double y_mm)
{
    pupil_shape e;
    double c, s;
    if (!shape_for(pu, film_point, &e, &c, &s))
        return false;
    const double radial = (c * x_mm + s * y_mm - e.centre_mm) / e.radial_mm;
    const double tangential = (c * y_mm - s * x_mm) / e.tangential_mm;
    return radial * radial + tangential * tangential <= 1.0;
}

void pupil_film_rays(const pupil *pu, int n, const vec3 *film_points, const double *u,
                     const double *v, vec3 *directions, double *weights)
{
    for (int k = 0; k < n; k++) {
        double x, y, area;
        if (!pupil_point(pu, film_points[k], u[k], v[k], &x, &y, &area)) {
            directions[k] = v3(0.0, 0.0, 1.0);
            weights[k] = 0.0;
            continue;
        }
        directions[k] = pupil_direction(pu, film_points[k], x, y);
        const double cos_theta = directions[k].z;
        weights[k] = area * (cos_theta * cos_theta) * (cos_theta * cos_theta) / (pu->z_mm * pu->z_mm);
    }
}

double pupil_film_ray(const pupil *pu, vec3 film_point, double u, double v, vec3 *direction)
{
    double weight;
    pupil_film_rays(pu, 1, &film_point, &u, &v, direction, &weight);
    return weight;
}
