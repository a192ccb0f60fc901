/* Images through OpenImageIO; the only C++ of the project is behind these functions. It is
   built into lens2pov-image-io.so, loaded on the first call (image_io_loader.c); when that
   library cannot be loaded, every function returns L2P_FAILED, err naming the paths tried. */
#ifndef LENS2POV_IMAGE_IO_H
#define LENS2POV_IMAGE_IO_H

#include "base/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reads any image OpenImageIO knows as linear float RGBA, row 0 at the top; alpha is 1 where
   the file has none. *pixels is malloc'd (width * height * 4 floats). One or two colour
   channels are grey. Float files (EXR) are taken as linear; integer files (PNG, TIFF, JPEG) are
   decoded with the exact sRGB curve unless they say they are linear or carry a gamma; their
   colour is then multiplied by alpha (associated alpha, as EXR stores it). A missing file is
   L2P_BAD_INPUT, any other failure L2P_FAILED. */
int image_read_rgba(const char *path, int *width, int *height, float **pixels, l2p_error *err);

typedef struct image_attribute {
    const char *name;   /* e.g. "lens2pov:lens", "FNumber" */
    const char *value;
} image_attribute;

/* Writes linear float RGB pixels (3 floats a pixel, row 0 at the top), by the extension of path:
   .png 8-bit sRGB-encoded (as POV-Ray writes PNG), .tif/.tiff 16-bit sRGB-encoded, .exr linear
   half float. Writes to a temporary name beside path and renames it when complete.
   Details: the extension is matched case-insensitively, anything else is L2P_BAD_INPUT; PNG
   and TIFF values are clipped to [0, 1], encoded with the exact sRGB curve (IEC 61966-2-1) and
   rounded to the nearest code. Attributes are stored as strings under their names, "FNumber"
   also as OIIO's float "FNumber" and "Exif:FNumber"; all of them (but "Software") also go into
   ImageDescription as "name=value" lines, unless the caller gives one, because TIFF drops
   attributes it does not know. The temporary file is "<dir>/.<base>.tmp<pid><ext>", registered
   with cleanup_track while it exists. A missing folder is L2P_BAD_INPUT (as in outfile_open),
   any other failure L2P_FAILED; no file is left behind on failure. */
int image_write_rgb(const char *path, int width, int height, const float *pixels,
                    const image_attribute *attributes, int attribute_count, l2p_error *err);

/* Copies into buf (truncated to len - 1 characters) the value of attribute name of the image
   at path, formatted as text, looking also in the "name=value" lines of its ImageDescription
   (see image_write_rgb). Returns L2P_OK when found, L2P_FAILED when the file cannot be opened
   or has no such attribute. For tests and `info`-like reports. */
int image_get_attribute(const char *path, const char *name, char *buf, size_t len);

/* Loads the image library now rather than on the first image read or write, so that a command
   that will need it fails before its long work when it cannot be loaded: L2P_FAILED, with the
   paths tried, as the other functions would fail. */
int image_io_ready(l2p_error *err);

/* Whether the image library is there to load, without loading it (a file check, at once):
   render checks this before POV-Ray runs and waits for the load, which takes about 0.3 s,
   only when it develops. L2P_FAILED with the paths tried, as image_io_ready. */
int image_io_present(l2p_error *err);

#ifdef __cplusplus
}
#endif

#endif
