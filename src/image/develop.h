/* Developing: weighting the rendered samples and averaging them into film pixels. */
#ifndef LENS2POV_DEVELOP_H
#define LENS2POV_DEVELOP_H

#include "base/error.h"
#include "image/samplemap.h"

/* The doubles sums holds a crop pixel: 3 (weight * colour), or with dispersion 10 (weight *
   band weight * colour, weight * band weight, weight * colour, weight). */
size_t develop_sums_per_pixel(const samplemap_header *h);

/* Adds one sample of this weight and rendered colour into a pixel's sums; colour is its
   wavelength band's colour weights (spectrum.h), NULL without dispersion. */
void develop_add(double *pixel, const double *colour, double weight, const float *rgba);

/* Accumulates one rendered chunk image (RGBA, its first row being the row work-around's
   duplicate, dropped) into the sums of the film pixels of the crop, develop_sums_per_pixel
   doubles each. Alpha is not used: pixels past the table's last face (which POV-Ray
   leaves black) are recognised by their index. Chunk k's image must be exactly packed_width x
   (samplemap_chunk_rows + 1), else L2P_FAILED with a message naming the sizes; a record whose
   film pixel is outside the crop (possible only in a map made in memory) is L2P_FAILED too. */
int develop_accumulate(const samplemap *map, long long chunk, const float *rgba, int width,
                       int height, double *sums, l2p_error *err);

/* Turns sums into the picture: each crop pixel is its sum divided by spp (blocked samples
   count as black: that is vignetting); with dispersion, the irradiance so found times the
   radiance averaged with the band weights (develop.c says why). rgb gets 3 floats a crop pixel. */
void develop_finish(const samplemap *map, const double *sums, float *rgb);

/* develop_finish, then the picture written to out_path with the metadata below: only the
   map's header is used (crop, spp, what the picture was made with). */
int develop_write_picture(const samplemap *map, const double *sums, const char *out_path,
                          l2p_error *err);

/* L2P_BAD_INPUT, naming it, when one file is given as two of the renders (one would be
   developed twice and another never); else L2P_OK. */
int develop_check_distinct(const char *const *renders, int render_count, l2p_error *err);

/* The whole develop step: reads every chunk's render, accumulates, writes out_path with the
   lens, f-number, focus distance, film distance, film diagonal and spp as metadata. renders[k]
   is chunk k's render; render_count must be samplemap_chunk_count (else L2P_BAD_INPUT). The
   picture is the crop only. Attributes (strings): lens2pov:lens, lens2pov:pupil,
   lens2pov:trace, lens2pov:weighting, FNumber, lens2pov:focus_distance (scene units, %.6g,
   "infinity"), lens2pov:film_distance_mm, lens2pov:film_diagonal_mm, lens2pov:spp,
   lens2pov:dispersion = "on" (only with dispersion),
   Software = "lens2pov". Errors from a render name its file. */
int develop_files(const samplemap *map, const char *const *renders, int render_count,
                  const char *out_path, l2p_error *err);

#endif
