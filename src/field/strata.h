/* Stratified pupil points for field sampling: the core of the pupil that passes whole on the
   axis, and the ring around it, each given a fixed share of the shared samples
   (docs/fields.md, "The exposure"). */
#ifndef LENS2POV_FIELD_STRATA_H
#define LENS2POV_FIELD_STRATA_H

#include <stdbool.h>
#include "camera/camera.h"

/* Wavelengths, evenly spaced over the spectrum, at which the core's radius is measured. */
enum { FIELD_STRATA_WAVELENGTHS = 33 };

typedef struct field_strata {
    bool on;                   /* false: the shared samples not moved, every scale 1 (but post) */
    /* With blades the region that passes on the axis is the blades' polygon, not a disk: the
       samples are left where they are and weighted by whether they pass there (post). */
    bool post;
    const camera *camera;      /* with post: the camera whose axis decides */
    double axis_share;         /* with post: the share of the unit disk that passes there */
    int axis_count;            /* with post: how many of the samples pass there */
    double core_radius[FIELD_STRATA_WAVELENGTHS];   /* on the unit disk; one value without dispersion */
    double ring_from;          /* a shared sample whose pupil_u is at least this goes to the ring */
    int core_count, ring_count;   /* how many of the shared samples go to each stratum */
} field_strata;

/* Measures the core on camera c's axis and deals the first `samples` shared samples
   (field_shared_sample) to the strata: camera c's spp, or adaptive sampling's first round,
   whose every later block of as many (a power of two) is dealt alike. */
void field_strata_count(const camera *c, int samples, field_strata *out);

/* The core's radius on the unit disk at this wavelength (any, without dispersion). */
double field_strata_core_radius(const field_strata *t, double nm);

/* Whether shared sample s, as field_shared_sample gives it, goes to the ring. */
bool field_strata_in_ring(const field_strata *t, film_sample s);

/* Moves shared sample *s's pupil point into its stratum, uniformly over the stratum's part of
   the unit disk, and returns the factor for its sub-image's weights: the stratum's share of
   the disk over its share of the samples. With post, leaves *s where it is and returns the
   factor of its stratum: the samples that pass on the axis, or the others. Leaves *s alone
   and returns 1 when t is neither. */
double field_strata_place(const field_strata *t, film_sample *s);

#endif
