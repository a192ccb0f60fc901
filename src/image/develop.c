#include "image/develop.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "image/image_io.h"
#include "optics/spectrum.h"

static long long crop_width(const samplemap_header *h) { return h->crop_x1 - h->crop_x0; }
static long long crop_height(const samplemap_header *h) { return h->crop_y1 - h->crop_y0; }

/* The chunk's image must be exactly packed_width x (face rows + 1): anything else means the
   render does not belong to this map (or POV-Ray was run with other settings), the input's
   fault (L2P_BAD_INPUT, as field_develop says of a field render). */
static int check_chunk_image(const samplemap_header *h, long long chunk, int width, int height,
                             l2p_error *err)
{
    const long long count = samplemap_chunk_count(h);
    if (chunk < 0 || chunk >= count)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "chunk %lld does not exist (the map has %lld)",
                        chunk, count);
    const int rows = samplemap_chunk_rows(h, chunk);
    if (width != h->packed_width || height != rows + 1)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "render of chunk %lld is %dx%d, expected %dx%d (packed width x face "
                        "rows + 1): it does not belong to this sample map",
                        chunk, width, height, h->packed_width, rows + 1);
    return L2P_OK;
}

/* Index into the crop's pixels of a record's whole-film pixel; -1 outside the crop (a map made
   in memory, not checked by samplemap_read). */
static long long crop_index(const samplemap_header *h, uint32_t film_pixel)
{
    const long long x = film_pixel % (uint32_t)h->film_width - h->crop_x0;
    const long long y = film_pixel / (uint32_t)h->film_width - h->crop_y0;
    if (x < 0 || x >= crop_width(h) || y < 0 || y >= crop_height(h))
        return -1;
    return y * crop_width(h) + x;
}

/* The colour weights of every wavelength band (spectrum.h), or NULL without dispersion. */
static double (*band_weights(const samplemap_header *h))[3]
{
    if (h->wavelength_bands <= 0)
        return NULL;
    double (*w)[3] = malloc(sizeof *w * (size_t)h->wavelength_bands);
    for (int b = 0; w && b < h->wavelength_bands; b++)
        spectrum_band_weights(b, h->wavelength_bands, w[b]);
    return w;
}

size_t develop_sums_per_pixel(const samplemap_header *h)
{
    return h->wavelength_bands > 0 ? 10 : 3;
}

void develop_add(double *pixel, const double *colour, double weight, const float *rgba)
{
    if (!colour) {
        for (int c = 0; c < 3; c++)
            pixel[c] += weight * (double)rgba[c];
        return;
    }
    for (int c = 0; c < 3; c++) {
        pixel[c] += weight * colour[c] * (double)rgba[c];
        pixel[3 + c] += weight * colour[c];
        pixel[6 + c] += weight * (double)rgba[c];
    }
    pixel[9] += weight;
}

/* Adds face's colour into its film pixel. */
static int add_sample(const samplemap *map, const double (*colour)[3], long long face,
                      const float *rgba, double *sums, l2p_error *err)
{
    const samplemap_record *r = &map->records[face];
    const long long i = crop_index(&map->header, r->film_pixel);
    if (i < 0)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "face %lld: film pixel %lu outside the crop",
                        face, (unsigned long)r->film_pixel);
    develop_add(sums + develop_sums_per_pixel(&map->header) * (size_t)i,
                colour ? colour[map->band[face]] : NULL, (double)r->weight, rgba);
    return L2P_OK;
}

/* The end of the last row, past the table, has no face: POV-Ray leaves it black. Colour there
   is a render made through another camera: another trace's table, longer than this one, or
   the scene's own camera, when the include came before the scene (POV-Ray keeps the last
   camera) or not at all. */
