/* Developing: weighting the rendered samples and averaging them into film pixels. */
#ifndef LENS2POV_DEVELOP_H
#define LENS2POV_DEVELOP_H

#include "error.h"
#include "samplemap.h"

/* Accumulates one rendered chunk image (RGBA, its first row being the row work-around's
   duplicate, dropped) into sums of weight * colour per film pixel of the crop. sums holds
   3 doubles per crop pixel. Alpha is not used: pixels past the table's last face (which POV-Ray
   leaves black) are recognised by their index. */
int develop_accumulate(const samplemap *map, long long chunk, const float *rgba, int width,
                       int height, double *sums, l2p_error *err);

/* Turns sums into the picture: each crop pixel is its sum divided by spp (blocked samples
   count as black: that is vignetting). rgb gets 3 floats a crop pixel. */
void develop_finish(const samplemap *map, const double *sums, float *rgb);

/* The whole develop step: reads every chunk's render, accumulates, writes out_path with the
   lens, f-number, focus distance, film distance, film diagonal and spp as metadata. */
int develop_files(const samplemap *map, const char *const *renders, int render_count,
                  const char *out_path, l2p_error *err);

#endif
