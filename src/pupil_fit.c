/* Fitting a pupil's sampled region to the rays the lens passes (pupil_fit in pupil.h).

   For film point (r, 0, 0) the passing region of the pupil plane is the set of points whose
   ray from the film point gets through every surface: an intersection of the images of the
   stop and of the element rims, each nearly an ellipse, so nearly convex and symmetric about
   the x axis. It is found as its extent on the x axis (a passing point first, then both ends
   bisected) and its boundary bisected in DIRECTIONS + 1 directions over the upper half-plane
   from the middle of that extent. All directions are bisected in lockstep, so that the lane
   tracer takes them side by side. */
#include "pupil.h"
#include "trace_batch.h"

enum {
    DIRECTIONS = 96,   /* boundary points over [0, pi]: DIRECTIONS + 1 of them */
    BISECTIONS = 36,   /* each halves a bracket; the first is at most the region's size */
    DOUBLINGS = 60,    /* a bracket grows at most this often */
    NEAR_TRIES = 64,   /* points either side of the guess on the x axis, a quarter size apart */
    SCAN = 4096,       /* the last-resort scan along the x axis */
    CHECKS = 3         /* film radii checked between two nodes */
};

/* The last growth of every shape. The boundary is bisected to 2^-36 of the region's size, so
   what the fit can miss lies between two directions: where a vignetted region's top is the
   stop's nearly flat image and the ellipse curves more, the region's arc bulges past the
   ellipse through its neighbouring boundary points by about s^2 / 8 (kappa_ellipse -
   kappa_region) with s the points' spacing. With 48 directions that reached 0.26% on the
   double-Gauss's film edge; with 96 it is a quarter of that, and 0.4% covers it six times.
   The region's corners lie on the x axis, where a direction always points. */
static const double MARGIN = 1.004;

typedef struct region {
    bool found;
    double lo_mm, hi_mm;                   /* extent on the x axis */
    double x_mm[DIRECTIONS + 1], y_mm[DIRECTIONS + 1];   /* boundary, y >= 0 */
} region;

/* Traces the rays from (r, 0, 0) toward pupil points (x[k], y[k]); passed[k] for each. */
static void trace_points(const pupil *pu, const lens *l, double r, const double *x,
                         const double *y, int n, bool *passed)
{
    for (int done = 0; done < n; done += TRACE_SOA_MAX) {
        const int m = n - done < TRACE_SOA_MAX ? n - done : TRACE_SOA_MAX;
        trace_soa b;
        for (int k = 0; k < m; k++) {
            const vec3 d = pupil_direction(pu, v3(r, 0, 0), x[done + k], y[done + k]);
            b.ox[k] = r; b.oy[k] = 0; b.oz[k] = 0;
            b.dx[k] = d.x; b.dy[k] = d.y; b.dz[k] = d.z;
            b.status[k] = v3_isfinite(d) ? TRACE_PASSED : TRACE_MISSED;
        }
        trace_soa_toward_scene(l, &b, m);
        for (int k = 0; k < m; k++)
            passed[done + k] = b.status[k] == TRACE_PASSED;
    }
}

static bool passes(const pupil *pu, const lens *l, double r, double x, double y)
{
    bool p;
    trace_points(pu, l, r, &x, &y, 1, &p);
    return p;
}

/* Distances t[k] along the rays from (x0, y0) in directions (ux[k], uy[k]) where the region
   ends: each bracket [in, out] starts at [0, step], doubles while out passes, then is bisected.
   (x0, y0) must pass. */
