/* The sample map: for every face of the ray table (every rendered pixel), the film pixel it
   belongs to, its position inside that pixel and its weight.

   File layout (PREFIX.map): a text header of exactly SAMPLEMAP_HEADER_BYTES bytes, "key value"
   lines ending with the line "end" and padded with spaces, then `faces` records of 16 bytes,
   little-endian: uint32 film pixel index (y * film_width + x, whole-film coordinates),
   float32 x and y offsets inside the pixel in [0, 1), float32 weight. Face k is rendered in
   chunk k / chunk_faces, at packed position ((k % chunk_faces) % packed_width,
   (k % chunk_faces) / packed_width) of that chunk's face rows. */
#ifndef LENS2POV_SAMPLEMAP_H
#define LENS2POV_SAMPLEMAP_H

#include <stdint.h>
#include <stdio.h>
#include "error.h"

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
} samplemap_header;

typedef struct samplemap {
    samplemap_header header;
    samplemap_record *records;     /* header.faces of them */
} samplemap;

/* Number of chunks and the rows of chunk k's face layout (its image has one row more, see
   povmesh.h for the row work-around). */
long long samplemap_chunk_count(const samplemap_header *h);
int samplemap_chunk_rows(const samplemap_header *h, long long chunk);

/* Writing: reserve the header, append records, then write the header once faces is known. */
int samplemap_begin(FILE *fp);
int samplemap_append(FILE *fp, const samplemap_record *records, size_t count);
int samplemap_finish(FILE *fp, const samplemap_header *h);

int samplemap_read(const char *path, samplemap *out, l2p_error *err);
void samplemap_free(samplemap *m);

#endif
