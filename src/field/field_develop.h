/* Developing a field render: its map (fieldmap.h) and its renders' pictures into the picture,
   each pixel of each sub-image weighted as pixel sampling weights a sample (develop.h). */
#ifndef LENS2POV_FIELD_FIELD_DEVELOP_H
#define LENS2POV_FIELD_FIELD_DEVELOP_H

#include "field/fieldmap.h"

/* renders[r] is render r's picture (the ini's PREFIX.fNNN.exr), count of them; the picture goes
   to out with develop's metadata. L2P_BAD_INPUT for a count or a picture size that does not
   match the map (naming the file), a bad weight; errors of reading and writing pictures. */
int field_develop(const field_map *m, const char *const *renders, int count, const char *out,
                  l2p_error *err);

#endif
