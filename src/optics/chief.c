/* The chief ray (chief.h): its slope at the film found by Newton's method on where it crosses
   the stop's plane, from the paraxial aim or else from a bracket of a scan. */
#include "optics/chief.h"

#include <math.h>
#include <string.h>
#include "optics/pupil.h"

/* Far beyond any lens, in mm: rims this wide never cut a ray. */
#define OPEN_DIAMETER_MM 1e9
/* Where the chief ray crosses the stop's plane, at most this far from its centre, mm. */
#define AIM_MM 1e-11
/* The scan for a bracket: slopes -SCAN_SLOPE .. SCAN_SLOPE (about 84 degrees) in SCAN_STEPS. */
#define SCAN_SLOPE 10.0
#define SCAN_STEPS 400

int chief_lens_open(chief_lens *c, const lens *l)
{
    double z, radius;
    c->aim_z_mm = pupil_stop_image(l, true, &z, &radius, NULL) == L2P_OK && fabs(z) > 1e-9 ? z : NAN;
    if (lens_copy(&c->open, l))
        return L2P_FAILED;
    for (int i = 0; i < c->open.count; i++)
        c->open.surface[i].aperture_diameter_mm = OPEN_DIAMETER_MM;
    c->open.stop_diameter_mm = OPEN_DIAMETER_MM;
    lens_set_blades(&c->open, 0, 0.0);
    return L2P_OK;
}

void chief_lens_close(chief_lens *c)
{
    lens_free(&c->open);
}

/* The ray from film point (r, 0, 0) with slope dx/dz = t. */
static ray from_film(double r, double t)
{
    ray y = {v3(r, 0, 0), v3_normalize(v3(t, 0, 1))};
    return y;
}

/* Where the ray of slope t crosses the stop's plane, x in mm, having crossed the surfaces
   between the film and the stop; false when it does not get there. */
static bool stop_height(const lens *open, double r, double t, double *x_mm)
{
    ray y = from_film(r, t);
    if (open->stop < open->count - 1 &&
        trace_toward_scene(open, open->stop + 1, open->count - 1, &y, NULL) != TRACE_PASSED)
        return false;
    if (!(y.d.z > 0))
        return false;
    *x_mm = y.o.x + (open->surface[open->stop].vertex_z_mm - y.o.z) / y.d.z * y.d.x;
    return isfinite(*x_mm);
}

/* Newton's method from slope *t toward the crossing at height target_mm, the derivative by a
   forward difference; a step that leaves the lens is halved until it does not. */
static bool newton_to(const lens *open, double r, double target_mm, double *t)
{
    double h;
    if (!stop_height(open, r, *t, &h))
        return false;
    h -= target_mm;
    for (int k = 0; k < 60 && fabs(h) > AIM_MM; k++) {
        const double dt = 1e-7 * (1.0 + fabs(*t));
        double h2, next = NAN, step;
        if (!stop_height(open, r, *t + dt, &h2) || !(h2 - target_mm != h))
            return false;
        step = -h * dt / (h2 - target_mm - h);
        int halvings = 0;
        while (!stop_height(open, r, *t + step, &next) && ++halvings < 40)
            step *= 0.5;
        if (halvings == 40)
            return false;
        *t += step;
        h = next - target_mm;
    }
    return fabs(h) <= AIM_MM;
}

static bool newton(const lens *open, double r, double *t)
{
    return newton_to(open, r, 0.0, t);
}

/* A start for newton() when the paraxial aim fails: of the slopes between which the crossing
   changes side, both passing, the pair nearest the paraxial aim t0. */
static bool bracket(const lens *open, double r, double t0, double *t)
{
    double best = INFINITY, prev_t = NAN, prev_h = NAN;
    for (int k = 0; k <= SCAN_STEPS; k++) {
        const double s = -SCAN_SLOPE + 2.0 * SCAN_SLOPE * k / SCAN_STEPS;
        double h;
        if (!stop_height(open, r, s, &h)) {
            prev_t = NAN;
            continue;
        }
        if (!isnan(prev_t) && (h <= 0) != (prev_h <= 0)) {
            const double mid = prev_t - prev_h * (s - prev_t) / (h - prev_h);
            if (fabs(mid - t0) < fabs(best - t0))
                best = mid;
        }
        prev_t = s, prev_h = h;
    }
    *t = best;
    return isfinite(best);
}

bool chief_slope(const chief_lens *c, double film_radius_mm, double *slope)
{
    const double r = film_radius_mm;
    /* toward the middle of the paraxial exit pupil (behind the film when it is virtual), or
       parallel to the axis when the pupil is at infinity (telecentric) */
    const double t0 = r > 0 && isfinite(c->aim_z_mm) ? -r / c->aim_z_mm : 0.0;
    *slope = t0;
    return newton(&c->open, r, slope) ||
           (bracket(&c->open, r, t0, slope) && newton(&c->open, r, slope));
}

bool chief_ray(const chief_lens *c, double film_radius_mm, ray *out)
{
    double t;
    if (!chief_slope(c, film_radius_mm, &t))
        return false;
    ray y = from_film(film_radius_mm, t);
    if (trace_toward_scene(&c->open, 0, c->open.count - 1, &y, NULL) != TRACE_PASSED)
        return false;
    *out = y;
    return true;
}

bool chief_angle(const chief_lens *c, double film_radius_mm, double *theta_rad)
{
    ray y;
    if (!chief_ray(c, film_radius_mm, &y))
        return false;
    *theta_rad = atan2(hypot(y.d.x, y.d.y), y.d.z);
    return true;
}

/* Whether the ray from the film's centre toward height h_mm of the stop's plane gets through
   l; *blocked the surface that stops it. From slope *t, left at the aimed slope. */
static bool axial_passes(const chief_lens *c, const lens *l, double h_mm, double *t, int *blocked)
{
    *blocked = -1;   /* none known: no ray from the centre gets to that height at all */
    if (!newton_to(&c->open, 0.0, h_mm, t))
        return false;
    ray y = from_film(0.0, *t);
    return trace_toward_scene(l, 0, l->count - 1, &y, blocked) == TRACE_PASSED;
}

int chief_axial_limit(const chief_lens *c, const lens *l, double *passing)
{
    /* aimed first at the stop's paraxial image's rim (a start on the right side of the lens's
       fold), then at the stop's rim a hair inside it; bisected between the axis and there */
    const double rim_mm = 0.999 * 0.5 * l->stop_diameter_mm;
    double z, radius, t;
    int blocked;
    *passing = 1.0;
    if (pupil_stop_image(l, true, &z, &radius, NULL) != L2P_OK || !(fabs(z) > 1e-9))
        return -1;
    t = 0.999 * radius / z;
    const double t_rim = t;
    if (axial_passes(c, l, rim_mm, &t, &blocked))
        return l->stop;
    int limit = blocked;   /* the rim that cuts the ray just outside the passing cone */
    double in = 0.0, out = 1.0;
    for (int k = 0; k < 30; k++) {
        const double mid = 0.5 * (in + out);
        t = t_rim * mid;
        if (axial_passes(c, l, mid * rim_mm, &t, &blocked))
            in = mid;
        else if ((out = mid), blocked >= 0)
            limit = blocked;
    }
    *passing = in;
    return limit;
}
