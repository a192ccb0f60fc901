/* What lens2pov-image-io.so exports: the functions of image_io.h under other names, so that the
   C side (image_io_loader.c) can keep the public names and forward to them once the library is
   loaded. Each function is declared through its type, so that the loader's function pointers and
   the C++ definitions cannot drift apart. */
#ifndef LENS2POV_IMAGE_IO_IMPL_H
#define LENS2POV_IMAGE_IO_IMPL_H

#include "image/image_io.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The file the build puts beside the executable (and `make install` into PREFIX/lib/lens2pov). */
#define IMAGE_IO_LIBRARY "lens2pov-image-io.so"

typedef int image_io_read_rgba_fn(const char *path, int *width, int *height, float **pixels,
                                  l2p_error *err);
typedef int image_io_write_rgb_fn(const char *path, int width, int height, const float *pixels,
                                  const image_attribute *attributes, int attribute_count,
                                  l2p_error *err);
typedef int image_io_get_attribute_fn(const char *path, const char *name, char *buf, size_t len);

/* Same contracts as image_read_rgba, image_write_rgb and image_get_attribute. The library calls
   back into the executable for l2p_fail, cleanup_track and cleanup_untrack (the signal handler's
   list of temporary files lives there), which the executable exports for it (see Makefile). */
image_io_read_rgba_fn image_io_impl_read_rgba;
image_io_write_rgb_fn image_io_impl_write_rgb;
image_io_get_attribute_fn image_io_impl_get_attribute;

#ifdef __cplusplus
}
#endif

#endif
