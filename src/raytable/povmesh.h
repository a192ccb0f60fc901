/* Writing the ray table for POV-Ray's mesh_camera: one triangle per ray, whose centroid is the
   ray's origin and whose normal, in POV-Ray's reversed winding, normalize((P3-P1) x (P2-P1)),
   is its direction (see docs/povray.md). Also writes the settings
   (.ini), the sample map (.map) and, on request, the ray table as CSV.

   Layout for distribution 0 at one ray per pixel: faces fill rows of packed_width pixels.
   POV-Ray 3.7.0.10 renders image row y with face row max(y - 1, 0) (FS#254), so every image is
   one row taller than its face rows and its row 0 is dropped when developing. */
#ifndef LENS2POV_POVMESH_H
#define LENS2POV_POVMESH_H

#include <stdbool.h>
#include <stdint.h>
#include "camera/camera.h"
#include "base/error.h"
#include "image/samplemap.h"

typedef struct emitted_ray {
    int px, py;                 /* film pixel */
    double offset_x, offset_y;  /* position in the pixel, [0, 1) */
    vec3 film_point;            /* camera space, mm */
    ray out;                    /* camera space, mm, origin on the lens's front */
    double weight;
    int band;                   /* with dispersion: the wavelength's band (spectrum.h) */
    double wavelength_nm;       /* with dispersion, else not read */
} emitted_ray;

typedef struct povmesh_emitter povmesh_emitter;

/* Opens the outputs under temporary names. chunk_faces 0: one chunk, written as PREFIX.inc and
   PREFIX.ini; otherwise chunks of chunk_faces faces, rounded up to whole packed rows of up to
   1024 faces by fewer than one face a row (the last chunk holds the rest), PREFIX.c000.inc,
   PREFIX.c000.ini, ... csv_path may be NULL. */
int povmesh_open(povmesh_emitter **e, const camera *c, const char *prefix, const char *csv_path,
                 long long chunk_faces, l2p_error *err);

/* Faces are written in two steps, so that threads can format rays side by side while one of
   them appends in face order. Formatting reads the emitter and writes only its arguments.

   Neighbouring rays share a triangle edge where float32 can hold them as well as alone (see
   povface.h): four vertices for two faces, which POV-Ray parses in two thirds of the time.
   A face's kind (enum face_kind, facelist.h) tells the appender where its vertices are. */
enum { POVMESH_RAY_TEXT_MAX = 512, POVMESH_CSV_MAX = 560 };

/* Faces formatted and not yet appended, in face order: each one's vertex text (one after the
   other), its kind, its sample-map record and band and, when the emitter writes CSV, its CSV row. */
typedef struct formatted_faces {
    char *text;
    size_t text_len, *length;
    unsigned char *kind;
    samplemap_record *record;
    uint32_t *band;             /* each face's wavelength band (read with dispersion only) */
    char *csv;
    size_t csv_len, *csv_length;
    long long count;
} formatted_faces;

/* Formats n rays, consecutive faces, onto the end of f, which has room for them (n more
   entries, n * POVMESH_RAY_TEXT_MAX text bytes, n * POVMESH_CSV_MAX CSV bytes). */
void povmesh_format_rays(const povmesh_emitter *e, const emitted_ray *r, int n,
                         formatted_faces *f);

/* Appends f's faces, in order. */
int povmesh_append(povmesh_emitter *e, const formatted_faces *f, l2p_error *err);
bool povmesh_wants_csv(const povmesh_emitter *e);

/* Called as each chunk is complete, with its files already renamed into place (not with the
   others at the end), so that a renderer can start on it while the rest are written. A
   nonzero return stops the writing: the append or close fails with L2P_FAILED. */
typedef int (*povmesh_chunk_hook)(void *ctx, int index);
void povmesh_set_chunk_hook(povmesh_emitter *e, povmesh_chunk_hook hook, void *ctx);

/* Every chunk's camera mesh is moved by the transform of this identifier after its own
   translate (the scene declares it before the include: one table placed anew in each frame
   of an animation). The name must stay valid while e writes. */
void povmesh_set_placement(povmesh_emitter *e, const char *transform_name);

/* The name of a chunk's file: PREFIX.EXT, or PREFIX.cNNN.EXT when chunked (malloc'd). */

char *povmesh_chunk_file(const char *prefix, bool chunked, int index, const char *ext);

/* Completes every file and renames them all into place (commit), or removes them; frees e.
   After a commit, *chunk_count (when not NULL) gets the number of chunks written. */
int povmesh_close(povmesh_emitter *e, bool commit, int *chunk_count, l2p_error *err);


/* The sample map header's description of the camera (film, crop, lens, pupil, aperture,
   focus, units); the table's layout fields are left 0. */
void povmesh_camera_header(const camera *c, samplemap_header *h);

#endif
