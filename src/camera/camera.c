#include "camera/camera.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "camera/spectral.h"
#include "optics/focus.h"
#include "optics/spectrum.h"
#include "optics/trace_batch.h"

void camera_options_default(camera_options *o)
{
    memset(o, 0, sizeof *o);
    o->width = 640;
    o->height = 480;
    o->spp = 16;
    o->film_diagonal_mm = 35.0;
    o->film_distance_mm = o->focus_distance_units = NAN;
    o->aperture_diameter_mm = o->f_number = NAN;
    o->wavelength_nm = NAN;
    o->pupil = PUPIL_STOP_IMAGE;
    o->trace = TRACE_KIND_FULL;
    o->location = v3(0, 0, 0);
    o->look_at = v3(0, 0, 1);
    o->sky = v3(0, 1, 0);
    o->unit_mm = 1000.0;
    o->weighting = WEIGHTING_NORMALIZED;
}

/* The largest component's size: a vector scaled by its inverse has a length between 1 and
   sqrt(3), whose square neither overflows nor underflows (a look-at point 1e155 away would). */
static double largest(vec3 v)
{
    return fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z)));
}

static int setup_placement(camera *c, const camera_options *o, l2p_error *err)
{
    const vec3 ahead = v3_sub(o->look_at, o->location);
    if (!(largest(ahead) > 0.0))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--look-at must differ from --location");
    if (!isfinite(largest(ahead)))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--look-at and --location are too far apart "
                        "for double precision");
    c->forward = v3_normalize(v3_scale(ahead, 1.0 / largest(ahead)));
    if (!(largest(o->sky) > 0.0) || !v3_isfinite(o->sky))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--sky must be a direction: not 0,0,0");
    const vec3 side = v3_cross(v3_scale(o->sky, 1.0 / largest(o->sky)), c->forward);
    if (!(v3_length(side) > 1e-12))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--sky must not be parallel to the viewing direction");
    c->right = v3_normalize(side);
    c->up = v3_cross(c->forward, c->right);
    if (o->mirror)
        c->right = v3_scale(c->right, -1.0);
    c->location = o->location;
    c->unit_mm = o->unit_mm;
    return L2P_OK;
}

vec3 camera_world_from_camera_offset(const camera *c, vec3 p)
{
    const vec3 m = v3_add(v3_add(v3_scale(c->right, p.x), v3_scale(c->up, p.y)),
                          v3_scale(c->forward, p.z));
    return v3_scale(m, 1.0 / c->unit_mm);
}

vec3 camera_world_from_camera_point(const camera *c, vec3 p)
{
    return v3_add(c->location, camera_world_from_camera_offset(c, p));
}

vec3 camera_world_from_camera_dir(const camera *c, vec3 d)
{
    return v3_normalize(v3_add(v3_add(v3_scale(c->right, d.x), v3_scale(c->up, d.y)),
                               v3_scale(c->forward, d.z)));
}

/* The stop opening for --aperture-diameter or --f-number (N = f / entrance pupil diameter;
   the entrance pupil scales with the stop). */
static int setup_aperture(lens *l, const camera_options *o, double efl_mm, l2p_error *err)
{
    const double full = l->surface[l->stop].aperture_diameter_mm;
    double diameter = full;
    if (!isnan(o->aperture_diameter_mm)) {
        diameter = o->aperture_diameter_mm;
    } else if (!isnan(o->f_number)) {
        double z, r;
        int st = pupil_stop_image(l, false, &z, &r, err);
        if (st)
            return st;
        const double magnification = 2.0 * r / l->stop_diameter_mm;
        /* The widest as the message prints it (4 digits) counts as the widest: a user who
           types back f/2.03 for 2.03015 gets the full opening. */
        char widest[32];
        snprintf(widest, sizeof widest, "%.4g", efl_mm / (full * magnification));
        if (o->f_number < strtod(widest, NULL))
            return l2p_fail(err, L2P_BAD_INPUT, l->path, l->surface[l->stop].line,
                            "--f-number %g is faster than the lens: its widest is f/%s",
                            o->f_number, widest);
        diameter = fmin(full, efl_mm / (o->f_number * magnification));
    }
    if (!(diameter > 0.0) || diameter > full * (1.0 + 1e-12))
        return l2p_fail(err, L2P_BAD_INPUT, l->path, l->surface[l->stop].line,
                        "aperture diameter %.9g mm is not in (0, %.9g], the stop's opening",
                        diameter, full);
    l->stop_diameter_mm = fmin(diameter, full);
    return L2P_OK;
}

