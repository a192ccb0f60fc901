#include "cli/framing.h"
#include "cli/lens_lookup.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include "cli/info.h"
#include "povray/scenecam.h"

int framing_from_scene(cli *c, const char *scene, l2p_error *err)
{
    if (c->placed && !c->angle_scene)
        return L2P_OK;
    scene_camera sc;
    const int st = scene_camera_read(scene, c->cam.width, c->cam.height, &sc, err);
    if (!st) {
        framing_apply(c, &sc);
        framing_warn_perturbed(scene, sc.perturbed && !c->placed);
    }
    return st;
}

void framing_warn_perturbed(const char *scene, bool perturbed)
{
    if (perturbed)
        fprintf(stderr, "lens2pov: warning: %s: the camera's normal { } is left out: a lens does "
                "not perturb its rays\n", scene);
}

void framing_apply(cli *c, const scene_camera *s)
{
    const scene_camera sc = *s;
    if (!c->placed) {
        /* The look-at point on the axis at the focus distance: camera_setup's default focus. */
        c->cam.location = sc.location;
        c->cam.look_at = v3_madd(sc.location, sc.forward, sc.focus_distance);
        c->cam.sky = sc.up;
        c->cam.mirror = sc.mirrored;
    }
    if (c->angle_scene)
        c->angle_deg = sc.hfov_deg;
}

/* The film half width, mm, at which the horizontal half field of cam is half_deg: bisection
   between 0 and hi, where the field is at least that. */
static double half_width_for(const camera *cam, double half_deg, double hi)
{
    double lo = 0.0;
    for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; k++) {
        const double mid = 0.5 * (lo + hi);
        *(info_half_field_deg(cam, v3(mid, 0, 0)) < half_deg ? &lo : &hi) = mid;
    }
    return 0.5 * (lo + hi);
}

static int setup_with_diagonal(camera *cam, const lens *l, const cli *c, double diagonal_mm,
                               l2p_error *err)
{
    lens copy;
    if (lens_copy(&copy, l))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    camera_options o = c->cam;
    o.film_diagonal_mm = diagonal_mm;
    const int st = camera_setup(cam, &copy, &o, err);
    if (st)
        camera_free(cam);
    return st;
}

/* The pupil region is fitted up to the film's corner, so the chief rays, and the field, move a
   little with the film's size: the film is sized again on each camera until it settles. */
static int solve_film(camera *cam, const lens *l, const cli *c, l2p_error *err)
{
    const double aspect = (double)c->cam.height / (double)c->cam.width;
    const double per_half_width = 2.0 * sqrt(1.0 + aspect * aspect);
    const double half_deg = 0.5 * c->angle_deg;
    double widest = 0.0;
    for (int i = 0; i < l->count; i++)
        widest = fmax(widest, l->surface[i].aperture_diameter_mm);
    /* Beyond a few times the widest element the lens passes nothing: the field is its
       image circle's there. */
    double x = 4.0 * widest;
    int st = setup_with_diagonal(cam, l, c, per_half_width * x, err);
    if (st)
        return st;
    const double most = info_half_field_deg(cam, v3(x, 0, 0));
    if (!(most >= half_deg)) {
        camera_free(cam);
        return l2p_fail(err, L2P_BAD_INPUT, l->path, 0,
                        "--angle %g: this lens sees at most %.4g degrees across (at its focus "
                        "in effect)", c->angle_deg, 2.0 * most);
    }
    for (int round = 0; round < 8; round++) {
        const double next = half_width_for(cam, half_deg, round ? 2.0 * x : x);
        camera_free(cam);
        st = setup_with_diagonal(cam, l, c, per_half_width * next, err);
        if (st)
            return st;
        const bool settled = fabs(next - x) <= 1e-12 * x;
        x = next;
        if (settled)
            break;
    }
    return L2P_OK;
}

int framing_camera_setup(camera *cam, lens *l, const cli *c, l2p_error *err)
{
    if (c->angle_scene && isnan(c->angle_deg)) {
        lens_free(l);
        memset(cam, 0, sizeof *cam);
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--angle scene needs a scene: render SCENE LENS, or trace --scene SCENE");
    }
    if (isnan(c->angle_deg)) {
        const int st = camera_setup(cam, l, &c->cam, err);
        if (st)
            camera_free(cam);
        return st;
    }
    const int st = solve_film(cam, l, c, err);
    lens_free(l);
    return st;
}

int framing_load_camera(const cli *c, const char *lens_name, camera *cam, l2p_error *err)
{
    lens l;
    int st = lens_read_named(lens_name, &l, err);
    if (st)
        return st;
    st = framing_camera_setup(cam, &l, c, err);
    if (st)
        camera_free(cam);
    return st;
}
