#include "optics/pupil.h"

#include <string.h>
#include "optics/thicklens.h"

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

/* Whether surfaces first..last bend no ray: each has the medium of the one before it (air in
   front of the first surface), as dummy and baffle rows exported by design programs do. */
static bool refracts_nothing(const lens *l, int first, int last)
{
    for (int k = first; k <= last; k++) {
        const double before = k > 0 ? l->surface[k - 1].ior : 1.0, abbe = k > 0 ? l->surface[k - 1].abbe : 0.0;
        if (l->surface[k].ior != before || l->surface[k].abbe != abbe)
            return false;
    }
    return true;
}

int pupil_stop_image(const lens *l, bool toward_film, double *z_mm, double *radius_mm,
                     l2p_error *err)
{
    const lens_surface *stop = &l->surface[l->stop];
    const int first = toward_film ? l->stop + 1 : 0, last = toward_film ? l->count - 1 : l->stop - 1;
    if (first > last || refracts_nothing(l, first, last)) {   /* the stop is its own image */
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
        out->radius_mm = 0.5 * rear->aperture_diameter_mm;
        out->z_mm = rear->vertex_z_mm + lens_sag_mm(rear, out->radius_mm);
    } else {
        int st = pupil_stop_image(l, true, &out->z_mm, &out->radius_mm, err);
        if (st)
            return st;
    }
    out->node_spacing_mm = 0.0;
    out->chief_spacing_mm = 0.0;
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

/* The forward map's branches read backwards: where |x| >= |y| the square's ring coordinate is
   a = sign(x) r and b / a = atan(y / x) / (pi / 4); elsewhere b = sign(y) r and
   a / b = atan(x / y) / (pi / 4). */
void pupil_square_of_disk(double x, double y, double *u, double *v)
{
    const double r = hypot(x, y);
    double a = 0.0, b = 0.0;
    if (r > 0.0 && fabs(x) >= fabs(y)) {
        a = copysign(r, x);
        b = a * atan(y / x) / (M_PI / 4.0);
    } else if (r > 0.0) {
        b = copysign(r, y);
        a = b * atan(x / y) / (M_PI / 4.0);
    }
    *u = 0.5 * (a + 1.0);
    *v = 0.5 * (b + 1.0);
}

vec3 pupil_direction(const pupil *pu, vec3 film_point, double x_mm, double y_mm)
{
    /* A pupil behind the film is a virtual one: the ray leaves the film away from it. */
    const vec3 d = v3_sub(v3(x_mm, y_mm, pu->z_mm), film_point);
    return v3_normalize(pu->z_mm < 0.0 ? v3_scale(d, -1.0) : d);
}

/* The node j and fraction f of film radius r; false beyond the reach. */
static bool node_of(const pupil *pu, double r_mm, int *j, double *f)
{
    if (!(r_mm <= pu->reach_mm))
        return false;
    const double t = r_mm / pu->node_spacing_mm;
    *j = t < PUPIL_NODES - 1 ? (int)t : PUPIL_NODES - 1;
    *f = fmin(t - *j, 1.0);
    return true;
}

/* The knot i and fraction g of cos(phi), clamped to [-1, 1]. */
static inline void knot_of(double cos_phi, int *i, double *g)
{
    const double t = 0.5 * PUPIL_KNOTS * (1.0 - fmax(-1.0, fmin(1.0, cos_phi)));
    *i = t < PUPIL_KNOTS - 1 ? (int)t : PUPIL_KNOTS - 1;
    *g = fmin(t - *i, 1.0);
}

double pupil_shape_radius_mm(const pupil_shape *e, double cos_phi)
{
    int i;
    double g;
    knot_of(cos_phi, &i, &g);
    return e->radius_mm[i] + g * (e->radius_mm[i + 1] - e->radius_mm[i]);
}

/* The chief ray's crossing at film radius r: Catmull-Rom between the tabulated ones, odd about
   the axis and continued quadratically past the last; constant beyond the table. */
static double chief_x_at(const pupil *pu, double r_mm)
{
    if (!(pu->chief_spacing_mm > 0.0))
        return 0.0;
    const double *x = pu->chief_x_mm, t = fmin(r_mm / pu->chief_spacing_mm, PUPIL_CHIEF_SAMPLES);
    const int i = t < PUPIL_CHIEF_SAMPLES - 1 ? (int)t : PUPIL_CHIEF_SAMPLES - 1;
    const double f = t - i, p1 = x[i], p2 = x[i + 1];
    const double p0 = i > 0 ? x[i - 1] : -x[1];
    const double p3 = i + 2 <= PUPIL_CHIEF_SAMPLES ? x[i + 2] : 3.0 * p2 - 3.0 * p1 + p0;
    return p1 + 0.5 * f * (p2 - p0 + f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 +
                                          f * (3.0 * (p1 - p2) + p3 - p0)));
}

/* The region's centre at film radius r, in node j at fraction f: the chief ray's crossing plus
   the two nodes' offsets from theirs (pupil.h). */
static double centre_at(const pupil *pu, double r_mm, int j, double f)
{
    const double a = pu->node[j].centre_mm - pupil_chief_at_node(pu, j);
    const double b = pu->node[j + 1].centre_mm - pupil_chief_at_node(pu, j + 1);
    return chief_x_at(pu, r_mm) + a + f * (b - a);
}