/* The film must lie behind every surface's rim, and not so far that the table's absolute
   camera-space coordinates lose the rays' precision (trace-back error grows with the square of
   the film distance: 0.04 mm at 1e8 mm). */
static const double FILM_DISTANCE_MAX_RATIO = 1000.0;

static int check_film_position(const lens *l, bool from_option, double focus_mm, l2p_error *err)
{
    double size = lens_total_length_mm(l);
    for (int i = 0; i < l->count; i++) {
        const lens_surface *s = &l->surface[i];
        size = fmax(size, s->aperture_diameter_mm);
        const double lowest = s->vertex_z_mm + fmin(0.0, lens_sag_mm(s, 0.5 * s->aperture_diameter_mm));
        if (lowest < 0.0)
            return l2p_fail(err, L2P_BAD_INPUT, l->path, s->line,
                            "the film (%g mm behind the rear vertex) is inside the lens: the rim "
                            "of this surface reaches %g mm behind it", l->film_distance_mm, -lowest);
    }
    if (l->film_distance_mm <= FILM_DISTANCE_MAX_RATIO * size)
        return L2P_OK;
    if (from_option)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--film-distance %g mm is too far from the lens: %.3g times its size, at "
                        "most %g", l->film_distance_mm, l->film_distance_mm / size,
                        FILM_DISTANCE_MAX_RATIO);
    char focus[48];
    snprintf(focus, sizeof focus, isinf(focus_mm) ? "at infinity" : "at %g mm", focus_mm);
    return l2p_fail(err, L2P_BAD_INPUT, l->path, l->surface[0].line,
                    "focusing %s puts the film %g mm behind the lens, too far from it (%.3g "
                    "times its size, at most %g): the lens is nearly afocal", focus,
                    l->film_distance_mm, l->film_distance_mm / size, FILM_DISTANCE_MAX_RATIO);
}

static int setup_focus(camera *c, const camera_options *o, l2p_error *err)
{
    lens *l = &c->lens;
    if (!isnan(o->film_distance_mm)) {
        if (!(o->film_distance_mm >= 0.0))
            return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--film-distance must be >= 0");
        lens_set_film_distance(l, o->film_distance_mm);
    } else {
        double units = o->focus_distance_units;
        if (isnan(units))
            units = v3_length(v3_sub(o->look_at, o->location));
        if (!(units > 0.0))
            return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--focus-distance must be positive");
        int st = focus_set(l, units * o->unit_mm, o->unit_mm, isnan(o->focus_distance_units), err);
        if (!st)
            st = check_film_position(l, false, units * o->unit_mm, err);
        if (st)
            return st;
    }
    if (!isnan(o->film_distance_mm)) {
        int st = check_film_position(l, true, NAN, err);
        if (st)
            return st;
        c->focus_distance_units = focus_distance_mm(l) / o->unit_mm;
    } else {
        /* the distance focused at, not one computed back from the film: at infinity that is a
           division by the rounding error of the film's place, a huge number of either sign */
        c->focus_distance_units = isnan(o->focus_distance_units) ? v3_length(v3_sub(o->look_at, o->location))
                                                                 : o->focus_distance_units;
    }
    return L2P_OK;
}

/* The mean weight at the film centre at wavelength nm, blocked rays counting 0. The rays from
   the axial point that get through form a cone (rotational symmetry) of half-angle theta_max,
   and the mean of A cos^4 / Z^2 over any disk that holds it is then exactly pi sin^2(theta_max),
   the cone's projected solid angle:
   (1/A) int_0^rho (A Z^2 / (Z^2 + r^2)^2) 2 pi r dr = pi rho^2 / (Z^2 + rho^2). The cone's edge
   is bisected along a radius of the disk sampled at nm (u in [0.5, 1] maps to radius 2u - 1).
   A grid over the disk converges only like 1/N, and not monotonically (2% off at 48 x 48). */
static double centre_mean_weight_at(const camera *c, double nm)
{
    const vec3 centre = v3(0, 0, 0);
    ray r;
    double w, in = 0.0, out = 1.0;
    if (!camera_trace_at(c, centre, 0.5, 0.5, nm, &r, &w))
        return 0.0;
    if (camera_trace_at(c, centre, 1.0, 0.5, nm, &r, &w))
        in = 1.0;
    for (int k = 0; k < 60 && in < 1.0; k++) {
        const double mid = 0.5 * (in + out);
        if (camera_trace_at(c, centre, 0.5 + 0.5 * mid, 0.5, nm, &r, &w))
            in = mid;
        else
            out = mid;
    }
    const pupil *pu = camera_pupil_at(c, nm);   /* the pupil camera_trace_at draws from */
    pupil_shape disk;
    if (!pupil_shape_at(pu, 0.0, &disk))
        return 0.0;
    const double rho = in * disk.radius_mm[0], z = pu->z_mm;
    return M_PI * rho * rho / (z * z + rho * rho);
}

