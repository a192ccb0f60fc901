/* The warnings every command gives once its camera is set up (cli.h): what the options or
   the lens make of the picture that the user may not expect. */
#include "cli/cli.h"

#include <math.h>
#include <stdio.h>
#include "cli/info.h"
#include "optics/chief.h"

void cli_warn_wavelength(const cli *c, const char *lens_path, bool glass)
{
    if (!isnan(c->cam.wavelength_nm) && !glass)
        fprintf(stderr, "lens2pov: warning: %s gives no Abbe numbers, so its indices are the same "
                        "at every wavelength: --wavelength %g changes nothing\n", lens_path,
                c->cam.wavelength_nm);
}

/* A picture whose samples the lens mostly blocks is black or noisy, whatever the scene: said
   before the work, with what would help. */
static void warn_pass_share(const cli *c, const camera *cam)
{
    const double share = camera_pass_share(cam);   /* NAN: no film point probed is reached */
    if (share >= 0.01)
        return;
    const char *why =
        c->cam.pupil == PUPIL_REAR ? "--pupil rear samples the rear element's whole rim; "
                                     "stop-image samples where the light passes"
        : cam->dispersion ? "through a stop this small the light's place in the pupil moves with "
                            "the wavelength by more than its size; --dispersion off samples one "
                            "place, or open the stop"
                          : "open the stop";
    if (!(share > 0.0))
        fprintf(stderr, "lens2pov: warning: no sample of a probe over the film gets through the "
                        "lens: the picture will be black (%s)\n", why);
    else
        fprintf(stderr, "lens2pov: warning: only %.2g%% of the samples get through the lens: the "
                        "picture will be noisy for its --spp (%s)\n", 100.0 * share, why);
}

/* A rim that cuts the beam from the film's centre before the stop does makes the lens slower
   than its stop says: f-numbers then mean less than they seem to. Said when the rim passes
   less than 95% of the stop's radius (clear apertures fitted to the marginal ray, as lens
   files often give them, clip its edge alone). Not with --trace thick, whose lens has no
   rims and whose cone is the thick lens's. */
static void warn_axial_limit(const camera *cam)
{
    chief_lens open;
    double passing;
    if (cam->trace == TRACE_KIND_THICK || chief_lens_open(&open, &cam->lens))
        return;
    const int limit = chief_axial_limit(&open, &cam->lens, &passing);
    chief_lens_close(&open);
    if (limit == cam->lens.stop || passing >= 0.95 || !(cam->centre_cone_sin2 > 0.0))
        return;
    const lens *l = &cam->lens;
    char where[64];   /* no ray from the centre gets to the rest of the stop: no rim to name */
    snprintf(where, sizeof where, limit >= 0 ? ":%d: the rim of this surface" : ": its surfaces",
             limit >= 0 ? l->surface[limit].line : 0);
    fprintf(stderr, "lens2pov: warning: %s%s, not the stop (line %d, %g mm open), limit%s the "
                    "beam from the film's centre to %.0f%% of the stop's diameter: the lens works "
                    "at f/%.3g, not the f/%.3g its stop gives\n", l->path, where,
            l->surface[l->stop].line, l->stop_diameter_mm, limit >= 0 ? "s" : "", 100.0 * passing,
            0.5 / sqrt(cam->centre_cone_sin2), info_working_f_number(cam));
}

void cli_warn(const cli *c, const camera *cam, bool picture)
{
    cli_warn_wavelength(c, cam->lens.path, cam->glass);
    warn_axial_limit(cam);
    if (c->cam.blade_rotation_deg != 0.0 && c->cam.aperture_blades == 0)
        fprintf(stderr, "lens2pov: warning: --blade-rotation %g turns blades, and the stop has none "
                        "(--aperture-blades N): it changes nothing\n", c->cam.blade_rotation_deg);
    /* A film nearer the lens than its focal plane images a virtual object: nothing in front of
       the lens is sharp. */
    if (!isnan(c->cam.film_distance_mm) && !(cam->focus_distance_units > 0.0) &&
        isfinite(cam->focus_distance_units))
        fprintf(stderr, "lens2pov: warning: --film-distance %g mm focuses %g units behind the "
                        "film: nothing in the scene is sharp\n", c->cam.film_distance_mm,
                -cam->focus_distance_units);
    if (!picture)
        return;
    if (c->cam.pupil == PUPIL_STOP)
        fprintf(stderr, "lens2pov: warning: --pupil stop aims at the stop's own disk, which misses "
                        "rays the lens passes and holds rays it blocks: the picture is biased (with "
                        "normalized weights the lens's vignetting is lost, too bright off the axis; "
                        "with physical ones too dark; a diagnostic: stop-image and rear are "
                        "unbiased)\n");
    /* Rays leave out diffraction: through a stop this small it would blur every point over the
       Airy disk, 2.44 lambda N_w across (lambda 550 nm; N_w = 1 / (2 sin theta), the working
       f-number of the cone that reaches the film centre, larger than N when focused near),
       more than 1% of the film's diagonal. */
    const double n_w = cam->centre_cone_sin2 > 0.0 ? 0.5 / sqrt(cam->centre_cone_sin2)
                                                   : cam->f_number;
    const double airy_mm = 2.44 * 550e-6 * n_w;
    if (!isfinite(airy_mm))   /* a stop so small that its f-number overflows */
        fprintf(stderr, "lens2pov: warning: through a stop this small diffraction, which ray "
                        "tracing leaves out, would blur every point over the whole film: the "
                        "picture is not what this lens would take\n");
    else if (airy_mm > 0.01 * cam->film.diagonal_mm)
        fprintf(stderr, "lens2pov: warning: at working f/%.4g diffraction, which ray tracing "
                        "leaves out, would blur every point over %.3g mm (the Airy disk, 2.44 "
                        "lambda N at 550 nm), %.3g pixels: the picture is not what this lens "
                        "would take\n", n_w, airy_mm,
                airy_mm / (cam->film.width_mm / cam->film.width));
    warn_pass_share(c, cam);
}

