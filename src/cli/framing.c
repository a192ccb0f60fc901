#include "cli/framing.h"
#include "cli/lens_lookup.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include "camera/fieldangle.h"
#include "povray/scenecam.h"

/* trace --scene with POV-Ray's options (a library path, Declare=, an ini): the camera of the
   one frame they render; an animation has a camera a frame, which only render follows. */
static int camera_with_options(const cli *c, const char *scene, scene_camera *out,
                               l2p_error *err)
{
    scene_frames sf;
    int st = scene_frames_read(scene, c->cam.width, c->cam.height, c->povray_args,
                               c->povray_arg_count, &sf, err);
    if (st)
        return st;
    if (sf.count != 1)
        st = l2p_fail(err, L2P_BAD_INPUT, scene, 0, "POV-Ray's options make %d frames; trace "
                      "writes one camera: choose a frame (+SF and +EF), or render the animation",
                      sf.count);
    else
        *out = sf.frame[0].cam;
    scene_frames_free(&sf);
    return st;
}

int framing_from_scene(cli *c, const char *scene, l2p_error *err)
{
    if (c->placed && !c->angle_scene)
        return L2P_OK;
    scene_camera sc;
    const int st = c->povray_args ? camera_with_options(c, scene, &sc, err)
                                  : scene_camera_read(scene, c->cam.width, c->cam.height, &sc, err);
    if (!st) {
        framing_apply(c, &sc);
        framing_warn_perturbed(scene, sc.perturbed && !c->placed);
        framing_warn_unseen(scene, sc.computed_include);
    }
    return st;
}

void framing_warn_unseen(const char *scene, int line)
{
    if (line)
        fprintf(stderr, "lens2pov: warning: %s:%d: this #include names its file by an expression, "
                "in which lens2pov cannot see a camera statement: POV-Ray's default camera is "
                "taken (if the file holds the camera, give --location, --look-at and --angle)\n",
                scene, line);
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

/* The film half width, mm, at which the horizontal half field of f is half_deg:
   bisection between 0 and hi, where it is at least that. The field angle grows with the film
   radius up to the image circle and stays there. */
static double half_width_for(const field_angles *f, double half_deg, double hi)
{
    double lo = 0.0;
    for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; k++) {
        const double mid = 0.5 * (lo + hi);
        *(field_angles_half_deg(f, mid) < half_deg ? &lo : &hi) = mid;
    }
    return 0.5 * (lo + hi);
}

/* The field angle belongs to the lens and its focus, not to the film (camera/fieldangle.h): it is measured
   on a camera whose film reaches beyond anything the lens passes, where the pupil's reach is
   the image circle, and the film is then sized to it. */
static int solve_film(camera *cam, const lens *l, const cli *c, l2p_error *err)
{
    memset(cam, 0, sizeof *cam);   /* freeable on failure, as camera_setup leaves it */
    const double aspect = (double)c->cam.height / (double)c->cam.width;
    const double per_half_width = 2.0 * sqrt(1.0 + aspect * aspect);
    const double half_deg = 0.5 * c->angle_deg;
    double widest = 0.0;
    for (int i = 0; i < l->count; i++)
        widest = fmax(widest, l->surface[i].aperture_diameter_mm);
    /* Beyond a few times the widest element the lens passes nothing. */
    const double x = 4.0 * widest;
    camera wide;
    int st = setup_with_diagonal(&wide, l, c, per_half_width * x, err);
    if (st)
        return st;
    field_angles f;
    if (field_angles_open(&f, &wide)) {
        camera_free(&wide);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    const double most = field_angles_half_deg(&f, x);
    double half_width = NAN;
    if (!(most >= half_deg))
        st = l2p_fail(err, L2P_BAD_INPUT, l->path, 0,
                      "%s %g: this lens sees at most %.4g degrees across (at its focus in "
                      "effect)", c->angle_scene ? "the scene camera's angle" : "--angle",
                      c->angle_deg, 2.0 * most);
    else
        half_width = half_width_for(&f, half_deg, x);
    field_angles_close(&f);
    camera_free(&wide);
    return st ? st : setup_with_diagonal(cam, l, c, per_half_width * half_width, err);
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