/* The mean weight at the film centre: the scale that makes it 1 makes the centre as bright as
   a pinhole camera. With dispersion the cone changes with the wavelength (the pupil's image
   moves and grows with the index), and the mean is over the wavelengths as they are sampled,
   lambda = P^-1(u) for u uniform (spectrum.h), by the midpoint rule in u. */
static double centre_mean_weight(const camera *c)
{
    if (!c->dispersion)
        return centre_mean_weight_at(c, WAVELENGTH_D_NM);
    enum { STEPS = 128 };
    double sum = 0.0;
    for (int i = 0; i < STEPS; i++)
        sum += centre_mean_weight_at(c, spectrum_wavelength_nm((i + 0.5) / STEPS));
    return sum / STEPS;
}

static int setup_weights(camera *c, weighting w, l2p_error *err)
{
    c->weighting = w;
    c->weight_scale = 1.0;
    const double mean = centre_mean_weight(c);
    c->centre_cone_sin2 = mean > 0.0 ? mean / M_PI : 0.0;
    if (w == WEIGHTING_PHYSICAL)
        return L2P_OK;
    if (!(mean > 0.0))
        return l2p_fail(err, L2P_BAD_INPUT, c->lens.path, c->lens.surface[c->lens.stop].line,
                        "with this stop, the lens blocks every ray at the film centre: nothing "
                        "to normalize against (use --weighting physical)");
    c->weight_scale = 1.0 / mean;
    return L2P_OK;
}

static int setup_film(camera *c, const camera_options *o, l2p_error *err)
{
    if (o->width <= 0 || o->height <= 0 || o->spp <= 0)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--width, --height and --spp must be positive");
    if (!(o->film_diagonal_mm > 0.0) || !isfinite(o->film_diagonal_mm))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--film-diagonal must be positive");
    if (!(o->unit_mm > 0.0) || !isfinite(o->unit_mm))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--unit-mm must be positive");
    film_init(&c->film, o->width, o->height, o->film_diagonal_mm);
    sample_pattern_init(&c->samples, o->spp, o->seed);
    c->crop_x0 = o->crop_x0;
    c->crop_y0 = o->crop_y0;
    c->crop_x1 = o->crop_x1 ? o->crop_x1 : o->width;
    c->crop_y1 = o->crop_y1 ? o->crop_y1 : o->height;
    if (c->crop_x0 < 0 || c->crop_y0 < 0 || c->crop_x1 > o->width || c->crop_y1 > o->height ||
        c->crop_x0 >= c->crop_x1 || c->crop_y0 >= c->crop_y1)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--crop %d,%d,%d,%d is not a region of the %dx%d film (X0,Y0 inclusive, "
                        "X1,Y1 exclusive)", c->crop_x0, c->crop_y0, c->crop_x1, c->crop_y1,
                        o->width, o->height);
    return L2P_OK;
}

static int setup_dispersion(camera *c, const camera_options *o, l2p_error *err)
{
    c->glass = lens_has_abbe(&c->lens);
    if (!isnan(o->wavelength_nm)) {
        if (o->dispersion == DISPERSION_ON)
            return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--wavelength traces one wavelength, "
                            "--dispersion on many: give one");
        lens_at_wavelength(&c->lens, o->wavelength_nm);
    }
    const bool glass = lens_has_abbe(&c->lens);
    c->dispersion = o->dispersion == DISPERSION_ON ||
                    (o->dispersion == DISPERSION_AUTO && glass && o->trace == TRACE_KIND_FULL);
    if (c->dispersion && !glass)
        return l2p_fail(err, L2P_BAD_INPUT, c->lens.path, 0, "--dispersion on needs the Abbe "
                        "numbers of the glasses (a fifth column): this lens gives none");
    if (c->dispersion && o->trace == TRACE_KIND_THICK)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--dispersion on needs --trace full: the "
                        "thick lens is one fit, at the d line");
    return L2P_OK;
}