static void boundary(const pupil *pu, const lens *l, double r, double x0, double y0,
                     const double *ux, const double *uy, int n, double step, double *t)
{
    double in[DIRECTIONS + 1], out[DIRECTIONS + 1], x[DIRECTIONS + 1], y[DIRECTIONS + 1];
    int growing[DIRECTIONS + 1];
    bool passed[DIRECTIONS + 1];
    for (int k = 0; k < n; k++) {
        in[k] = 0.0;
        out[k] = step;
        growing[k] = k;
    }
    for (int round = 0, m = n; round < DOUBLINGS && m > 0; round++) {
        for (int i = 0; i < m; i++) {
            x[i] = x0 + out[growing[i]] * ux[growing[i]];
            y[i] = y0 + out[growing[i]] * uy[growing[i]];
        }
        trace_points(pu, l, r, x, y, m, passed);
        int still = 0;
        for (int i = 0; i < m; i++) {
            const int k = growing[i];
            if (passed[i]) {
                in[k] = out[k];
                out[k] *= 2.0;
                growing[still++] = k;
            }
        }
        m = still;
    }
    for (int round = 0; round < BISECTIONS; round++) {
        for (int k = 0; k < n; k++) {
            x[k] = x0 + 0.5 * (in[k] + out[k]) * ux[k];
            y[k] = y0 + 0.5 * (in[k] + out[k]) * uy[k];
        }
        trace_points(pu, l, r, x, y, n, passed);
        for (int k = 0; k < n; k++)
            *(passed[k] ? &in[k] : &out[k]) = 0.5 * (in[k] + out[k]);
    }
    for (int k = 0; k < n; k++)
        t[k] = in[k];
}

/* Half-side of a square of the pupil plane that holds every useful point for film radius r:
   a ray that gets through crosses the rear surface within its semi-aperture a, no nearer to
   the film than z_near, so by similar triangles it meets the plane z = Z within
   r + (r + a) |Z| / z_near of the axis. */
static double search_half_side_mm(const pupil *pu, const lens *l, double r)
{
    const lens_surface *rear = &l->surface[l->count - 1];
    const double a = 0.5 * rear->aperture_mm;
    const double z_near = rear->vertex_z_mm + fmin(0.0, lens_sag_mm(rear, a));
    if (!(z_near > 1e-3 * a))
        return 10.0 * (r + a) + fabs(pu->z_mm);
    return 1.5 * (r + (r + a) * fabs(pu->z_mm) / z_near);
}

/* A passing point of the x axis: the guess, then points a quarter of size apart either side
   of it, then a scan of the whole useful segment. */
static bool find_on_axis(const pupil *pu, const lens *l, double r, double guess, double size,
                         double *x)
{
    double xs[2 * NEAR_TRIES + 1], ys[2 * NEAR_TRIES + 1] = {0};
    bool passed[2 * NEAR_TRIES + 1];
    xs[0] = guess;
    for (int k = 1; k <= NEAR_TRIES; k++) {
        xs[2 * k - 1] = guess + 0.25 * size * k;
        xs[2 * k] = guess - 0.25 * size * k;
    }
    trace_points(pu, l, r, xs, ys, 2 * NEAR_TRIES + 1, passed);
    for (int k = 0; k < 2 * NEAR_TRIES + 1; k++)
        if (passed[k]) {
            *x = xs[k];
            return true;
        }
    const double half = search_half_side_mm(pu, l, r);
    for (int done = 0; done < SCAN; done += TRACE_SOA_MAX) {
        double sx[TRACE_SOA_MAX], sy[TRACE_SOA_MAX] = {0};
        bool sp[TRACE_SOA_MAX];
        for (int k = 0; k < TRACE_SOA_MAX; k++)
            sx[k] = -half + 2.0 * half * (done + k + 0.5) / SCAN;
        trace_points(pu, l, r, sx, sy, TRACE_SOA_MAX, sp);
        for (int k = 0; k < TRACE_SOA_MAX; k++)
            if (sp[k]) {
                *x = sx[k];
                return true;
            }
    }
    return false;
}

