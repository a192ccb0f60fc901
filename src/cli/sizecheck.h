/* Estimates, before any tracing, of the disk and memory a trace or render will take, from the
   options alone, and the refusal of a request that cannot fit (--no-size-check lets it
   through). With pixel sampling every sample of the crop is counted as a face: an upper
   bound, since the lens blocks some. With field sampling POV-Ray gets far fewer faces than
   samples, estimated from the crop's sides and the tolerance, and each render's picture is
   its own size (docs/fields.md, "Memory and disk"); every pixel of every sub-image is counted
   as rendered. */
#ifndef LENS2POV_SIZECHECK_H
#define LENS2POV_SIZECHECK_H

#include "cli/cli.h"

/* Bytes a face costs in each file, from real outputs of the four lenses (rounded up): the
   include's text, the sample map's record, the --rays CSV row, and a render's EXR pixel
   (uncompressed half RGB, more than POV-Ray's compressed files take). */
#define SIZE_INCLUDE_BYTES_PER_FACE 100.0
#define SIZE_MAP_BYTES_PER_FACE 16.0
#define SIZE_CSV_BYTES_PER_FACE 230.0
#define SIZE_EXR_BYTES_PER_FACE 8.0
/* POV-Ray's .pov-state beside a render in progress, which holds the blocks rendered so far (five
   floats a pixel; 118 MB for 6 M rendered pixels measured) until the render ends. */
#define SIZE_POVRAY_STATE_BYTES_PER_PIXEL 20.0

/* Field sampling, from real renders of the four lenses (rounded up; docs/fields.md): a
   sub-image's faces at the default tolerance for each pixel of the crop's width plus height,
   with a margin over the densest lens; a face in a distribution-3 include (its share of the
   vertices, normals and UVs with it); a render's ini, wrapper scene and POV-Ray log; a CSV
   row, which adds the render pixel's three integers to a pixel-sampling row; and POV-Ray
   3.7.0.10's memory for a face of a distribution-3 camera mesh and for a pixel of its
   picture (docs/povray.md). */
#define SIZE_FIELD_FACES_PER_SIDE_PIXEL 20.0
/* The same for a lens of the common kind: the bundled lenses take 0.1 (the macro at f/8) to 17
   (the DX fisheye) faces a side pixel, 1.3 in the median. The disk is refused at this, and
   only warned of at the bound above: a run that fills the disk fails and keeps its outputs. */
#define SIZE_FIELD_FACES_TYPICAL_PER_SIDE_PIXEL 2.5
#define SIZE_FIELD_INCLUDE_BYTES_PER_FACE 100.0
#define SIZE_FIELD_RENDER_FILES_BYTES 65536.0
#define SIZE_FIELD_CSV_BYTES_PER_ROW (SIZE_CSV_BYTES_PER_FACE + 20.0)
#define SIZE_FIELD_POVRAY_BYTES_PER_FACE 200.0
#define SIZE_POVRAY_BYTES_PER_PIXEL 40.0
/* What lens2pov keeps for each sub-image besides its faces until the renders are written: its
   record, its mesh's five allocations and its place in the map (about 1.1 kB on a 2x2 film at
   100,000 spp, where little else counts). */
#define SIZE_FIELD_BYTES_PER_SUBIMAGE 2048.0

typedef struct size_estimate {
    double faces;                 /* at most (field sampling: estimated) */
    double table_bytes;           /* include, ini and sample map; field: includes, inis, and the
                                     map's weights where written (trace, render's kept folder) */
    double csv_bytes;             /* --rays, 0 without */
    double renders_bytes;         /* render: the chunks' (field: the renders') EXR files, and
                                     POV-Ray's state files of the renders at once */
    double memory_bytes;          /* render: lens2pov itself, and POV-Ray's processes at once
                                     or lens2pov's own work */
    double povray_process_bytes;  /* render: one POV-Ray process, at most */
    bool csv_in_workspace;        /* the CSV is written in the workspace, then moved to --rays */
} size_estimate;

/* The estimate for the options of c (pixel or field sampling, c->field_sampling); jobs:
   POV-Ray processes at once (render), 0 for trace. */
size_estimate size_estimate_of(const cli *c, int jobs);

/* trace: the table in -o's folder and the CSV in its own fit on their file systems. */
int size_check_trace(const cli *c, l2p_error *err);

/* render: the workspace (work_dir, the folder the temporary files go to) holds the table, the
   renders and the CSV, the CSV also fits where --rays goes, and POV-Ray's processes (or the
   development after them) fit in the memory available. */
int size_check_render(const cli *c, const char *work_dir, int jobs, l2p_error *err);

/* The same once an animation's frames are known: a picture a frame, and with --keep-temp
   every table and every frame's renders kept. */
int size_check_frames(const cli *c, const char *work_dir, int jobs, int frames, int tables,
                      l2p_error *err);

#endif