int camera_setup(camera *c, lens *l, const camera_options *o, l2p_error *err)
{
    memset(c, 0, sizeof *c);
    c->lens = *l;
    memset(l, 0, sizeof *l);
    c->trace = o->trace;
    int st = setup_film(c, o, err);
    if (!st)
        st = setup_placement(c, o, err);
    if (!st)
        st = setup_dispersion(c, o, err);
    /* The cardinal points are probed, and the focus found, by rays at a fixed fraction of the
       smallest opening, the stop's included: the opening is chosen with the full stop's focal
       length, and the points that the camera keeps are found again at the chosen opening and
       film distance. */
    if (!st)
        st = thick_lens_of(&c->lens, 0, c->lens.count - 1, &c->thick, err);
    if (!st)
        st = setup_aperture(&c->lens, o, thick_efl_mm(&c->thick), err);
    if (!st)
        st = setup_focus(c, o, err);
    if (!st)
        st = thick_lens_of(&c->lens, 0, c->lens.count - 1, &c->thick, err);
    /* A thick lens has no rear element: its rear pupil is the stop's image too, the one
       aperture a thick lens has (trace_thick), seen whole from every film point. */
    const pupil_kind kind =
        o->trace == TRACE_KIND_THICK && o->pupil == PUPIL_REAR ? PUPIL_STOP_IMAGE : o->pupil;
    if (!st)
        st = pupil_make(&c->lens, kind, &c->pupil, err);
    /* The stop pupil stays the seed's diagnostic, and thick tracing samples the stop's image,
       as the seed's third variant does: a thick lens blocks nothing. */
    if (!st && o->pupil != PUPIL_STOP && o->trace == TRACE_KIND_FULL) {
        pupil_fit(&c->pupil, &c->lens, 0.5 * c->film.diagonal_mm);
        if (c->dispersion)
            st = camera_cover_spectrum(c, err);
    }
    if (!st) {
        double z, r;
        st = pupil_stop_image(&c->lens, false, &z, &r, err);
        c->f_number = thick_efl_mm(&c->thick) / (2.0 * r);
    }
    if (!st && c->trace == TRACE_KIND_THICK)
        st = pupil_stop_image(&c->lens, true, &c->thick_exit_z_mm, &c->thick_exit_radius_mm, err);
    if (!st)
        st = setup_weights(c, o->weighting, err);
    /* The blades last: a polygon inscribed in the opening passes a subset of the round stop's
       rays, so the pupil fitted to the round stop covers every ray they pass (the fit assumes
       a lens symmetric about its axis, which blades are not), and the normalized weights keep
       the round opening's scale: blades darken the picture by the polygon's share of the
       circle, as they do a real lens at the same f-number. */
    if (!st && o->aperture_blades && o->trace == TRACE_KIND_THICK)
        st = l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--aperture-blades needs --trace full: thick-lens "
                      "tracing passes every ray its sampled disk gives and has no stop to shape");
    if (!st)
        lens_set_blades(&c->lens, o->aperture_blades, o->blade_rotation_deg * (M_PI / 180.0));
    return st;
}

void camera_free(camera *c)
{
    lens_free(&c->lens);
    free(c->spectral);
    memset(c, 0, sizeof *c);
}

/* Thick tracing leaves the ray on P1; start it where a real lens's rays start, on the plane of
   the front vertex, so both kinds of trace see the same scene in front of the lens. */
static bool trace_thick(const camera *c, ray *r)
{
    /* The thick lens's one aperture is the stop's image: a ray it would not pass is blocked
       whatever pupil sampled it (the rear pupil's disk is larger, the stop's elsewhere). The
       stop-image pupil samples that disk itself; 1e-9 keeps its rim. */
    const double t = (c->thick_exit_z_mm - r->o.z) / r->d.z;
    const vec3 at = v3_madd(r->o, r->d, t);
    if (!(r->d.z > 0.0) || !(hypot(at.x, at.y) <= c->thick_exit_radius_mm * (1.0 + 1e-9)))
        return false;
    if (!thick_trace_toward_scene(&c->thick, r))
        return false;
    const double to_front = (c->lens.surface[0].vertex_z_mm - r->o.z) / r->d.z;
    r->o = v3_madd(r->o, r->d, to_front);
    return v3_isfinite(r->o);
}

static void batch_from_rays(trace_batch *b, const vec3 *origin, const vec3 *direction, int n)
{
    for (int k = 0; k < n; k++) {
        b->ox[k] = origin[k].x; b->oy[k] = origin[k].y; b->oz[k] = origin[k].z;
        b->dx[k] = direction[k].x; b->dy[k] = direction[k].y; b->dz[k] = direction[k].z;
    }
}

static void rays_from_batch(ray *r, const trace_batch *b, int n)
{
    for (int k = 0; k < n; k++) {
        r[k].o = v3(b->ox[k], b->oy[k], b->oz[k]);
        r[k].d = v3(b->dx[k], b->dy[k], b->dz[k]);
    }
}

