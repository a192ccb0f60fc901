/* Images through OpenImageIO; the only C++ of the project is behind these functions. */
#ifndef LENS2POV_IMAGE_IO_H
#define LENS2POV_IMAGE_IO_H

#include "error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reads any image OpenImageIO knows as linear float RGBA, row 0 at the top; alpha is 1 where
   the file has none. *pixels is malloc'd (width * height * 4 floats). */
int image_read_rgba(const char *path, int *width, int *height, float **pixels, l2p_error *err);

typedef struct image_attribute {
    const char *name;   /* e.g. "lens2pov:lens", "FNumber" */
    const char *value;
} image_attribute;

/* Writes linear float RGB pixels (3 floats a pixel, row 0 at the top), by the extension of path:
   .png 8-bit sRGB-encoded (as POV-Ray writes PNG), .tif/.tiff 16-bit sRGB-encoded, .exr linear
   half float. Writes to a temporary name beside path and renames it when complete. */
int image_write_rgb(const char *path, int width, int height, const float *pixels,
                    const image_attribute *attributes, int attribute_count, l2p_error *err);

#ifdef __cplusplus
}
#endif

#endif