/* The passing region for film radius r, searched from a guess of its centre and size. */
static region find_region(const pupil *pu, const lens *l, double r, double guess, double size)
{
    region g = {.found = false};
    double x0;
    if (!(size > 0.0) || !find_on_axis(pu, l, r, guess, size, &x0))
        return g;
    const double ux[2] = {1.0, -1.0}, uy[2] = {0.0, 0.0};
    double t[2];
    boundary(pu, l, r, x0, 0.0, ux, uy, 2, 0.125 * size, t);
    g.found = true;
    g.hi_mm = x0 + t[0];
    g.lo_mm = x0 - t[1];
    double middle = 0.5 * (g.lo_mm + g.hi_mm);
    if (!passes(pu, l, r, middle, 0.0))
        middle = x0;   /* not convex: x0 at least sees the region as a star */
    double dx[DIRECTIONS + 1], dy[DIRECTIONS + 1], s[DIRECTIONS + 1];
    for (int k = 0; k <= DIRECTIONS; k++) {
        dx[k] = cos(M_PI * k / DIRECTIONS);
        dy[k] = sin(M_PI * k / DIRECTIONS);
    }
    dx[DIRECTIONS] = -1.0;
    dy[DIRECTIONS] = 0.0;
    boundary(pu, l, r, middle, 0.0, dx, dy, DIRECTIONS + 1, 0.125 * (g.hi_mm - g.lo_mm), s);
    for (int k = 0; k <= DIRECTIONS; k++) {
        g.x_mm[k] = middle + s[k] * dx[k];
        g.y_mm[k] = s[k] * dy[k];
    }
    return g;
}

/* The smallest shape of the pupil's kind that holds the region: for stop-image the ellipse on
   the region's bounding box, grown until it holds every boundary point; for rear the disk
   about the axis that holds them and the rear rim. */
static pupil_shape fit_shape(const pupil *pu, const region *g)
{
    double lo = g->lo_mm, hi = g->hi_mm, top = 0.0, far = 0.0;
    for (int k = 0; k <= DIRECTIONS; k++) {
        lo = fmin(lo, g->x_mm[k]);
        hi = fmax(hi, g->x_mm[k]);
        top = fmax(top, g->y_mm[k]);
        far = fmax(far, hypot(g->x_mm[k], g->y_mm[k]));
    }
    if (pu->kind == PUPIL_REAR) {
        const double radius = fmax(pu->radius_mm, far);
        return (pupil_shape){0.0, radius, radius};
    }
    pupil_shape e = {0.5 * (lo + hi), fmax(0.5 * (hi - lo), 1e-300), fmax(top, 1e-300)};
    double worst = 1.0;
    for (int k = 0; k <= DIRECTIONS; k++)
        worst = fmax(worst, hypot((g->x_mm[k] - e.centre_mm) / e.radial_mm, g->y_mm[k] / e.tangential_mm));
    e.radial_mm *= worst;
    e.tangential_mm *= worst;
    return e;
}

/* How much shape e must grow about its centre to hold region g (at least 1). */
static double shortfall(const pupil_shape *e, const region *g)
{
    double worst = 1.0;
    for (int k = 0; k <= DIRECTIONS; k++)
        worst = fmax(worst, hypot((g->x_mm[k] - e->centre_mm) / e->radial_mm, g->y_mm[k] / e->tangential_mm));
    return worst;
}

static void grow(pupil_shape *e, double factor)
{
    e->radial_mm *= factor;
    e->tangential_mm *= factor;
}

/* The nodes' shapes where the region is found; found[j] says where. The guess for each node
   continues the two before it. */
static void fit_nodes(pupil *pu, const lens *l, bool *found)
{
    double guess = 0.0, size = pu->radius_mm;
    for (int j = 0; j <= PUPIL_NODES; j++) {
        const region g = find_region(pu, l, j * pu->node_spacing_mm, guess, size);
        found[j] = g.found;
        if (!g.found)
            continue;
        pu->node[j] = fit_shape(pu, &g);
        if (j == 0) {   /* on the axis the region is a disk about it */
            const double radius = fmax(pu->node[0].radial_mm, pu->node[0].tangential_mm);
            pu->node[0] = (pupil_shape){0.0, radius, radius};
        }
        const double previous = j > 0 && found[j - 1] ? pu->node[j - 1].centre_mm : pu->node[j].centre_mm;
        guess = 2.0 * pu->node[j].centre_mm - previous;
        size = pu->node[j].radial_mm;
    }
}

