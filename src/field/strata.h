/* Post-stratification of the shared pupil points: the core of the pupil that passes whole on
   the axis, and the ring around it (docs/fields.md, "The exposure"). */
#ifndef LENS2POV_FIELD_STRATA_H
#define LENS2POV_FIELD_STRATA_H

#include <stdbool.h>
#include "camera/camera.h"

/* Wavelengths, evenly spaced over the spectrum, at which the core's radius is measured. */
enum { FIELD_STRATA_WAVELENGTHS = 33 };

typedef struct field_strata {
    bool on;                   /* false: the plain estimate, every scale 1 */
    double core_radius[FIELD_STRATA_WAVELENGTHS];   /* on the unit disk; one value without dispersion */
    double core_share;         /* the core's share of the samples' domain */
    double core_scale, ring_scale;   /* what a sub-image's weights are multiplied by */
} field_strata;

/* Measures the core on camera c's axis and counts its spp shared samples (field_shared_sample)
   in each stratum. */
void field_strata_count(const camera *c, field_strata *out);

/* The core's radius on the unit disk at this wavelength (any, without dispersion). */
double field_strata_core_radius(const field_strata *t, double nm);

/* Whether shared sample s falls in the ring. */
bool field_strata_in_ring(const field_strata *t, film_sample s);

/* The factor for the weights of a sub-image seen with shared sample s. */
double field_strata_scale(const field_strata *t, film_sample s);

#endif