bool pupil_shape_at(const pupil *pu, double r_mm, pupil_shape *out)
{
    if (!pupil_is_fitted(pu)) {
        if (!(r_mm <= pu->reach_mm))
            return false;
        out->centre_mm = 0.0;
        for (int i = 0; i <= PUPIL_KNOTS; i++)
            out->radius_mm[i] = pu->radius_mm;
        return true;
    }
    int j;
    double f;
    if (!node_of(pu, r_mm, &j, &f))
        return false;
    const pupil_shape *a = &pu->node[j], *b = &pu->node[j + 1];
    out->centre_mm = centre_at(pu, r_mm, j, f);
    for (int i = 0; i <= PUPIL_KNOTS; i++)
        out->radius_mm[i] = a->radius_mm[i] + f * (b->radius_mm[i] - a->radius_mm[i]);
    return true;
}

/* For film point p: the region's centre (cx, cy) in the pupil plane, the unit vector (c, s)
   from the axis toward p ((1, 0) on the axis, where the region is a disk about it), and the
   node j and fraction f of p's radius (j = -1: the model's disk). False beyond the reach. */
static bool locate(const pupil *pu, vec3 p, double *cx, double *cy, double *c, double *s,
                   int *j, double *f)
{
    const double r = sqrt(p.x * p.x + p.y * p.y);
    *c = r > 0.0 ? p.x / r : 1.0;
    *s = r > 0.0 ? p.y / r : 0.0;
    if (!pupil_is_fitted(pu)) {
        *j = -1;
        *cx = *cy = 0.0;
        return r <= pu->reach_mm;
    }
    if (!node_of(pu, r, j, f))
        return false;
    const double centre = centre_at(pu, r, *j, *f);
    *cx = centre * *c;
    *cy = centre * *s;
    return true;
}

/* R toward (dx, dy) from the centre ((0, 0): any direction), for film direction (c, s), node
   j and fraction f: only the two knots either side, of the two nodes either side. */
static double radius_toward(const pupil *pu, double dx, double dy, double c, double s, int j,
                            double f)
{
    if (j < 0)
        return pu->radius_mm;
    const double length = sqrt(dx * dx + dy * dy);
    int i;
    double g;
    knot_of(length > 0.0 ? (c * dx + s * dy) / length : 1.0, &i, &g);
    const pupil_shape *a = &pu->node[j], *b = &pu->node[j + 1];
    const double ra = a->radius_mm[i] + g * (a->radius_mm[i + 1] - a->radius_mm[i]);
    const double rb = b->radius_mm[i] + g * (b->radius_mm[i + 1] - b->radius_mm[i]);
    return ra + f * (rb - ra);
}

/* The disk's point d goes to centre + R(phi) d, phi the angle of d from the film point's
   direction. The angle of d is kept, so a fixed sample moves continuously with the film
   point, also across the axis, where R is constant. A sector of the unit disk (area dphi / 2)
   maps onto one of area R^2 dphi / 2: the density is 1 / (pi R^2). */
static bool pupil_point_of_disk(const pupil *pu, vec3 film_point, double dx, double dy,
                                double *x_mm, double *y_mm, double *inverse_density_mm2)
{
    double cx, cy, c, s, f = 0.0;
    int j;
    if (!locate(pu, film_point, &cx, &cy, &c, &s, &j, &f))
        return false;
    const double radius = radius_toward(pu, dx, dy, c, s, j, f);
    *x_mm = cx + radius * dx;
    *y_mm = cy + radius * dy;
    *inverse_density_mm2 = M_PI * radius * radius;
    return true;
}

bool pupil_point(const pupil *pu, vec3 film_point, double u, double v, double *x_mm,
                 double *y_mm, double *inverse_density_mm2)
{
    double dx, dy;
    disk_point(u, v, &dx, &dy);
    return pupil_point_of_disk(pu, film_point, dx, dy, x_mm, y_mm, inverse_density_mm2);
}

bool pupil_contains(const pupil *pu, vec3 film_point, double x_mm, double y_mm)
{
    double cx, cy, c, s, f = 0.0;
    int j;
    if (!locate(pu, film_point, &cx, &cy, &c, &s, &j, &f))
        return false;
    const double dx = x_mm - cx, dy = y_mm - cy;
    const double radius = radius_toward(pu, dx, dy, c, s, j, f);
    return dx * dx + dy * dy <= radius * radius;
}

void pupil_film_rays(const pupil *pu, int n, const vec3 *film_points, const double *u,
                     const double *v, vec3 *directions, double *weights)
{
    double dx = 0.0, dy = 0.0;
    for (int k = 0; k < n; k++) {
        double x, y, area;   /* the inverse density: the area of a uniform region */
        /* a ray field shares one sample among all its pixels: its disk point once */
        if (k == 0 || u[k] != u[k - 1] || v[k] != v[k - 1])
            disk_point(u[k], v[k], &dx, &dy);
        if (!pupil_point_of_disk(pu, film_points[k], dx, dy, &x, &y, &area)) {
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
