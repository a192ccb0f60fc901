/* Tracing every film sample of the crop into the ray table. */
#ifndef LENS2POV_RAYTABLE_H
#define LENS2POV_RAYTABLE_H

#include <stdatomic.h>
#include <stdbool.h>
#include "camera/camera.h"
#include "raytable/povmesh.h"

typedef struct raytable_stats {
    long long samples;   /* traced */
    long long passed;    /* written: the rest the lens blocked */
    int chunks;          /* written */
    double seconds;
} raytable_stats;

/* POV-Ray 3.7.0.10's memory per mesh_camera face of a mesh with "hierarchy off", its output
   image included (docs/povray.md); the default budget is 1 GB a process. */
#define RAYTABLE_POVRAY_BYTES_PER_FACE 215.0
#define RAYTABLE_DEFAULT_MEMORY_MB 1024.0

/* Faces per chunk for a POV-Ray memory budget in MB (<= 0: the default). */
long long raytable_faces_for_memory(double memory_mb);

/* The faces raytable_write will write for c: the samples of the crop the lens passes. Traces
   them all on every core (about a fifth of the cost of writing them); -1 out of memory. */
long long raytable_count_faces(const camera *c);

/* For a renderer that starts on each chunk as it is complete: told of each chunk (see
   povmesh_set_chunk_hook), and stopped between rows when *stop becomes true (L2P_FAILED). */
typedef struct raytable_stream {
    povmesh_chunk_hook chunk_done;
    void *ctx;
    const atomic_bool *stop;
} raytable_stream;

/* What to write, and where. */
typedef struct raytable_request {
    const char *prefix;             /* PREFIX.inc, PREFIX.ini, PREFIX.map */
    const char *csv_path;           /* every ray as CSV; NULL: none */
    long long chunk_faces;          /* as for povmesh_open: 0 is one chunk */
    bool progress;                  /* a bar on stderr */
    const raytable_stream *stream;  /* NULL: none */
    const char *placement;          /* see povmesh_set_placement; NULL: none */
} raytable_request;

/* Traces crop pixels x spp samples and writes the table. Without a stream, all outputs appear
   together or not at all. stats may be NULL. */
int raytable_write(const camera *c, const raytable_request *q, raytable_stats *stats,
                   l2p_error *err);

#endif