/* The film radius beyond which nothing passes, when the last nodes find nothing: bisected
   between the last node that finds the region and the first that does not, and at least the
   radius where the search last found it. Fills the empty nodes with the last found shape;
   INFINITY when every node or none finds the region, or when one is found after a gap. */
static double find_reach(pupil *pu, const lens *l, const bool *found)
{
    int last = -1;
    for (int j = 0; j <= PUPIL_NODES; j++)
        if (found[j])
            last = j;
    for (int j = 1; j <= PUPIL_NODES; j++)
        if (!found[j])
            pu->node[j] = pu->node[j - 1];
    if (last < 0 || last == PUPIL_NODES)
        return INFINITY;
    for (int j = 0; j < last; j++)
        if (!found[j])
            return INFINITY;
    const pupil_shape *e = &pu->node[last];
    double in = last * pu->node_spacing_mm, out = in + pu->node_spacing_mm;
    for (int k = 0; k < 40; k++) {
        const double mid = 0.5 * (in + out);
        if (find_region(pu, l, mid, e->centre_mm, e->radial_mm).found)
            in = mid;
        else
            out = mid;
    }
    return out;
}

/* The growth of b alone that grows the shape interpolated at fraction f from a to b by at least
   factor on both axes: (1 - f) a + f g b >= factor ((1 - f) a + f b). */
static double far_growth(const pupil_shape *a, const pupil_shape *b, double factor, double f)
{
    const double radial = 1.0 + (factor - 1.0) * ((1.0 - f) * a->radial_mm + f * b->radial_mm) /
                                    (f * b->radial_mm);
    const double tangential = 1.0 + (factor - 1.0) *
                                        ((1.0 - f) * a->tangential_mm + f * b->tangential_mm) /
                                        (f * b->tangential_mm);
    return fmax(radial, tangential);
}

/* Checks CHECKS film radii between each two nodes (up to the reach) against the shape
   interpolated there, and grows both nodes where it falls short; next to the axis only the
   outer one, since the disk on the axis is exact by symmetry. */
static void check_between(pupil *pu, const lens *l)
{
    for (int j = 0; j < PUPIL_NODES; j++)
        for (int c = 1; c <= CHECKS; c++) {
            const double r = (j + (double)c / (CHECKS + 1)) * pu->node_spacing_mm;
            pupil_shape e;
            if (!pupil_shape_at(pu, r, &e))
                continue;
            const region g = find_region(pu, l, r, e.centre_mm, e.radial_mm);
            if (!g.found)
                continue;
            const double factor = shortfall(&e, &g);
            if (factor <= 1.0)
                continue;
            if (j > 0) {
                grow(&pu->node[j], factor);
                grow(&pu->node[j + 1], factor);
            } else {
                grow(&pu->node[1], far_growth(&pu->node[0], &pu->node[1], factor, (double)c / (CHECKS + 1)));
            }
        }
}

void pupil_fit(pupil *pu, const lens *l, double film_radius_mm)
{
    if (!(film_radius_mm > 0.0) || !isfinite(film_radius_mm))
        return;
    bool found[PUPIL_NODES + 1];
    pu->node_spacing_mm = film_radius_mm / PUPIL_NODES;
    for (int j = 0; j <= PUPIL_NODES; j++)
        pu->node[j] = (pupil_shape){0.0, pu->radius_mm, pu->radius_mm};
    fit_nodes(pu, l, found);
    pu->reach_mm = find_reach(pu, l, found);
    check_between(pu, l);
    for (int j = 0; j <= PUPIL_NODES; j++)
        grow(&pu->node[j], MARGIN);
}
