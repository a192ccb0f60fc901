/* Fitting a pupil's sampled region to the rays the lens passes (pupil_fit in pupil.h).

   For film point (r, 0, 0) the passing region of the pupil plane is the set of points whose
   ray from the film point gets through every surface: an intersection of the images of the
   stop and of the element rims, each nearly an ellipse, so nearly convex and symmetric about
   the x axis. It is found as its extent on the x axis (a passing point first, then both ends
   bisected) and its boundary bisected in DIRECTIONS + 1 directions over the upper half-plane
   from the middle of that extent. All directions are bisected in lockstep, so that the lane
   tracer takes them side by side. */
#include "optics/pupil.h"
#include "optics/chief.h"
#include "optics/trace_batch.h"

enum {
    DIRECTIONS = 96,   /* boundary points over [0, pi]: DIRECTIONS + 1 of them */
    BISECTIONS = 30,   /* each halves a bracket; the first is at most the region's size */
    DOUBLINGS = 60,    /* a bracket grows at most this often */
    NEAR_TRIES = 64,   /* points either side of the guess on the x axis, a quarter size apart */
    SCAN = 4096,       /* the last-resort scan along the x axis */
    CHECKS = 1         /* film radii checked between two nodes */
};

/* The last growth of every shape. The boundary is bisected to 2^-30 of the region's size, so
   what the fit can miss lies between two of the 97 directions, where the region's arc may
   bulge past the radius interpolated linearly in the angle: by about s^2 / 8 times the
   radius's second derivative in the angle, s = pi / 96, a few 1e-4 of the radius for the
   regions a lens makes. 0.4% holds that several times over, and the fit samples four angles
   between each two directions as well (PUPIL_FIT_MARGIN, pupil.h). */
static const double MARGIN = PUPIL_FIT_MARGIN;

typedef struct region {
    bool found;
    double lo_mm, hi_mm;                   /* extent on the x axis */
    double middle_mm;                      /* where the boundary is seen from, on the x axis */
    double x_mm[DIRECTIONS + 1], y_mm[DIRECTIONS + 1];   /* boundary, y >= 0 */
} region;

