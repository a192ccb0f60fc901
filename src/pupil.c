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
    for (int i = 0; i < PUPIL_RINGS; i++)
        out->ring_radius_mm[i] = out->radius_mm;
    out->ring_width_mm = 0.0;
    if (!(fabs(out->z_mm) > 1e-9 * (1.0 + out->radius_mm)) || !(out->radius_mm > 0.0))
        return l2p_fail(err, L2P_BAD_INPUT, l->path,
                        l->surface[kind == PUPIL_REAR ? l->count - 1 : l->stop].line,
                        "the %s exit pupil lies in the film plane; choose another --pupil or "
                        "film distance", pupil_kind_name(kind));
    return L2P_OK;
}

/* The bodies of concentric_disk and pupil_direction, inlined into pupil_film_rays, which runs
   for every film sample. */
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

static inline vec3 direction_toward(const pupil *pu, vec3 film_point, double x_mm, double y_mm)
{
    /* A pupil behind the film is a virtual one: the ray leaves the film away from it. */
    const vec3 d = v3_sub(v3(x_mm, y_mm, pu->z_mm), film_point);
    return v3_normalize(pu->z_mm < 0.0 ? v3_scale(d, -1.0) : d);
}

/* The ring of film point (x, y): hypot(x, y) / ring_width_mm rounded down, at most
   PUPIL_RINGS - 1 (also for NaN). hypot is slow. Where the squares neither overflow nor
   underflow, sqrt(x^2 + y^2) and hypot are both within a few ulps of the exact radius, so
   when the quotient widened by 1e-12 (relative, thousands of ulps) either side lies in one
   ring, hypot's lies in it too; only nearer a ring's edge does hypot decide. */
static inline int ring_index(const pupil *pu, double x, double y)
{
    if (!(pu->ring_width_mm > 0.0))
        return 0;
    const double r2_mm2 = x * x + y * y;
    if (r2_mm2 > 0x1p-900 && r2_mm2 < 0x1p900) {
        const double q = sqrt(r2_mm2) / pu->ring_width_mm;
        const double low = q * (1.0 - 1e-12), high = q * (1.0 + 1e-12);
        if (low >= PUPIL_RINGS - 1)
            return PUPIL_RINGS - 1;
        if (high < PUPIL_RINGS - 1 && (int)low == (int)high)
            return (int)low;
    }
    const double q = hypot(x, y) / pu->ring_width_mm;
    return q < PUPIL_RINGS - 1 ? (int)q : PUPIL_RINGS - 1;
}

void concentric_disk(double u, double v, double *x, double *y) { disk_point(u, v, x, y); }

vec3 pupil_direction(const pupil *pu, vec3 film_point, double x_mm, double y_mm)
{
    return direction_toward(pu, film_point, x_mm, y_mm);
}

double pupil_ring_radius_mm(const pupil *pu, vec3 film_point)
{
    return pu->ring_radius_mm[ring_index(pu, film_point.x, film_point.y)];
}

/* In passes over the batch, each a short chain of arithmetic per sample, so that the sines,
   square roots and divisions of different samples overlap. */
void pupil_film_rays(const pupil *pu, int n, const vec3 *film_points, const double *u,
                     const double *v, vec3 *directions, double *weights)
{
    for (int k = 0; k < n; k++) {            /* the points on the unit disk, kept in directions */
        double x, y;
        disk_point(u[k], v[k], &x, &y);
        directions[k] = v3(x, y, 0.0);
    }
    for (int k = 0; k < n; k++)              /* the radii of the rings, kept in weights */
        weights[k] = pu->ring_radius_mm[ring_index(pu, film_points[k].x, film_points[k].y)];
    for (int k = 0; k < n; k++) {
        const double radius = weights[k];
        directions[k] = direction_toward(pu, film_points[k], directions[k].x * radius,
                                         directions[k].y * radius);
        const double cos_theta = directions[k].z;
        const double area = M_PI * radius * radius;
        weights[k] = area * (cos_theta * cos_theta) * (cos_theta * cos_theta) / (pu->z_mm * pu->z_mm);
    }
}

double pupil_film_ray(const pupil *pu, vec3 film_point, double u, double v, vec3 *direction)
{
    double weight;
    pupil_film_rays(pu, 1, &film_point, &u, &v, direction, &weight);
    return weight;
}
