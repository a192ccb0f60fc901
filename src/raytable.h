/* Tracing every film sample of the crop into the ray table. */
#ifndef LENS2POV_RAYTABLE_H
#define LENS2POV_RAYTABLE_H

#include <stdbool.h>
#include "camera.h"
#include "povmesh.h"

typedef struct raytable_stats {
    long long samples;   /* traced */
    long long passed;    /* written: the rest the lens blocked */
    double seconds;
} raytable_stats;

/* Traces crop pixels x spp samples and writes PREFIX.inc/.ini/.map (and csv_path when not
   NULL); chunk_faces as for povmesh_open. All outputs appear together or not at all. */
int raytable_write(const camera *c, const char *prefix, const char *csv_path,
                   long long chunk_faces, bool progress, povmesh_chunk_info **chunks,
                   int *chunk_count, raytable_stats *stats, l2p_error *err);

#endif