static int check_unused_end(const samplemap_header *h, long long chunk, const float *rgba,
                            int width, int height, l2p_error *err)
{
    const long long first = chunk * h->chunk_faces, used = h->faces - first;
    for (long long i = used; i < (long long)(height - 1) * width; i++) {
        const float *p = rgba + 4 * (size_t)(width + i);   /* face i sits one row down */
        if (p[0] != 0.0f || p[1] != 0.0f || p[2] != 0.0f)
            return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "pixel (%lld, %d) of the render, past "
                            "the last ray, is not black: the render was not made through this "
                            "trace's include (a render of another trace, or one whose scene set "
                            "its camera after the include: POV-Ray keeps the last camera)",
                            i % width, height - 1);
    }
    return L2P_OK;
}

int develop_accumulate(const samplemap *map, long long chunk, const float *rgba, int width,
                       int height, double *sums, l2p_error *err)
{
    const samplemap_header *h = &map->header;
    int st = check_chunk_image(h, chunk, width, height, err);
    if (!st)
        st = check_unused_end(h, chunk, rgba, width, height, err);
    if (st)
        return st;
    double (*colour)[3] = band_weights(h);
    if (h->wavelength_bands > 0 && !colour)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    /* Image row y >= 1 shows face row y - 1 (POV-Ray 3.7.0.10, FS#254); row 0 is a duplicate. */
    const long long first = chunk * h->chunk_faces;
    for (int y = 1; y < height && !st; y++)
        for (int x = 0; x < width && !st; x++) {
            const long long face = first + (long long)(y - 1) * width + x;
            if (face >= h->faces)   /* past the table: the unused end of the last row */
                break;
            st = add_sample(map, (const double (*)[3])colour, face,
                            rgba + 4 * ((size_t)y * (size_t)width + (size_t)x), sums, err);
        }
    free(colour);
    return st;
}

/* With dispersion, channel c of a pixel is the irradiance sum(w) / spp times the radiance
   averaged with the weights w b_c (b_c the sample's band weight): sum(w b_c L_c) / sum(w b_c).
   Over all spp bands the b_c average 1 exactly, but a blocked sample (w = 0) takes its band
   out, and band weights span about -3 to 5: sum(w b_c L_c) / spp alone would tint a white
   pixel by up to a third at 16 spp for one blocked sample. This way a scene of one colour
   keeps it exactly wherever samples are blocked, and the fringes of dispersion (L_c varying
   with the band) stay; what it drops is the colour of vignetting that differs with
   wavelength, a fraction of a percent for real lenses. Where sum(w b_c) is below a quarter of
   sum(w) (few samples pass, in bands of small or negative weight) the average is no longer a
   mean of the samples' radiances, and the plain weighted mean sum(w L_c) / sum(w) is taken. */
static double dispersed(const double *pixel, int c, int spp)
{
    const double weight = pixel[9], band_weight = pixel[3 + c];
    if (!(weight > 0))
        return 0.0;
    const double radiance = band_weight >= 0.25 * weight ? pixel[c] / band_weight
                                                         : pixel[6 + c] / weight;
    return weight / spp * radiance;
}

void develop_finish(const samplemap *map, const double *sums, float *rgb)
{
    const samplemap_header *h = &map->header;
    const size_t pixels = (size_t)crop_width(h) * (size_t)crop_height(h);
    const size_t stride = develop_sums_per_pixel(h);
    for (size_t i = 0; i < pixels; i++)
        for (int c = 0; c < 3; c++)
            rgb[3 * i + c] = (float)(stride == 3 ? sums[3 * i + c] / h->spp
                                                 : dispersed(sums + stride * i, c, h->spp));
}

/* ---- the whole step ---- */

/* Reads one render and adds it in; errors name the render's file. */
static int develop_one(const samplemap *map, long long chunk, const char *path, double *sums,
                       l2p_error *err)
{
    int width = 0, height = 0;
    float *rgba = NULL;
    int st = image_read_rgba(path, &width, &height, &rgba, err);
    if (st)
        return st;
    st = develop_accumulate(map, chunk, rgba, width, height, sums, err);
    free(rgba);
    if (st) {
        char text[sizeof err->text];
        snprintf(text, sizeof text, "%s", err->text);
        l2p_fail(err, st, path, 0, "%s", text);
    }
    return st;
}

