/* Shared test support: running the built binary, reading its outputs back. */
#ifndef LENS2POV_TEST_SUPPORT_H
#define LENS2POV_TEST_SUPPORT_H

#include <stdbool.h>
#include <stddef.h>
#include "base/vec3.h"
#include "camera/camera.h"
#include "field/povuv.h"

#ifndef LENS2POV_SOURCE_DIR
#define LENS2POV_SOURCE_DIR "."
#endif
#define LENS_DIR LENS2POV_SOURCE_DIR "/lenses/"

/* A reference grid's density: FULL in the normal build; under AddressSanitizer, where a ray
   costs some fifty times more, the coarser ASAN (the memory checks see the same code; the
   normal build holds the fine tolerance). */
#ifdef __SANITIZE_ADDRESS__
#define FULL_OR_ASAN(full, asan) (asan)
#else
#define FULL_OR_ASAN(full, asan) (full)
#endif

/* Runs the lens2pov binary ($LENS2POV, else build/lens2pov) with a NULL-terminated argument
   list; stdout and stderr go to files that *out and *errout receive (malloc'd, may be NULL).
   Returns the exit status. */
int run_lens2pov(char **out, char **errout, ...);
/* Runs it and fails the test, naming `what` and with its messages, unless it exits 0. */
void run_lens2pov_ok(const char *what, ...);
/* The same with the arguments in a NULL-terminated array. */
int run_lens2pov_argv(char **out, char **errout, char *const args[]);

/* Runs a shell command that runs POV-Ray (system()), up to six times while it fails, after
   pauses of 0.1 s doubling: POV-Ray 3.7 sometimes times out starting its threads on a loaded
   machine, and lens2pov's runner starts such a run again too (docs/povray.md). Returns the
   last status. */
int system_povray(const char *command);

/* A fresh folder under /tmp, removed with everything in it when the test's process exits
   (the name is in a buffer the next call reuses), and a path inside a folder (static buffers
   rotate). */
const char *test_tmpdir(void);
const char *tmp_path(const char *dir, const char *name);

/* Writes text, or length bytes, to path (exact bytes); reads a whole file (malloc'd, with a
   NUL after it; NULL when it cannot be read). */
void write_text(const char *path, const char *text);
/* Fails the test unless the picture at path has attribute key, with the value want. */
void expect_attribute(const char *path, const char *key, const char *want);
void write_bytes(const char *path, const char *data, size_t length);
char *read_text(const char *path, size_t *length);

bool file_exists(const char *path);

/* A number of `lens2pov info --json`'s output, "key": value; fails the test when there is
   none. */
double json_number(const char *json, const char *key);

/* Removes a folder under /tmp with everything in it. */
void remove_tree(const char *dir);

/* The entries of a folder (without . and ..) whose names start with prefix (NULL: all);
   listing, when not NULL, gets their names, space-separated. */
int count_entries(const char *dir, const char *prefix, char *listing, size_t size);

/* A camera of lenses/NAME.dat with options o (NULL: the defaults); fails the test on error. */
void test_camera(camera *c, const char *lens_name, const camera_options *o);

/* One row of the --rays CSV. */
typedef struct csv_ray {
    double raster_x, raster_y, film_x, film_y;
    vec3 o, d;
    double weight;
} csv_ray;
csv_ray *read_rays_csv(const char *path, size_t *count);

/* One row of a field render's --rays CSV: the columns above, then where it is rendered. */
typedef struct field_csv_ray {
    csv_ray ray;
    int image, image_x, image_y;
} field_csv_ray;
field_csv_ray *read_field_rays_csv(const char *path, size_t *count);

/* A distribution-3 include (vertex_vectors, normal_vectors, uv_vectors, face_indices) as
   POV-Ray reads it, through the model of src/field/povuv.c; fails the test when it cannot. */
void read_field_include(const char *text, povuv_mesh *pm);

/* The rays an include gives POV-Ray: vertices as float32, origin = centroid, direction =
   normalize((P3-P1) x (P2-P1)), then the scale and translate, world space in scene units. */
typedef struct pov_ray { vec3 o, d; } pov_ray;
pov_ray *read_include_as_povray(const char *path, size_t *count);

/* Where channel c of an image dominates (above 0.05 and twice the other two together): the
   weighted centre in pixels, (0, 0) the top-left corner; found false when nowhere. */
typedef struct marker_centroid { double x, y; bool found; } marker_centroid;
marker_centroid image_marker(const char *path, int c);

#endif