void camera_film_rays(const camera *c, sample_batch *s, vec3 *direction)
{
    const int n = s->n;
    /* runs of samples drawn from one pupil (with dispersion, of wavelengths near one another) */
    for (int k = 0, end; k < n; k = end) {
        const pupil *pu = c->dispersion ? camera_pupil_at(c, s->wavelength_nm[k]) : &c->pupil;
        end = k + 1;
        while (end < n && (!c->dispersion || camera_pupil_at(c, s->wavelength_nm[end]) == pu))
            end++;
        pupil_film_rays(pu, end - k, s->film_point + k, s->u + k, s->v + k, direction + k, s->weight + k);
    }
    for (int k = 0; k < n; k++)
        s->weight[k] *= c->weight_scale;
}

void camera_trace_batch(const camera *c, sample_batch *s)
{
    const int n = s->n;
    trace_batch b;
    vec3 direction[CAMERA_BATCH];
    camera_film_rays(c, s, direction);
    for (int k = 0; k < n; k++)
        b.status[k] = s->weight[k] > 0.0 && isfinite(s->weight[k]) && v3_isfinite(direction[k])
                          ? TRACE_PASSED : TRACE_MISSED;
    if (c->trace == TRACE_KIND_THICK) {
        for (int k = 0; k < n; k++) {
            s->out[k].o = s->film_point[k];
            s->out[k].d = direction[k];
            if (b.status[k] == TRACE_PASSED && !trace_thick(c, &s->out[k]))
                b.status[k] = TRACE_MISSED;
        }
    } else {
        batch_from_rays(&b, s->film_point, direction, n);
        trace_batch_toward_scene_at(&c->lens, &b, n, c->dispersion ? s->wavelength_nm : NULL);
        rays_from_batch(s->out, &b, n);
    }
    /* & rather than &&: whether a ray passed is unpredictable, a branch on it costly. */
    for (int k = 0; k < n; k++)
        s->passed[k] = (b.status[k] == TRACE_PASSED) & v3_isfinite(s->out[k].o) &
                       v3_isfinite(s->out[k].d);
}

bool camera_trace(const camera *c, vec3 film_point, double u, double v, ray *out, double *weight)
{
    return camera_trace_at(c, film_point, u, v, WAVELENGTH_D_NM, out, weight);
}

bool camera_trace_at(const camera *c, vec3 film_point, double u, double v, double nm, ray *out,
                     double *weight)
{
    sample_batch s;
    s.n = 1;
    s.film_point[0] = film_point;
    s.u[0] = u;
    s.v[0] = v;
    s.wavelength_nm[0] = nm;
    camera_trace_batch(c, &s);
    *out = s.out[0];
    *weight = s.weight[0];
    return s.passed[0];
}

double camera_pass_share(const camera *c)
{
    enum { ACROSS = 16, SPP = 64 };   /* film points a side; samples at each */
    sample_pattern pattern;
    sample_pattern_init(&pattern, SPP, 0x9e3779b97f4a7c15u);
    long long reached = 0, passed = 0;
    sample_batch b;
    b.n = 0;
    for (int i = 0; i < ACROSS * ACROSS * SPP; i++) {
        const int fx = i % ACROSS, fy = i / ACROSS % ACROSS, k = i / (ACROSS * ACROSS);
        const double rx = c->crop_x0 + (fx + 0.5) / ACROSS * (c->crop_x1 - c->crop_x0);
        const double ry = c->crop_y0 + (fy + 0.5) / ACROSS * (c->crop_y1 - c->crop_y0);
        const sample_pixel pixel = sample_pattern_pixel(&pattern, fx, fy);
        const film_sample f = sample_pattern_sample(&pattern, pixel, k);
        b.film_point[b.n] = film_camera_from_raster(&c->film, rx, ry);
        b.u[b.n] = f.pupil_u;
        b.v[b.n] = f.pupil_v;
        b.wavelength_nm[b.n] = sample_pattern_wavelength(&pattern, pixel, k).nm;
        if (++b.n == CAMERA_BATCH || i + 1 == ACROSS * ACROSS * SPP) {
            camera_trace_batch(c, &b);
            for (int j = 0; j < b.n; j++) {
                reached += pupil_reaches(camera_pupil_at(c, b.wavelength_nm[j]), b.film_point[j]);
                passed += b.passed[j];
            }
            b.n = 0;
        }
    }
    return reached ? (double)passed / (double)reached : NAN;
}