/* Metadata values as text; the buffers live in the caller. */
typedef struct metadata_text {
    char f_number[32], focus[32], film_distance[32], diagonal[32], spp[32];
} metadata_text;

/* %.6g, with "infinity" for a focus at infinity rather than printf's "inf". */
static void format_number(char *buf, size_t size, double v)
{
    if (isinf(v))
        snprintf(buf, size, "%sinfinity", v < 0 ? "-" : "");
    else
        snprintf(buf, size, "%.6g", v);
}

static int fill_attributes(const samplemap_header *h, metadata_text *t, image_attribute *a)
{
    format_number(t->f_number, sizeof t->f_number, h->f_number);
    format_number(t->focus, sizeof t->focus, h->focus_distance_units);
    format_number(t->film_distance, sizeof t->film_distance, h->film_distance_mm);
    format_number(t->diagonal, sizeof t->diagonal, h->film_diagonal_mm);
    snprintf(t->spp, sizeof t->spp, "%d", h->spp);
    const image_attribute list[] = {
        {"lens2pov:lens", h->lens},          {"lens2pov:pupil", h->pupil},
        {"lens2pov:trace", h->trace},        {"lens2pov:weighting", h->weighting},
        {"FNumber", t->f_number},            {"lens2pov:focus_distance", t->focus},
        {"lens2pov:film_distance_mm", t->film_distance},
        {"lens2pov:film_diagonal_mm", t->diagonal},
        {"lens2pov:spp", t->spp},            {"Software", "lens2pov"},
    };
    memcpy(a, list, sizeof list);
    int n = (int)(sizeof list / sizeof list[0]);
    if (h->wavelength_bands > 0)   /* only then: other pictures keep their bytes */
        a[n++] = (image_attribute){"lens2pov:dispersion", "on"};
    return n;
}

int develop_write_picture(const samplemap *map, const double *sums, const char *out_path,
                          l2p_error *err)
{
    const samplemap_header *h = &map->header;
    float *rgb = malloc(sizeof *rgb * 3 * (size_t)crop_width(h) * (size_t)crop_height(h));
    if (!rgb)
        return l2p_fail(err, L2P_FAILED, out_path, 0, "out of memory");
    develop_finish(map, sums, rgb);
    metadata_text text;
    image_attribute attributes[16];
    const int count = fill_attributes(h, &text, attributes);
    int st = image_write_rgb(out_path, (int)crop_width(h), (int)crop_height(h), rgb, attributes,
                             count, err);
    free(rgb);
    return st;
}

/* Whether paths a and b name one file: the same device and inode, or the same text when
   either is missing (then reading it reports that). */
static bool same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0)
        return strcmp(a, b) == 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

int develop_check_distinct(const char *const *renders, int render_count, l2p_error *err)
{
    for (int i = 0; i < render_count; i++)
        for (int j = 0; j < i; j++)
            if (same_file(renders[i], renders[j]))
                return l2p_fail(err, L2P_BAD_INPUT, renders[i], 0, "given as render %d and as "
                                "render %d: each render is developed once, in its place", j, i);
    return L2P_OK;
}

int develop_files(const samplemap *map, const char *const *renders, int render_count,
                  const char *out_path, l2p_error *err)
{
    const samplemap_header *h = &map->header;
    const long long chunks = samplemap_chunk_count(h);
    if (render_count != chunks)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "the sample map has %lld chunk%s but %d render%s given", chunks,
                        chunks == 1 ? "" : "s", render_count,
                        render_count == 1 ? " was" : "s were");
    int st = develop_check_distinct(renders, render_count, err);
    if (st)
        return st;
    double *sums = calloc(develop_sums_per_pixel(h) * (size_t)crop_width(h) * (size_t)crop_height(h),
                          sizeof *sums);
    if (!sums)
        return l2p_fail(err, L2P_FAILED, out_path, 0, "out of memory");
    for (int k = 0; k < render_count && !st; k++)
        st = develop_one(map, k, renders[k], sums, err);
    if (!st)
        st = develop_write_picture(map, sums, out_path, err);
    free(sums);
    return st;
}
