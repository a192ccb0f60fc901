#include "cli/info.h"
#include "optics/focus.h"
#include "cli/commands.h"
#include "cli/framing.h"
#include "cli/lens_lookup.h"
#include "camera/fieldangle.h"

#include <stdlib.h>
#include <string.h>

int lens_info_of(const lens *src, lens_info *out, l2p_error *err)
{
    lens l;
    if (lens_copy(&l, src))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    l.stop_diameter_mm = l.surface[l.stop].aperture_diameter_mm;
    lens_set_film_distance(&l, 0.0);
    thick_lens t;
    double ep_z, ep_r, xp_z, xp_r;
    int st = thick_lens_of(&l, 0, l.count - 1, &t, err);
    if (!st)
        st = focus_check_real_image(&l, &t, err);   /* as trace's focusing refuses it */
    if (!st)
        st = pupil_stop_image(&l, false, &ep_z, &ep_r, err);
    /* the pupils alone, not a pupil to sample: with the film at the rear vertex, a stop there
       would be a pupil in the film plane, which sampling refuses */
    if (!st)
        st = pupil_stop_image(&l, true, &xp_z, &xp_r, err);
    if (!st) {
        memset(out, 0, sizeof *out);
        out->efl_mm = thick_efl_mm(&t);
        out->bfd_mm = -t.f2_z_mm;   /* rear vertex (z = 0 here) to F2, toward the film */
        out->ffd_mm = t.f1_z_mm - l.surface[0].vertex_z_mm;
        out->f_number = out->efl_mm / (2.0 * ep_r);
        out->stop_diameter_mm = l.stop_diameter_mm;
        out->total_length_mm = lens_total_length_mm(&l);
        out->p1_from_rear_mm = t.p1_z_mm;
        out->p2_from_rear_mm = t.p2_z_mm;
        out->entrance_pupil_from_rear_mm = ep_z;
        out->entrance_pupil_diameter_mm = 2.0 * ep_r;
        out->exit_pupil_from_rear_mm = xp_z;
        out->exit_pupil_diameter_mm = 2.0 * xp_r;
    }
    lens_free(&l);
    return st;
}

double info_half_field_deg(const camera *c, vec3 p)
{
    field_angles f;
    if (field_angles_open(&f, c))
        return NAN;
    const double deg = field_angles_half_deg(&f, hypot(p.x, p.y));
    field_angles_close(&f);
    return deg;
}

/* The image-side f-number at the focus in effect, N_w = 1 / (2 n' sin theta'), paraxially
   the exit pupil's height above the film over its diameter (the film at z = 0, in air): at
   infinity focus the f-number itself, nearer N (1 + |m| / m_p), m the magnification and m_p
   the pupil magnification (Smith, Modern Optical Engineering, 4th ed., sec. 6.4). */
double info_working_f_number(const camera *c)
{
    double z, r;
    l2p_error ignored;
    if (pupil_stop_image(&c->lens, true, &z, &r, &ignored) || !(r > 0.0))
        return NAN;
    return fabs(z) / (2.0 * r);   /* a pupil behind the film too (z < 0) */
}

typedef struct field { const char *key, *label, *unit; double value; } field;

static void print_fields(FILE *out, const field *f, int n, bool json)
{
    for (int i = 0; i < n; i++) {
        const char *comma = i + 1 < n ? "," : "";
        if (json && isfinite(f[i].value))
            fprintf(out, "  \"%s\": %.10g%s\n", f[i].key, f[i].value, comma);
        else if (json)
            fprintf(out, "  \"%s\": null%s\n", f[i].key, comma);
        else
            fprintf(out, "%-34s %12.6g %s\n", f[i].label, f[i].value, f[i].unit);
    }
}

