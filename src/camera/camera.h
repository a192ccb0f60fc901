/* One film sample to one world ray with its weight; focusing, aperture and placement. */
#ifndef LENS2POV_CAMERA_H
#define LENS2POV_CAMERA_H

#include <stdbool.h>
#include <stdint.h>
#include "base/error.h"
#include "camera/film.h"
#include "optics/lens.h"
#include "optics/pupil.h"
#include "optics/thicklens.h"
#include "optics/trace.h"
#include "optics/trace_batch.h"

typedef enum trace_kind { TRACE_KIND_FULL, TRACE_KIND_THICK } trace_kind;
typedef enum weighting { WEIGHTING_NORMALIZED, WEIGHTING_PHYSICAL } weighting;
/* --dispersion: auto is on when the lens gives Abbe numbers and the trace is full. */
typedef enum dispersion_mode { DISPERSION_AUTO, DISPERSION_ON, DISPERSION_OFF } dispersion_mode;

/* The camera options of the command line. NAN (or 0 for the integers) means "not given". */
typedef struct camera_options {
    int width, height, spp;
    double film_diagonal_mm;
    double film_distance_mm, focus_distance_units;  /* at most one; INFINITY focuses at infinity */
    double aperture_diameter_mm, f_number;          /* at most one */
    int aperture_blades;                            /* 0: a round stop; else 3 .. LENS_MAX_BLADES */
    double blade_rotation_deg;                      /* a corner's angle from +x toward +y */
    pupil_kind pupil;
    trace_kind trace;
    vec3 location, look_at, sky;
    bool mirror;               /* right points left: the picture mirrored (a scene's camera) */
    double unit_mm;
    weighting weighting;
    dispersion_mode dispersion;
    double wavelength_nm;      /* NAN: the file's n_d; else every index at this wavelength */
    uint64_t seed;
    int crop_x0, crop_y0, crop_x1, crop_y1;          /* x1 = 0: the whole film */
} camera_options;

/* Defaults of the contract: 640x480, 16 spp, 35 mm diagonal, stop-image pupil, full tracing,
   location <0,0,0>, look-at <0,0,1>, sky <0,1,0>, metres, normalized weights. */
void camera_options_default(camera_options *o);

typedef struct camera {
    lens lens;                 /* at the chosen film distance and stop opening */
    film film;
    pupil pupil;               /* with dispersion, covering the whole spectrum */
    /* With dispersion, spectral_count pupils (CAMERA_SPECTRAL_PUPILS or more) fitted at
       wavelengths evenly spaced over the spectrum, each covering its neighbours'
       (camera_pupil_at); else NULL. */
    pupil *spectral;
    int spectral_count;
    thick_lens thick;          /* thick lens of the whole lens (for --trace thick and info) */
    double thick_exit_z_mm, thick_exit_radius_mm;   /* --trace thick: the exit pupil, which
                                                       blocks what it does not pass */
    trace_kind trace;
    weighting weighting;
    bool dispersion;           /* each sample traced at its own wavelength (spectrum.h) */
    bool glass;                /* the lens file gives Abbe numbers (before --wavelength) */
    double weight_scale;       /* multiplies A cos^4 / Z^2 (1 when physical) */
    double focus_distance_units;  /* film plane to in-focus plane; INFINITY at infinity */
    double f_number;           /* rear focal length / entrance pupil diameter */
    /* sin^2 of the half-angle of the cone that passes at the film centre (averaged over the
       spectrum with dispersion), 0 when none: the working f-number is 1 / (2 sin) */
    double centre_cone_sin2;
    sample_pattern samples;
    int crop_x0, crop_y0, crop_x1, crop_y1;
    /* world_from_camera: p -> location + (p.x right + p.y up + p.z forward) / unit_mm */
    vec3 location, right, up, forward;
    double unit_mm;
} camera;

enum { CAMERA_SPECTRAL_PUPILS = 9, CAMERA_SPECTRAL_PUPILS_MAX = 65 };

/* The pupil a sample of wavelength nm is drawn from: with dispersion, the spectral pupil
   nearest nm, which holds every ray the lens passes between the midpoints to its neighbours;
   else the pupil. */
const pupil *camera_pupil_at(const camera *c, double nm);

/* Takes ownership of the lens. Validates the options against the lens (L2P_BAD_INPUT with a
   message for a focus closer than the lens allows, an aperture larger than the stop, ...). */
int camera_setup(camera *c, lens *l, const camera_options *o, l2p_error *err);
void camera_free(camera *c);

/* Traces the film ray from film point p toward pupil sample (u, v) through the lens, at the
   d line when the camera has dispersion. On
   success gives the outgoing ray in camera space (origin on the front of the lens) and its
   weight, and returns true; false when the lens blocks it. */
bool camera_trace(const camera *c, vec3 film_point, double u, double v, ray *out, double *weight);
/* The same at wavelength nm when the camera has dispersion (the d line's without). */
bool camera_trace_at(const camera *c, vec3 film_point, double u, double v, double nm, ray *out,
                     double *weight);

/* Film samples traced together, interleaved for speed: in, each one's film point and pupil
   sample, and its wavelength when the camera has dispersion; out, its ray, its weight and
   whether the lens passed it. */
enum { CAMERA_BATCH = TRACE_BATCH_MAX };   /* one call of the batch tracer */
typedef struct sample_batch {
    int n;                                  /* <= CAMERA_BATCH */
    vec3 film_point[CAMERA_BATCH];
    double u[CAMERA_BATCH], v[CAMERA_BATCH];
    double wavelength_nm[CAMERA_BATCH];     /* read only with dispersion */
    ray out[CAMERA_BATCH];
    double weight[CAMERA_BATCH];
    bool passed[CAMERA_BATCH];
} sample_batch;

void camera_trace_batch(const camera *c, sample_batch *b);

/* camera_trace_batch's first step, without the lens: each sample's film ray toward its pupil
   point (direction, CAMERA_BATCH of them) and its weight, 0 where the pupil gives none. What
   the trace then gives those that pass, bit for bit. */
void camera_film_rays(const camera *c, sample_batch *b, vec3 *direction);

/* The share of samples the lens passes, from a probe: 16 x 16 film points over the crop
   (those the lens reaches), 64 samples each from the film's own sample pattern (pupil points
   and, with dispersion, wavelengths). 1 is every sample, 0 none; NAN when the lens reaches no
   film point probed. A low share is a picture that is noisy for its samples per pixel. */
double camera_pass_share(const camera *c);

/* Camera space (mm) to world (scene units): a point; a difference of points (the rotation and
   the scale without the translation); a direction, normalized. */
vec3 camera_world_from_camera_point(const camera *c, vec3 p);
vec3 camera_world_from_camera_offset(const camera *c, vec3 p);
vec3 camera_world_from_camera_dir(const camera *c, vec3 d);


#endif
