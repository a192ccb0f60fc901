/* Growing a pupil's disk, ring by ring of film radius, until it covers every ray the lens
   passes (see pupil_cover in pupil.h). */
#include "pupil.h"
#include "trace.h"

enum {
    GRID = 24,         /* coarse search of the pupil plane, per side */
    DIRECTIONS = 64,   /* boundary bisections around the passing region */
    BISECTIONS = 30    /* each halves the bracket: 2^-30 of a grid cell */
};

/* Relative margin on the radius found: the rings are sampled at three film radii each. */
static const double MARGIN = 1.01;

static bool passes(const pupil *pu, const lens *l, vec3 p, double x, double y)
{
    ray r = {p, pupil_direction(pu, p, x, y)};
    return v3_isfinite(r.d) && trace_toward_scene(l, 0, l->count - 1, &r, NULL) == TRACE_PASSED;
}

/* Half-side of a square of the pupil plane that holds every useful point for film point p:
   a ray that gets through crosses the rear surface within its aperture a, no nearer to the
   film than z_near, so by similar triangles it meets the plane z = Z within
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

/* Distance t along (cx, cy) + t (ux, uy) where rays stop getting through, from a passing
   start: march out a cell at a time, then bisect. */
static double boundary(const pupil *pu, const lens *l, vec3 p, double cx, double cy, double ux,
                       double uy, double cell, double limit)
{
    double in = 0.0, out = cell;
    while (out < limit && passes(pu, l, p, cx + out * ux, cy + out * uy)) {
        in = out;
        out += cell;
    }
    for (int k = 0; k < BISECTIONS; k++) {
        const double mid = 0.5 * (in + out);
        if (passes(pu, l, p, cx + mid * ux, cy + mid * uy))
            in = mid;
        else
            out = mid;
    }
    return in;
}

/* Farthest distance from the axis of a pupil-plane point through which a ray from film point
   (r, 0, 0) gets through; 0 when none does. A coarse grid finds the passing region; its
   boundary is then bisected in DIRECTIONS directions from the passing grid point nearest its
   centroid (the region, an intersection of the apertures' images, is star-shaped there). */
static double reach_mm(const pupil *pu, const lens *l, double r)
{
    const vec3 p = v3(r, 0, 0);
    const double half = search_half_side_mm(pu, l, r), cell = 2.0 * half / GRID;
    double sx = 0, sy = 0, reach = 0, gx[GRID * GRID], gy[GRID * GRID];
    int n = 0;
    for (int j = 0; j < GRID; j++)
        for (int i = 0; i < GRID; i++) {
            const double x = -half + (i + 0.5) * cell, y = -half + (j + 0.5) * cell;
            if (!passes(pu, l, p, x, y))
                continue;
            gx[n] = x;
            gy[n++] = y;
            sx += x;
            sy += y;
            reach = fmax(reach, hypot(x, y));
        }
    if (n == 0)
        return 0.0;
    int start = 0;
    for (int k = 1; k < n; k++)
        if (hypot(gx[k] - sx / n, gy[k] - sy / n) < hypot(gx[start] - sx / n, gy[start] - sy / n))
            start = k;
    for (int k = 0; k < DIRECTIONS; k++) {
        const double phi = 2.0 * M_PI * k / DIRECTIONS, ux = cos(phi), uy = sin(phi);
        const double t = boundary(pu, l, p, gx[start], gy[start], ux, uy, cell, 4.0 * half);
        reach = fmax(reach, hypot(gx[start] + t * ux, gy[start] + t * uy));
    }
    return reach;
}

void pupil_cover(pupil *pu, const lens *l, double film_radius_mm)
{
    pu->ring_width_mm = film_radius_mm / PUPIL_RINGS;
    double inner = reach_mm(pu, l, 0.0);
    for (int i = 0; i < PUPIL_RINGS; i++) {
        const double middle = reach_mm(pu, l, (i + 0.5) * pu->ring_width_mm);
        const double outer = reach_mm(pu, l, (i + 1) * pu->ring_width_mm);
        const double need = MARGIN * fmax(inner, fmax(middle, outer));
        pu->ring_radius_mm[i] = fmax(pu->radius_mm, need);
        inner = outer;
    }
}