void info_print(FILE *out, const lens *l, bool glass, const lens_info *li, const camera *c,
                double wavelength_nm, bool json)
{
    field f[32] = {
        {"efl_mm", "effective focal length", "mm", li->efl_mm},
        {"bfd_mm", "back focal distance", "mm", li->bfd_mm},
        {"ffd_mm", "front focal distance", "mm", li->ffd_mm},
        {"f_number", "f-number at full stop", "", li->f_number},
        {"stop_diameter_mm", "stop diameter", "mm", li->stop_diameter_mm},
        {"total_length_mm", "total length (front to rear vertex)", "mm", li->total_length_mm},
        {"front_principal_plane_mm", "front principal plane (from rear)", "mm", li->p1_from_rear_mm},
        {"rear_principal_plane_mm", "rear principal plane (from rear)", "mm", li->p2_from_rear_mm},
        {"entrance_pupil_mm", "entrance pupil (from rear)", "mm", li->entrance_pupil_from_rear_mm},
        {"entrance_pupil_diameter_mm", "entrance pupil diameter", "mm", li->entrance_pupil_diameter_mm},
        {"exit_pupil_mm", "exit pupil (from rear)", "mm", li->exit_pupil_from_rear_mm},
        {"exit_pupil_diameter_mm", "exit pupil diameter", "mm", li->exit_pupil_diameter_mm},
    };
    int n = 12;
    if (c) {
        const film *fi = &c->film;
        field more[] = {
            {"film_distance_mm", "film distance", "mm", c->lens.film_distance_mm},
            {"focus_distance", "focus distance (film to subject)", "units", c->focus_distance_units},
            {"aperture_f_number", "f-number (this aperture)", "", c->f_number},
            {"working_f_number", "working f-number (paraxial)", "", info_working_f_number(c)},
            /* 1 / (2 sin theta') of the cone that passes at the film centre, rims and all */
            {"working_f_number_traced", "working f-number (traced)", "",
             c->centre_cone_sin2 > 0.0 ? 0.5 / sqrt(c->centre_cone_sin2) : NAN},
            {"aperture_diameter_mm", "aperture diameter", "mm", c->lens.stop_diameter_mm},
            {"film_width_mm", "film width", "mm", fi->width_mm},
            {"film_height_mm", "film height", "mm", fi->height_mm},
            {"film_diagonal_mm", "film diagonal", "mm", fi->diagonal_mm},
            {"hfov_deg", "horizontal field of view", "deg", 2 * info_half_field_deg(c, v3(0.5 * fi->width_mm, 0, 0))},
            {"vfov_deg", "vertical field of view", "deg", 2 * info_half_field_deg(c, v3(0, 0.5 * fi->height_mm, 0))},
            {"dfov_deg", "diagonal field of view", "deg", 2 * info_half_field_deg(c, v3(0.5 * fi->width_mm, 0.5 * fi->height_mm, 0))},
            /* Only where the lens passes nothing beyond it (a fisheye's image circle). */
            {"image_circle_mm", "image circle diameter", "mm",
             isfinite(c->pupil.reach_mm) ? 2.0 * c->pupil.reach_mm : NAN},
        };
        memcpy(f + n, more, sizeof more);
        n += (int)(sizeof more / sizeof more[0]);
        if (!json && !isfinite(f[n - 1].value))
            n--;   /* no image circle: the lens covers the film (JSON says null) */
        /* N blades inscribed in the opening pass N sin(2 pi / N) / (2 pi) of its area: the
           f-number of a round stop passing as much light. */
        const int blades = c->lens.blades.count;
        if (blades)
            f[n++] = (field){"blades_f_number", "f-number of the blades' light", "",
                             c->f_number / sqrt(blades * sin(2 * M_PI / blades) / (2 * M_PI))};
    }
    if (!isnan(wavelength_nm)) {   /* first */
        memmove(f + 1, f, sizeof *f * (size_t)n++);
        f[0] = (field){"wavelength_nm", "wavelength", "nm", wavelength_nm};
    }
    if (json) {
        fputs("{\n  \"lens\": \"", out);
        for (const char *p = l->name; *p; p++)
            fprintf(out, *p == '"' || *p == '\\' ? "\\%c" : (unsigned char)*p < 32 ? "\\u%04x" : "%c", *p);
        fputs("\",\n", out);
        /* Only for files that give Abbe numbers: a four-column file prints as it always did. */
        if (glass)
            fputs("  \"abbe_numbers\": true,\n", out);
    }
    else
        fprintf(out, "%s (%d surfaces, stop on line %d%s)\n", l->path, l->count,
                l->surface[l->stop].line, glass ? ", Abbe numbers given" : "");
    print_fields(out, f, n, json);
    if (json)
        fprintf(out, "}\n");
}

int info_command(const cli *c, l2p_error *err)
{
    int st = cli_expect_arguments(c, 1, false, err);
    lens l;
    if (st || (st = lens_read_named(c->positional[0], &l, err)))
        return st;
    const bool glass = lens_has_abbe(&l);
    if (!isnan(c->cam.wavelength_nm))
        lens_at_wavelength(&l, c->cam.wavelength_nm);
    lens_info li;
    camera cam;
    bool with_camera = c->film_given;
    if (!(st = lens_info_of(&l, &li, err)) && with_camera) {
        lens copy;
        /* info prints no weights: none to normalize, nothing to refuse for it. */
        cli physical = *c;
        physical.cam.weighting = WEIGHTING_PHYSICAL;
        st = lens_copy(&copy, &l) ? l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory")
                                  : framing_camera_setup(&cam, &copy, &physical, err);
        if (st)
            camera_free(&cam);
        else
            cam.glass = glass;   /* the file's, before --wavelength fixed the indices */
    }
    if (!st && with_camera)
        cli_warn(c, &cam, false);
    else if (!st)
        cli_warn_wavelength(c, l.path, glass);
    if (!st)
        info_print(stdout, &l, glass, &li, with_camera ? &cam : NULL, c->cam.wavelength_nm,
                   c->json);
    if (with_camera && !st)
        camera_free(&cam);
    lens_free(&l);
    return st;
}
