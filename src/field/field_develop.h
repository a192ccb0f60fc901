/* Developing a field render: its map (fieldmap.h) and its renders' pictures into the picture,
   each pixel of each sub-image weighted as pixel sampling weights a sample (develop.h). */
#ifndef LENS2POV_FIELD_FIELD_DEVELOP_H
#define LENS2POV_FIELD_FIELD_DEVELOP_H

#include <stdbool.h>
#include "field/fieldmap.h"

/* renders[r] is render r's picture (the ini's PREFIX.fNNN.exr), count of them; the picture goes
   to out with develop's metadata. L2P_BAD_INPUT for a count or a picture size that does not
   match the map (naming the file), a bad weight; errors of reading and writing pictures. */
int field_develop(const field_map *m, const char *const *renders, int count, const char *out,
                  l2p_error *err);

/* The same, a render at a time as its picture comes: the renders are added in their order
   (the sums then do not depend on the order pictures come in), each as soon as it and those
   before it are known. */
typedef struct field_developer {
    const field_map *map;
    double *sums;
    double *early;      /* the sums of the first early_count sub-images alone, or NULL */
    int early_count;
    float *weights;
    char **picture;     /* render r's picture once given */
    int next;           /* the first render not yet added */
    bool remove_pictures;   /* each picture is deleted once added (render's own, not kept) */
} field_developer;

int field_develop_start(field_developer *d, const field_map *m, l2p_error *err);

/* The same, adding onto sums of m's crop (3 a pixel, or develop_sums_per_pixel's) that an
   earlier developer gave up (field_develop_take_sums): adaptive sampling's second round goes
   on with its first's picture. d owns them from the call on, also when it fails. */
int field_develop_continue(field_developer *d, const field_map *m, double *sums, l2p_error *err);

/* d's sums, which the caller then owns (d keeps none; free it as usual). */
double *field_develop_take_sums(field_developer *d);

/* Keeps the sums of the first count sub-images apart too, in d->early (adaptive sampling's
   first round, fieldtiles.h). L2P_FAILED out of memory. */
int field_develop_keep_early(field_developer *d, int count, l2p_error *err);

/* Render r's picture is complete at path. L2P_FAILED for a render given twice; errors of
   field_develop. With remove_pictures set (after field_develop_start) the picture is deleted
   once it is in the sums, so that a render's pictures on disk do not add up to spp of them. */
int field_develop_add(field_developer *d, int r, const char *path, l2p_error *err);

/* Writes the picture once every render has been added. */
int field_develop_finish(field_developer *d, const char *out, l2p_error *err);
void field_develop_free(field_developer *d);

#endif