/* Traces the rays from (r, 0, 0) toward pupil points (x[k], y[k]); passed[k] for each. */
static void trace_points(const pupil *pu, const lens *l, double r, const double *x,
                         const double *y, int n, bool *passed)
{
    for (int done = 0; done < n; done += TRACE_BATCH_MAX) {
        const int m = n - done < TRACE_BATCH_MAX ? n - done : TRACE_BATCH_MAX;
        trace_batch b;
        for (int k = 0; k < m; k++) {
            const vec3 d = pupil_direction(pu, v3(r, 0, 0), x[done + k], y[done + k]);
            b.ox[k] = r; b.oy[k] = 0; b.oz[k] = 0;
            b.dx[k] = d.x; b.dy[k] = d.y; b.dz[k] = d.z;
            b.status[k] = v3_isfinite(d) ? TRACE_PASSED : TRACE_MISSED;
        }
        trace_batch_toward_scene(l, &b, m);
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
    const double a = 0.5 * rear->aperture_diameter_mm;
    const double z_near = rear->vertex_z_mm + fmin(0.0, lens_sag_mm(rear, a));
    if (!(z_near > 1e-3 * a))
        return 10.0 * (r + a) + fabs(pu->z_mm);
    return 1.5 * (r + (r + a) * fabs(pu->z_mm) / z_near);
}

/* Where the chief ray of film radius r crosses the pupil plane: inside the region unless a rim
   cuts it, however small the stop. */
static bool chief_crossing(const chief_lens *c, const pupil *pu, double r, double *x)
{
    double slope;
    const bool ok = chief_slope(c, r, &slope);
    *x = r + slope * pu->z_mm;
    return ok && isfinite(*x);
}

/* The same for one radius (a region far smaller than the scan's step is found there). */
static bool chief_point(const pupil *pu, const lens *l, double r, double *x)
{
    chief_lens c;
    if (chief_lens_open(&c, l))
        return false;
    const bool ok = chief_crossing(&c, pu, r, x);
    chief_lens_close(&c);
    return ok;
}

/* The chief ray's crossings out to film radius r (pupil.h), for stop-image. Where no chief ray
   gets through (beyond a fisheye's image circle) the table goes on along the line through the
   last two found; with fewer than two found there is none, and the nodes' centres alone give
   the centre. */
static void tabulate_chief(pupil *pu, const lens *l, double film_radius_mm)
{
    chief_lens c;
    pu->chief_spacing_mm = 0.0;
    if (pu->kind != PUPIL_STOP_IMAGE || chief_lens_open(&c, l))
        return;
    const double spacing = film_radius_mm / PUPIL_CHIEF_SAMPLES;
    int found = 0;
    while (found <= PUPIL_CHIEF_SAMPLES &&
           chief_crossing(&c, pu, found * spacing, &pu->chief_x_mm[found]))
        found++;
    chief_lens_close(&c);
    if (found < 2)
        return;
    for (int i = found; i <= PUPIL_CHIEF_SAMPLES; i++)
        pu->chief_x_mm[i] = 2.0 * pu->chief_x_mm[i - 1] - pu->chief_x_mm[i - 2];
    pu->chief_spacing_mm = spacing;
}

/* A passing point of the x axis: the guess, then points a quarter of size apart either side
   of it, then the chief ray's, then a scan of the whole useful segment (near the reach the
   region is a sliver that the search near the guess can miss). */
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
    if (chief_point(pu, l, r, x) && passes(pu, l, r, *x, 0.0))
        return true;
    const double half = search_half_side_mm(pu, l, r);
    for (int done = 0; done < SCAN; done += TRACE_BATCH_MAX) {
        double sx[TRACE_BATCH_MAX], sy[TRACE_BATCH_MAX] = {0};
        bool sp[TRACE_BATCH_MAX];
        for (int k = 0; k < TRACE_BATCH_MAX; k++)
            sx[k] = -half + 2.0 * half * (done + k + 0.5) / SCAN;
        trace_points(pu, l, r, sx, sy, TRACE_BATCH_MAX, sp);
        for (int k = 0; k < TRACE_BATCH_MAX; k++)
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
    g.middle_mm = middle;
    boundary(pu, l, r, middle, 0.0, dx, dy, DIRECTIONS + 1, 0.125 * (g.hi_mm - g.lo_mm), s);
    for (int k = 0; k <= DIRECTIONS; k++) {
        g.x_mm[k] = middle + s[k] * dx[k];
        g.y_mm[k] = s[k] * dy[k];
    }
    return g;
}

static double size_of(const pupil_shape *e)
{
    double size = 0.0;
    for (int i = 0; i <= PUPIL_KNOTS; i++)
        size = fmax(size, e->radius_mm[i]);
    return size;
}

static pupil_shape disk(double radius_mm)
{
    pupil_shape e = {.centre_mm = 0.0};
    for (int i = 0; i <= PUPIL_KNOTS; i++)
        e.radius_mm[i] = radius_mm;
    return e;
}

/* Raises knots i and i + 1 of e until the shape reaches distance rho at cos(phi) = cos_phi
   from its centre (the knots' segment holding cos_phi). */
static void reach_out(pupil_shape *e, double cos_phi, double rho)
{
    const double t = 0.5 * PUPIL_KNOTS * (1.0 - fmax(-1.0, fmin(1.0, cos_phi)));
    const int i = t < PUPIL_KNOTS - 1 ? (int)t : PUPIL_KNOTS - 1;
    const double short_by = rho - pupil_shape_radius_mm(e, cos_phi);
    if (short_by > 0.0) {
        e->radius_mm[i] += short_by;
        e->radius_mm[i + 1] += short_by;
    }
}

/* The shape of the pupil's kind that holds the region. stop-image: the star about the
   region's middle through its boundary, the radius taken linear in the angle between two
   boundary directions and sampled four times between them; rear: the disk about the axis
   holding the boundary and the rear rim. */
static pupil_shape fit_shape(const pupil *pu, const region *g)
{
    if (pu->kind == PUPIL_REAR) {
        double far = pu->radius_mm;
        for (int k = 0; k <= DIRECTIONS; k++)
            far = fmax(far, hypot(g->x_mm[k], g->y_mm[k]));
        return disk(far);
    }
    double rho[DIRECTIONS + 1];
    for (int k = 0; k <= DIRECTIONS; k++)
        rho[k] = hypot(g->x_mm[k] - g->middle_mm, g->y_mm[k]);
    pupil_shape e = {.centre_mm = g->middle_mm};
    for (int i = 0; i <= PUPIL_KNOTS; i++) {   /* first through the boundary at the knots */
        const double t = acos(1.0 - 2.0 * i / PUPIL_KNOTS) / M_PI * DIRECTIONS;
        const int k = t < DIRECTIONS ? (int)t : DIRECTIONS - 1;
        e.radius_mm[i] = rho[k] + (t - k) * (rho[k + 1] - rho[k]);
    }
    for (int k = 0; k < DIRECTIONS; k++)       /* then out to it between them */
        for (int q = 0; q <= 4; q++)
            reach_out(&e, cos(M_PI * (k + q / 4.0) / DIRECTIONS), rho[k] + q / 4.0 * (rho[k + 1] - rho[k]));
    return e;
}

/* How much shape e must grow about its centre to hold region g (at least 1). */
static double shortfall(const pupil_shape *e, const region *g)
{
    double worst = 1.0;
    for (int k = 0; k <= DIRECTIONS; k++) {
        const double dx = g->x_mm[k] - e->centre_mm, dy = g->y_mm[k];
        const double rho = hypot(dx, dy);
        if (rho > 0.0)
            worst = fmax(worst, rho / pupil_shape_radius_mm(e, dx / rho));
    }
    return worst;
}

static void grow(pupil_shape *e, double factor)
{
    for (int i = 0; i <= PUPIL_KNOTS; i++)
        e->radius_mm[i] *= factor;
}

/* The nodes' shapes where the region is found; found[j] says where. The guess for each node
   continues the two before it, or with the chief rays tabulated, the chief ray's crossing
   moved by the last node's offset from it. */
static void fit_nodes(pupil *pu, const lens *l, bool *found)
{
    const bool chief = pu->chief_spacing_mm > 0.0;
    double guess = 0.0, size = pu->radius_mm, offset = 0.0;
    for (int j = 0; j <= PUPIL_NODES; j++) {
        if (chief)
            guess = pupil_chief_at_node(pu, j) + offset;
        const region g = find_region(pu, l, j * pu->node_spacing_mm, guess, size);
        found[j] = g.found;
        if (!g.found)
            continue;
        pu->node[j] = fit_shape(pu, &g);
        if (j == 0)   /* on the axis the region is a disk about it */
            pu->node[0] = disk(size_of(&pu->node[0]));
        const double previous = j > 0 && found[j - 1] ? pu->node[j - 1].centre_mm : pu->node[j].centre_mm;
        guess = 2.0 * pu->node[j].centre_mm - previous;
        offset = pu->node[j].centre_mm - pupil_chief_at_node(pu, j);
        size = size_of(&pu->node[j]);
    }
}

/* The film radius beyond which nothing passes, when the last nodes find nothing: bisected
   between the last node that finds the region and the first that does not, and at least the
   radius where the search last found it. Fills the empty nodes with the last found shape,
   at the same offset from the chief ray's crossing (the centre between the last found node
   and the reach follows the chief ray, pupil.h);
   INFINITY when every node or none finds the region, or when one is found after a gap. */
static double find_reach(pupil *pu, const lens *l, const bool *found)
{
    int last = -1;
    for (int j = 0; j <= PUPIL_NODES; j++)
        if (found[j])
            last = j;
    for (int j = 1; j <= PUPIL_NODES; j++)
        if (!found[j]) {
            pu->node[j] = pu->node[j - 1];
            pu->node[j].centre_mm += pupil_chief_at_node(pu, j) - pupil_chief_at_node(pu, j - 1);
        }
    if (last < 0 || last == PUPIL_NODES)
        return INFINITY;
    for (int j = 0; j < last; j++)
        if (!found[j])
            return INFINITY;
    const pupil_shape *e = &pu->node[last];
    double in = last * pu->node_spacing_mm, out = in + pu->node_spacing_mm;
    for (int k = 0; k < 24; k++) {   /* to 6e-8 of the node spacing */
        const double mid = 0.5 * (in + out);
        if (find_region(pu, l, mid, e->centre_mm, size_of(e)).found)
            in = mid;
        else
            out = mid;
    }
    return out;
}

/* The growth of b alone that grows the shape interpolated at fraction f from a to b by at least
   factor at every knot: (1 - f) a + f g b >= factor ((1 - f) a + f b). */
static double far_growth(const pupil_shape *a, const pupil_shape *b, double factor, double f)
{
    double g = 1.0;
    for (int i = 0; i <= PUPIL_KNOTS; i++)
        g = fmax(g, 1.0 + (factor - 1.0) * ((1.0 - f) * a->radius_mm[i] + f * b->radius_mm[i]) /
                              (f * b->radius_mm[i]));
    return g;
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
            const region g = find_region(pu, l, r, e.centre_mm, size_of(&e));
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
        pu->node[j] = disk(pu->radius_mm);
    tabulate_chief(pu, l, film_radius_mm);
    fit_nodes(pu, l, found);
    pu->reach_mm = find_reach(pu, l, found);
    check_between(pu, l);
    for (int j = 0; j <= PUPIL_NODES; j++)
        grow(&pu->node[j], MARGIN);
}

/* Beyond the reach, lens l may still pass rays a little farther out: the reach is bisected
   again, out to the next node, when l passes rays at the old one. */
static void extend_reach(pupil *pu, const lens *l)
{
    if (!isfinite(pu->reach_mm))
        return;
    pupil_shape e;
    pupil_shape_at(pu, pu->reach_mm, &e);
    double in = pu->reach_mm, out = in + pu->node_spacing_mm;
    if (!find_region(pu, l, in, e.centre_mm, size_of(&e)).found)
        return;
    if (find_region(pu, l, out, e.centre_mm, size_of(&e)).found) {
        pu->reach_mm = INFINITY;   /* as find_reach does when the region outlives the search */
        return;
    }
    for (int k = 0; k < 24; k++) {
        const double mid = 0.5 * (in + out);
        *(find_region(pu, l, mid, e.centre_mm, size_of(&e)).found ? &in : &out) = mid;
    }
    pu->reach_mm = out;
}

void pupil_cover(pupil *pu, const lens *l)
{
    if (!pupil_is_fitted(pu))
        return;
    extend_reach(pu, l);
    for (int j = 0; j <= PUPIL_NODES; j++)
        for (int c = 0; c <= CHECKS && (c == 0 || j < PUPIL_NODES); c++) {
            const double r = (j + (double)c / (CHECKS + 1)) * pu->node_spacing_mm;
            pupil_shape e;
            if (!pupil_shape_at(pu, r, &e))
                continue;
            const region g = find_region(pu, l, r, e.centre_mm, size_of(&e));
            const double factor = g.found ? shortfall(&e, &g) : 1.0;
            if (factor <= 1.0)
                continue;
            grow(&pu->node[j], factor * MARGIN);
            if (c > 0)
                grow(&pu->node[j + 1], factor * MARGIN);
        }
}
