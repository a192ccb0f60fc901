/* Estimates, before any tracing, of the disk and memory a trace or render will take, from the
   options alone, and the refusal of a request that cannot fit (--no-size-check lets it
   through). Every sample of the crop is counted as a face: an upper bound, since the lens
   blocks some. */
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

typedef struct size_estimate {
    double faces;                 /* at most */
    double table_bytes;           /* include, ini and sample map */
    double csv_bytes;             /* --rays, 0 without */
    double renders_bytes;         /* render: the chunks' EXR files */
    double memory_bytes;          /* render: POV-Ray's processes at once, or developing */
} size_estimate;

/* The estimate for the options of c; jobs: POV-Ray processes at once (render), 0 for trace. */
size_estimate size_estimate_of(const cli *c, int jobs);

/* trace: the table in -o's folder and the CSV in its own fit on their file systems. */
int size_check_trace(const cli *c, l2p_error *err);

/* render: the workspace (work_dir, the folder the temporary files go to) holds the table, the
   renders and the CSV, the CSV also fits where --rays goes, and POV-Ray's processes (or the
   development after them) fit in the memory available. */
int size_check_render(const cli *c, const char *work_dir, int jobs, l2p_error *err);

#endif
