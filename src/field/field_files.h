/* The files of a field render or trace (docs/fields.md): the field map, and for each POV-Ray
   render its include and ini, built from the sub-images; what field_render.c writes and
   field_povray.c renders and develops. */
#ifndef LENS2POV_FIELD_FIELD_FILES_H
#define LENS2POV_FIELD_FIELD_FILES_H

#include "base/outfile.h"
#include "camera/camera.h"
#include "field/field_develop.h"
#include "field/fieldmap.h"
#include "field/fieldpack.h"
#include "field/fieldpass.h"
#include "field/field_render.h"
#include "povray/povray.h"


/* The outputs, under temporary names until committed. */
typedef struct field_files {
    outfile map;               /* the map's file, with its weights, when asked for */
    char *map_path;            /* its final path (outfile forgets it once committed); NULL:
                                  none */
    field_map table;           /* the map in memory, its weights from pass */
    field_pass *pass;          /* each sub-image's weights, kept or to be made again; NULL
                                  unless the request develops */
    const camera *camera;      /* what they are made again with */
    outfile *inc, *ini;
    povray_chunk *chunk;       /* render r's include, ini and picture paths, faces */
    field_render_plan *plans;
    int renders;
    int subimages;             /* the map's */
    const field_piece *pieces; /* the request's */
    camera *piece_camera;      /* with pieces: the camera, narrowed to each as its weights are
                                  made again (field_piece_crop) */
    field_trace_stats stats;
    bool too_fine;             /* failed: a sub-image the tolerance cannot draw (the message
                                  names --sampling pixel) */
} field_files;

typedef struct field_files_request {
    const char *prefix;        /* PREFIX.map, PREFIX.fNNN.inc, PREFIX.fNNN.ini (picture .exr) */
    int jobs;                  /* threads building meshes */
    double tolerance_px;
    /* A transform identifier every render's camera is moved by last (an animation frame's
       placement, declared by the wrapper); NULL: none. */
    const char *placement;
    outfile *rays_csv;         /* --rays: written and finished, not committed; NULL: none */
    /* What a render costs POV-Ray beyond its pixels, as a frame of a run (seconds): what the
       packing weighs against the face search (fieldpack.c, cost_per_sub). */
    double frame_s;
    /* Whether PREFIX.map is written with every sub-image's weights (trace's, and render's
       when its work folder is kept, for develop); render itself develops from the table. */
    bool map_file;
    /* The most bytes of weights kept in memory for render's develop; beyond, they are made
       again where the pixels pass (fieldpass.h). */
    double weights_kept_bytes;
    bool develops;             /* render's: the table gives the weights; trace's has none */
    /* What the sub-images show (adaptive sampling's rounds, fieldtiles.h): count of them,
       sub-image j pieces[j]; pieces NULL: the camera's spp sub-images of the whole crop
       (count 0). A map file takes whole crops alone. Their strata are dealt for
       strata_samples (0: the camera's spp). */
    const field_piece *pieces;
    int count;
    int strata_samples;
    int render_base;           /* the files' first render number: render r is PREFIX.f(base + r) */
} field_files_request;

/* That cost as POV-Ray is, and as lens2pov runs it, its polls shortened (povray_env.h): the
   value that rendered fastest (docs/benchmarks-fields-2.md, "session 11"). */
#define FIELD_FRAME_S 0.25
#define FIELD_FRAME_POLLS_S 0.04

/* Builds the sub-images and writes the map (when asked for), every render's include and ini
   and the CSV, then commits all but the CSV. L2P_BAD_INPUT naming --sampling pixel for a
   tolerance not above 0 or a sub-image that would need more faces than pixels. *out is always
   set; free it with field_files_free, which removes what was not committed. */
int field_files_make(const camera *c, const field_files_request *q, field_files *out,
                     l2p_error *err);
void field_files_free(field_files *f);

/* field_povray.c: f's renders through POV-Ray, each job's as the frames of one run (with
   po's user_args, a still's POV-Ray options: each render a run of its own), each picture
   added to dev (started on f's table) as soon as POV-Ray has closed it. */
int field_render_into(const field_files *f, int jobs, const povray_options *po,
                      field_developer *dev, l2p_error *err);

/* field_adaptive.c: render's still with adaptive sampling (fieldtiles.h), q its request as
   for a uniform render (its map file, when asked for, and its CSV are written at the end,
   of both rounds); the picture goes to out. *too_fine as field_files' of the round that
   failed. */
int field_render_adaptive(const camera *c, const field_files_request *q, const povray_options *po,
                          const char *out, bool *too_fine, l2p_error *err);

#endif
