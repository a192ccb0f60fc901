/* Shared test support: running the built binary, reading its outputs back. */
#ifndef LENS2POV_TEST_SUPPORT_H
#define LENS2POV_TEST_SUPPORT_H

#include <stddef.h>
#include "base/vec3.h"

#ifndef LENS2POV_SOURCE_DIR
#define LENS2POV_SOURCE_DIR "."
#endif
#define LENS_DIR LENS2POV_SOURCE_DIR "/lenses/"

/* Runs the lens2pov binary ($LENS2POV, else build/lens2pov) with a NULL-terminated argument
   list; stdout and stderr go to files that *out and *errout receive (malloc'd, may be NULL).
   Returns the exit status. */
int run_lens2pov(char **out, char **errout, ...);

/* A fresh temporary folder under /tmp, and a path inside it (static buffers rotate). */
const char *test_tmpdir(void);
const char *tmp_path(const char *dir, const char *name);

/* Writes text to path (exact bytes). */
void write_text(const char *path, const char *text);
char *read_text(const char *path, size_t *length);

/* One row of the --rays CSV. */
typedef struct csv_ray {
    double raster_x, raster_y, film_x, film_y;
    vec3 o, d;
    double weight;
} csv_ray;
csv_ray *read_rays_csv(const char *path, size_t *count);

/* The rays an include gives POV-Ray: vertices as float32, origin = centroid, direction =
   normalize((P3-P1) x (P2-P1)), then the scale and translate, world space in scene units. */
typedef struct pov_ray { vec3 o, d; } pov_ray;
pov_ray *read_include_as_povray(const char *path, size_t *count);

#endif
