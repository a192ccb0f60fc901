/* A sub-image's weights as render keeps them until developed: the weights themselves while
   they take little memory, else only where the pixels pass, as runs, from which they are made
   again. All of them kept would be spp x pixels floats; the runs grow with the edges of the
   region the lens passes, as the sub-image's faces do, and making the weights again takes
   the pupil alone, without the lens trace. Either way, what is kept here stays in memory. */
#ifndef LENS2POV_FIELD_FIELDPASS_H
#define LENS2POV_FIELD_FIELDPASS_H

#include <stdbool.h>
#include "base/error.h"
#include "camera/camera.h"

/* render keeps a field's weights in memory as floats up to this many MB in all; beyond, the
   runs, since making the weights again costs a little CPU. The environment's
   LENS2POV_FIELD_WEIGHTS_MB replaces it. */
#define FIELD_WEIGHTS_KEPT_MB 256.0

/* That bound in bytes, the environment's or the default. L2P_BAD_INPUT, naming the variable,
   when it is set to anything but a number of 0 or more (*bytes then the default). */
int field_weights_kept_bytes(double *bytes, l2p_error *err);

typedef struct field_pass {
    float *weights;            /* kept as built, one a crop pixel; NULL: made again */
    film_sample sample;        /* the sub-image's shared sample, placed in its stratum */
    double weight_scale;       /* its stratum's (field_strata_place) */
    long long *runs;           /* begin, end (exclusive) of each run of passing crop pixels,
                                  pixel y * crop width + x, increasing */
    long long run_count;
} field_pass;

/* From the weights field_build_subimage gave a sub-image (those above 0 pass), seen with s and
   weight_scale: with keep, or when the runs would take more memory than the weights (more
   than one run in four pixels), *weights itself, which out then owns (*weights becomes NULL);
   else the runs. L2P_FAILED out of memory. */
int field_pass_of(float **weights, long long pixels, film_sample s, double weight_scale,
                  bool keep, field_pass *out, l2p_error *err);

/* The weights again, one a crop pixel of camera c: those field_build_subimage gave, bit for
   bit, where the pixels pass, 0 elsewhere. L2P_FAILED out of memory. */
int field_pass_weights(const camera *c, const field_pass *p, float *weights, l2p_error *err);

void field_pass_free(field_pass *p);

#endif
