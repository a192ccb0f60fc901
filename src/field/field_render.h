/* render --sampling field: the picture as spp sub-images, each the whole crop seen with one
   shared sample and drawn by an adaptive distribution-3 mesh; several sub-images a POV-Ray
   render; developed with each pixel's weight. docs/fields.md has the design. */
#ifndef LENS2POV_FIELD_FIELD_RENDER_H
#define LENS2POV_FIELD_FIELD_RENDER_H

#include <stdbool.h>
#include "base/outfile.h"
#include "camera/camera.h"

/* A picture of a field render: the still, or a frame of the user's animation. */
typedef struct field_frame {
    const char *output;        /* the developed picture */
    const char *placement;     /* the wrapper's #declare of Lens2pov_Placement; NULL: none */
    int number;                /* POV-Ray's frame number; -1: not an animation */
} field_frame;

typedef struct field_render_options {
    const char *scene_path;    /* the user's scene */
    const char *work_dir;      /* the workspace: includes, inis, renders, logs */
    const char *prefix;        /* the workspace's files of this render: PREFIX.map, ... */
    /* The pictures, each seen through the same renders: frames that differ only in where
       the camera stands (placement, the transform the renders' camera is moved by). */
    const field_frame *frames;
    int frame_count;
    int frame_digits;          /* POV-Ray pads frame numbers to this many */
    char *const *povray_args;  /* POV-Ray's options after "--"; NULL: none */
    int povray_arg_count;
    int jobs;                  /* POV-Ray processes at once, and threads building meshes */
    int threads_per_job;       /* +WTn; 0: POV-Ray's default */
    bool progress;
    double tolerance_px;       /* --field-tolerance */
    /* --adaptive: a still (one frame, not an animation's) in two rounds, spp the mean
       (fieldtiles.h); the caller leaves it off with dispersion. */
    bool adaptive;
    outfile *rays_csv;         /* --rays: opened by the caller, written and finished here, not
                                  committed; NULL: none */
    bool *too_fine;            /* set when the failure is a sub-image the tolerance cannot
                                  draw (more faces than pixels, or finer than float32);
                                  NULL: not asked */
    void (*povray_started)(void *ctx);   /* povray_options.started's, with no context */
    bool work_dir_kept;        /* povray_options.work_dir_kept's */
    const char *povray_file_name;   /* povray_options.file_name's: the POV-Ray runs' files */
} field_render_options;

/* --field-tolerance's default, in pixels: no picture shows an error this small. */
#define FIELD_DEFAULT_TOLERANCE_PX 0.05

/* Faces a POV-Ray render holds at most (a sub-image with more gets a render of its own):
   POV-Ray's per-pixel face search grows with the faces in a UV grid cell. */
enum { FIELD_FACES_PER_RENDER = 20000 };

/* A render's picture holds at most this many pixels, or one sub-image's render: about 670 MB
   of POV-Ray at its 40 bytes a pixel. Sub-images of few faces (a gentle field, or none where
   the lens blocks everything) would otherwise be packed by the dozen into one picture. */
#define FIELD_PIXELS_PER_RENDER 16777216.0

/* trace --sampling field: the map and the renders' includes and inis, for POV-Ray and
   `develop` to take from there (docs/fields.md). */
typedef struct field_trace_options {
    const char *prefix;        /* PREFIX.map, PREFIX.fNNN.inc, PREFIX.fNNN.ini (picture .exr) */
    int jobs;                  /* threads building meshes */
    double tolerance_px;
    outfile *rays_csv;         /* as field_render_options's */
} field_trace_options;

/* What a field trace wrote. */
typedef struct field_trace_stats {
    int renders;
    long long faces;
    long long pixels, passed;  /* pixels of all sub-images, and those whose ray passes */
} field_trace_stats;

/* Builds and writes the outputs, every one renamed into place only when all are complete.
   The same refusals as field_render. */
int field_trace(const camera *c, const field_trace_options *o, field_trace_stats *stats,
                l2p_error *err);

/* Builds, writes, renders and develops every frame (field_povray.c). L2P_BAD_INPUT naming
   --sampling pixel when the tolerance is not above 0 or a sub-image would need more faces
   than pixels; POV-Ray's errors as povray_render_chunks gives them. With rays_csv, the caller
   commits it on success. */
int field_render(const camera *c, const field_render_options *o, l2p_error *err);

#endif
