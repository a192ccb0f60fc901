/* The sample map: for every face of the ray table (every rendered pixel), the film pixel it
   belongs to, its position inside that pixel and its weight.

   File layout (PREFIX.map): a text header of exactly SAMPLEMAP_HEADER_BYTES bytes, "key value"
   lines ending with the line "end" and padded with spaces, then `faces` records of 16 bytes,
   little-endian: uint32 film pixel index (y * film_width + x, whole-film coordinates),
   float32 x and y offsets inside the pixel in [0, 1), float32 weight. Face k is rendered in
   chunk k / chunk_faces, at packed position ((k % chunk_faces) % packed_width,
   (k % chunk_faces) / packed_width) of that chunk's face rows.

   Header lines, in this order: "lens2pov-samplemap 1", then one "key value" line for every
   field of samplemap_header under its own name (film_width ... unit_mm; strings are the rest
   of the line, their newlines written as spaces; doubles as %.17g, inf and nan allowed: they
   are metadata), then "end". Readers skip keys they do not know, refuse missing or repeated
   ones. samplemap_read refuses (L2P_BAD_INPUT, "FILE: what is wrong") a wrong magic line, a
   record count other than faces, chunk_faces not a positive multiple of packed_width, a crop
   outside the film, a film pixel outside the crop, an offset outside [0, 1] (float32 rounding
   may give 1), a weight that is negative or not finite, a string longer than its field, a
   film of more than 2^32 pixels or chunk_faces above INT_MAX (POV-Ray counts faces in an int).

   With dispersion the header has the line "wavelength_bands N" (N = spp, after unit_mm; absent
   without dispersion, so such maps are unchanged) and every record 4 bytes more: uint32 band,
   the sample's wavelength band (spectrum.h), below N. */
#ifndef LENS2POV_SAMPLEMAP_H
#define LENS2POV_SAMPLEMAP_H

#include <stdint.h>
#include <stdio.h>
#include "base/error.h"

enum { SAMPLEMAP_HEADER_BYTES = 4096 };

typedef struct samplemap_record {
    uint32_t film_pixel;
    float offset_x, offset_y;
    float weight;
} samplemap_record;

typedef struct samplemap_header {
    int film_width, film_height;   /* pixels of the whole film */
    int spp;                       /* samples traced per film pixel (blocked ones included) */
    int crop_x0, crop_y0, crop_x1, crop_y1; /* pixel region traced; x1, y1 exclusive */
    int packed_width;              /* width of every rendered chunk image */
    long long faces;               /* faces in the whole table */
    long long chunk_faces;         /* faces per chunk (a multiple of packed_width) */
    /* What the picture was made with, for the developed image's metadata. */
    char lens[256];
    char pupil[32], trace[32], weighting[32];
    double f_number, aperture_diameter_mm, focus_distance_units, film_distance_mm;
    double film_diagonal_mm, unit_mm;
    int wavelength_bands;          /* 0: no dispersion; else spp, and records carry a band */
} samplemap_header;

typedef struct samplemap {
    samplemap_header header;
    samplemap_record *records;     /* header.faces of them */
    uint32_t *band;                /* each record's band with dispersion, else NULL */
} samplemap;

/* Number of chunks and the rows of chunk k's face layout (its image has one row more, see
   povmesh.h for the row work-around). Count: ceil(faces / chunk_faces), but at least 1: a table
   with no faces is still rendered as one chunk of 1 row (the emitter writes one zero-area face
   that is not in the map). Rows: ceil(faces of the chunk / packed_width), at least 1; 0 for a
   chunk that does not exist. */
long long samplemap_chunk_count(const samplemap_header *h);
int samplemap_chunk_rows(const samplemap_header *h, long long chunk);

/* Writing: reserve the header, append records, then write the header once faces is known.
   band is NULL without dispersion, else each record's band. Each returns L2P_OK or L2P_FAILED
   (see ferror / errno). samplemap_finish also fails when
   the records appended are not exactly h->faces or the header does not fit its 4096 bytes,
   and leaves the file position at the end. */
int samplemap_begin(FILE *fp);
int samplemap_append(FILE *fp, const samplemap_record *records, const uint32_t *band,
                     size_t count);
int samplemap_finish(FILE *fp, const samplemap_header *h);

int samplemap_read(const char *path, samplemap *out, l2p_error *err);

/* The header on its own, for the field map (fieldmap.h) too, which has another first line and
   lines of its own. text: the first line magic, a line for every field of h, the lines of
   `more` ("key value\n" each, or ""), "end", then spaces to SAMPLEMAP_HEADER_BYTES; -1 when
   it does not fit. Parsing: text is SAMPLEMAP_HEADER_BYTES bytes and a NUL, changed in place;
   keys it does not know are skipped; L2P_BAD_INPUT naming path as samplemap_read does. */
int samplemap_header_text(const samplemap_header *h, const char *magic, const char *more,
                          char text[SAMPLEMAP_HEADER_BYTES]);
int samplemap_header_parse(char *text, const char *magic, samplemap_header *h, const char *path,
                           l2p_error *err);
void samplemap_free(samplemap *m);

#endif
