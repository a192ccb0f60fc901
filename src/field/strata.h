/* Post-stratification of the shared pupil points over the fitted pupil's margin
   (docs/fields.md, "The exposure"). */
#ifndef LENS2POV_FIELD_STRATA_H
#define LENS2POV_FIELD_STRATA_H

#include "camera/camera.h"

/* What a sub-image's weights are multiplied by, by the stratum its pupil point falls in. */
typedef struct field_strata {
    double core_scale, margin_scale;
} field_strata;

/* Counts camera c's spp shared samples (field_shared_sample) by stratum. */
void field_strata_count(const camera *c, field_strata *out);

/* The factor for the weights of a sub-image seen with shared sample s. */
double field_strata_scale(const field_strata *t, const camera *c, film_sample s);

#endif
