#include "cli/sizecheck.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/sysinfo.h>
#include "field/field_render.h"
#include "field/field_files.h"
#include "field/fieldpack.h"
#include "field/fieldpass.h"
#include "field/subimage.h"
#include "raytable/raytable.h"

/* What a POV-Ray process takes with an empty scene; what render takes before any work, the
   image library loaded (OpenImageIO and the libraries it brings: about 131 MiB resident for a
   16x12 film), through every phase; and what developing keeps a film pixel in (its sums),
   besides the faces. */
#define POVRAY_BASE_BYTES (16.0 * 1048576.0)
#define RENDER_BASE_BYTES (160.0 * 1048576.0)
#define DEVELOP_BYTES_PER_PIXEL 32.0

static void crop_size(const camera_options *o, int *w, int *h)
{
    *w = o->crop_x1 ? o->crop_x1 - o->crop_x0 : o->width;
    *h = o->crop_y1 ? o->crop_y1 - o->crop_y0 : o->height;
}

static double crop_pixels(const camera_options *o)
{
    int w, h;
    crop_size(o, &w, &h);
    return (double)w * h;
}

/* POV-Ray's processes at once, their chunks cut as render cuts them (chunk_faces_for), or
   developing after them, whichever takes more; on disk the chunks' EXRs and the state files of
   the chunks at once. */
static void render_sizes(const cli *c, double faces, double pixels, int jobs, size_estimate *e)
{
    const double budget = (double)raytable_faces_for_memory(c->memory_mb);
    const double chunks = jobs * ceil(ceil(faces / budget) / jobs);
    const double chunk_faces = faces / chunks;
    const double at_once = chunks < jobs ? chunks : jobs;
    e->renders_bytes = faces * SIZE_EXR_BYTES_PER_FACE + at_once * chunk_faces * SIZE_POVRAY_STATE_BYTES_PER_PIXEL;
    e->povray_process_bytes = chunk_faces * RAYTABLE_POVRAY_BYTES_PER_FACE + POVRAY_BASE_BYTES;
    const double povray = at_once * e->povray_process_bytes;
    const double develop = faces * SIZE_MAP_BYTES_PER_FACE + chunk_faces * 16.0 +
                           pixels * DEVELOP_BYTES_PER_PIXEL;
    e->memory_bytes = RENDER_BASE_BYTES + (povray > develop ? povray : develop);
}

static size_estimate pixel_estimate(const cli *c, int jobs)
{
    const double pixels = crop_pixels(&c->cam);
    const double faces = pixels * c->cam.spp;
    size_estimate e = {.faces = faces, .csv_in_workspace = jobs > 0};
    e.table_bytes = faces * (SIZE_INCLUDE_BYTES_PER_FACE + SIZE_MAP_BYTES_PER_FACE) + 8192.0;
    e.csv_bytes = c->rays_csv ? faces * SIZE_CSV_BYTES_PER_FACE : 0.0;
    if (jobs > 0)
        render_sizes(c, faces, pixels, jobs, &e);
    return e;
}

/* ---------------------------------------------------------------- field sampling */

/* How field_render will lay out the work, from the options: estimates of the faces, and
   bounds of what a render holds whatever the faces turn out to be. */
typedef struct field_layout {
    double pixels, spp;
    double rows;               /* the crop's */
    double subimage_faces;     /* a sub-image's faces, estimated */
    double subimage_pixels;    /* a sub-image's render, had it one of its own */
    double render_faces;       /* a render's faces, at most */
    double render_pixels;      /* a render's picture, at most */
    double typical_render_pixels;   /* and with the faces estimated */
    double at_once;            /* POV-Ray processes at once, at most */
} field_layout;

/* A sub-image's faces. Where the lens passes the rays, the error between vertices h pixels
   apart goes as h^2 / n on a crop n pixels wide (the field's curvature in pixels falls as 1 /
   n), so the spacing the tolerance allows goes as sqrt(n tol) and the faces as n / tol; where
   it blocks some, faces follow the region's edge down to single pixels, also as n. Hence
   faces proportional to width plus height, and to 1 / tolerance below the default (the edges
   stay as fine above it), plus the coarsest grid's; a sub-image with more faces than pixels
   is refused. */
static double field_subimage_faces(const cli *c, int w, int h, double coarsest, double per_side)
{
    const double finer = fmax(1.0, FIELD_DEFAULT_TOLERANCE_PX / c->field_tolerance);
    const double faces = per_side * (w + h) * finer + coarsest;
    return fmax(1.0, fmin(faces, (double)w * h));
}

/* field_render packs consecutive sub-images into a render up to FIELD_FACES_PER_RENDER faces
   and FIELD_PIXELS_PER_RENDER pixels, and at most spp / jobs (rounded up), at least one. Its
   picture, 2^a x 2^b, is never larger than its sub-images' own renders' pictures together;
   every later render has the first one's size. That bound holds a render's memory; its disk,
   which runs out more gently (the run fails, the outputs kept), is taken at the count the
   packing chooses for the estimated faces: the pixels' bound alone counted 30 times the disk
   renders at 640 x 480 take, and refused them on a small /tmp. */
static field_layout field_layout_of(const cli *c, int jobs, double per_side)
{
    int w, h;
    crop_size(&c->cam, &w, &h);
    field_layout l = {.pixels = (double)w * h, .spp = c->cam.spp, .rows = h};
    const double cells = ceil((w - 1.0) / FIELD_COARSEST_CELL) * ceil((h - 1.0) / FIELD_COARSEST_CELL);
    const double coarsest = fmax(1.0, 2.0 * cells);
    const double most = ceil(l.spp / (jobs > 0 ? jobs : 1));
    l.subimage_faces = field_subimage_faces(c, w, h, coarsest, per_side);
    l.subimage_pixels = (field_render_size(w) + 1.0) * (field_render_size(h) + 1.0);
    const double fit = fmax(1.0, floor(FIELD_PIXELS_PER_RENDER / l.subimage_pixels));
    l.render_faces = fmin(most * l.subimage_faces, fmax(FIELD_FACES_PER_RENDER, l.subimage_faces));
    l.render_pixels = fmin(most, fit) * l.subimage_pixels;
    /* as field_pack_grid packs sub-images of the estimated faces, at the larger overhead */
    const int spp = c->cam.spp, renders = field_pack_count_estimate(spp, w, h, jobs > 0 ? jobs : 1,
                                                                     l.subimage_faces, FIELD_FRAME_S);
    l.typical_render_pixels = fmin(l.render_pixels, ceil((double)spp / renders) * l.subimage_pixels);
    l.at_once = fmin(jobs > 0 ? jobs : 1, l.spp);
    return l;
}

/* lens2pov keeps every sub-image's mesh until the renders are written: a face (field_mesh's
   tri) and a vertex (pos, nrm, pix) a face, a margin over the half as many vertices as
   faces of a triangulated grid, and SIZE_FIELD_BYTES_PER_SUBIMAGE; and until it is developed,
   its weights (fieldpass.h): a float a pixel while all of them fit FIELD_WEIGHTS_KEPT_MB (or
   the environment's bound), else where its pixels pass, four runs a row of the crop (more
   only with more faces; never more than the floats).
   Meanwhile it builds on jobs threads (a crop pixel's ray, weight, flags, prefix sum and
   vertex index, subimage.c), waits for POV-Ray's processes, then develops (the sums, a
   sub-image's weights, a render's picture as float RGBA). */
static void field_memory(const field_layout *l, int jobs, size_estimate *e)
{
    const double mesh_face = 3 * sizeof(int) + 6 * sizeof(float) + 2 * sizeof(double);
    const double weights = l->spp * l->pixels * sizeof(float);
    const double runs = l->spp * 4 * l->rows * 2 * sizeof(long long);
    double bound;
    field_weights_kept_bytes(&bound, NULL);   /* render refuses a bad one before this */
    const double kept = weights <= bound ? weights : fmin(runs, weights);
    const double meshes = l->spp * (l->subimage_faces * mesh_face + SIZE_FIELD_BYTES_PER_SUBIMAGE);
    const double build = jobs * l->pixels * (sizeof(ray) + sizeof(float) + 2 + 2 * sizeof(int));
    e->povray_process_bytes = POVRAY_BASE_BYTES +
                              l->render_faces * SIZE_FIELD_POVRAY_BYTES_PER_FACE +
                              l->render_pixels * SIZE_POVRAY_BYTES_PER_PIXEL;
    const double povray = l->at_once * e->povray_process_bytes;
    const double develop = l->pixels * (DEVELOP_BYTES_PER_PIXEL + sizeof(float)) +
                           l->render_pixels * 4 * sizeof(float);
    e->memory_bytes = RENDER_BASE_BYTES + meshes + kept + fmax(build, fmax(povray, develop));
}

/* The workspace holds each render's include and ini (and POV-Ray's wrapper scene and log: at
   most a render a sub-image) and the renders' EXRs; trace's map, and render's when the folder
   is kept, each sub-image's weights (a float a crop pixel; render keeps them off the disk,
   fieldpass.h); --rays goes straight to its own folder. A render's EXR goes once it is
   developed (field_povray.c) unless the folder is kept: renders are developed in their order
   as they come, so besides the one each POV-Ray process is writing, about one a process waits
   for those before it. With POV-Ray's own options a frame's EXRs wait for the whole frame. */
static size_estimate field_estimate(const cli *c, int jobs, double per_side)
{
    const field_layout l = field_layout_of(c, jobs, per_side);
    size_estimate e = {.faces = l.spp * l.subimage_faces};
    const bool weights_on_disk = jobs == 0 || c->keep_temp;
    e.table_bytes = e.faces * SIZE_FIELD_INCLUDE_BYTES_PER_FACE +
                    l.spp * (SIZE_FIELD_RENDER_FILES_BYTES +
                             (weights_on_disk ? l.pixels * sizeof(float) : 0.0));
    e.csv_bytes = c->rays_csv ? l.spp * l.pixels * SIZE_FIELD_CSV_BYTES_PER_ROW : 0.0;
    if (jobs > 0) {
        const double all = l.spp * l.subimage_pixels;
        const double pictures = c->keep_temp || c->povray_args
                                    ? all
                                    : fmin(all, 2 * l.at_once * l.typical_render_pixels);
        e.renders_bytes = pictures * SIZE_EXR_BYTES_PER_FACE +
                          l.at_once * l.typical_render_pixels * SIZE_POVRAY_STATE_BYTES_PER_PIXEL;
        field_memory(&l, jobs, &e);
    }
    return e;
}

size_estimate size_estimate_of(const cli *c, int jobs)
{
    return c->field_sampling ? field_estimate(c, jobs, SIZE_FIELD_FACES_PER_SIDE_PIXEL)
                             : pixel_estimate(c, jobs);
}

/* The estimate whose disk is refused: field sampling's at the common lens's faces. */
static size_estimate disk_estimate_of(const cli *c, int jobs)
{
    return c->field_sampling ? field_estimate(c, jobs, SIZE_FIELD_FACES_TYPICAL_PER_SIDE_PIXEL)
                             : pixel_estimate(c, jobs);
}

/* "845 GB", "12.3 MB". */
static const char *human(double bytes, char buf[32])
{
    static const char *const unit[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
    int u = 0;
    while (bytes >= 1000.0 && u < 6) {
        bytes /= 1000.0;
        u++;
    }
    snprintf(buf, 32, "%.3g %s", bytes, unit[u]);
    return buf;
}

/* The folder a file (or, when is_dir, a folder to be made or kept) goes into. */
static char *folder_for(const char *path, bool is_dir)
{
    struct stat sb;
    if (is_dir && stat(path, &sb) == 0)
        return strdup(path);
    const char *slash = strrchr(path, '/');
    return slash ? strndup(path, (size_t)(slash - path) + 1) : strdup(".");
}

/* Bytes the user may still write on folder's file system and its device; false when unknown
   (then nothing is refused). */
static bool free_bytes(const char *folder, double *bytes, dev_t *dev)
{
    struct statvfs v;
    struct stat sb;
    if (statvfs(folder, &v) != 0 || stat(folder, &sb) != 0)
        return false;
    *bytes = (double)v.f_bavail * (double)v.f_frsize;
    *dev = sb.st_dev;
    return true;
}

/* Outputs by folder: their bytes are summed on each file system before comparing. */
typedef struct disk_need {
    const char *path;
    bool is_dir;
    double bytes;
} disk_need;

static int refuse(const cli *c, const char *what, double need, double have, const char *where,
                  l2p_error *err)
{
    char a[32], b[32];
    const camera_options *o = &c->cam;
    /* memory also goes with the POV-Ray processes at once, disk not */
    return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                    "%.0f pixels x --spp %d is up to %.3g rays: about %s of %s%s%s, %s available; "
                    "give fewer pixels or samples%s (or --no-size-check to try anyway)",
                    crop_pixels(o), o->spp, crop_pixels(o) * o->spp, human(need, a), what,
                    where ? " in " : "", where ? where : "", human(have, b),
                    where ? "" : ", or fewer --jobs");
}

static int check_disk(const cli *c, const disk_need *needs, int n, bool warn_only, l2p_error *err)
{
    double have[8], total[8];
    dev_t dev[8];
    char *folder[8] = {0};
    int st = L2P_OK;
    for (int i = 0; i < n && i < 8; i++) {
        folder[i] = folder_for(needs[i].path, needs[i].is_dir);
        total[i] = 0.0;
        if (folder[i] && !free_bytes(folder[i], &have[i], &dev[i])) {
            free(folder[i]);   /* not there (yet): whatever writes to it says so */
            folder[i] = NULL;
        }
        if (!folder[i])
            continue;
        for (int k = 0; k <= i; k++)   /* summed into the first need on the same device */
            if (folder[k] && dev[k] == dev[i]) {
                total[k] += needs[i].bytes;
                break;
            }
    }
    for (int i = 0; !st && i < n && i < 8; i++) {
        char a[32], b[32];
        if (!folder[i] || !(total[i] > have[i]))
            continue;
        if (!warn_only)
            st = refuse(c, "disk", total[i], have[i], folder[i], err);
        else if (!c->quiet)
            fprintf(stderr, "lens2pov: warning: through a lens whose ray field needs many faces "
                    "this may take up to %s of disk in %s, %s available\n", human(total[i], a),
                    folder[i], human(have[i], b));
    }
    for (int i = 0; i < n && i < 8; i++)
        free(folder[i]);
    return st;
}

/* MemAvailable from /proc/meminfo, else what sysinfo calls free; 0 when unknown. */
static double available_memory(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    char line[256];
    double kb = 0.0;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1)
            break;
    if (f)
        fclose(f);
    if (kb > 0.0)
        return kb * 1024.0;
    struct sysinfo si;
    return sysinfo(&si) == 0 ? ((double)si.freeram + (double)si.bufferram) * si.mem_unit : 0.0;
}

int size_check_trace(const cli *c, l2p_error *err)
{
    if (c->no_size_check)
        return L2P_OK;
    int st = L2P_OK;
    for (int bound = 0; bound < (c->field_sampling ? 2 : 1) && !st; bound++) {
        const size_estimate e = bound ? size_estimate_of(c, 0) : disk_estimate_of(c, 0);
        const disk_need needs[] = {{c->output, false, e.table_bytes},
                                   {c->rays_csv ? c->rays_csv : c->output, false, e.csv_bytes}};
        st = check_disk(c, needs, 2, bound, err);
    }
    return st;
}

/* frames pictures, each from one table's renders; a kept folder (--keep-temp) keeps the
   tables and every frame's renders, else one of each is there at a time. */
static int check_render(const cli *c, const char *work_dir, int jobs, int frames, int tables,
                        l2p_error *err)
{
    if (c->no_size_check)
        return L2P_OK;
    const bool kept = c->keep_temp != NULL;
    int st = L2P_OK;
    for (int bound = 0; bound < (c->field_sampling ? 2 : 1) && !st; bound++) {
        const size_estimate d = bound ? size_estimate_of(c, jobs) : disk_estimate_of(c, jobs);
        /* Pixel sampling writes the CSV in the workspace, then moves (or copies) it to --rays. */
        const double csv_work = d.csv_in_workspace ? d.csv_bytes : 0.0;
        const double work = d.table_bytes * (kept ? tables : 1) + d.renders_bytes * (kept ? frames : 1);
        const disk_need needs[] = {{work_dir, true, work + csv_work},
                                   {c->rays_csv ? c->rays_csv : c->output, false, d.csv_bytes},
                                   {c->output, false, crop_pixels(&c->cam) * 16.0 * frames}};
        st = check_disk(c, needs, 3, bound, err);
    }
    const size_estimate e = size_estimate_of(c, jobs);
    const double have = available_memory();
    if (!st && have > 0.0 && e.memory_bytes > have)
        st = refuse(c, "memory (POV-Ray's processes at once, or developing)", e.memory_bytes,
                    have, NULL, err);
    return st;
}

int size_check_render(const cli *c, const char *work_dir, int jobs, l2p_error *err)
{
    return check_render(c, work_dir, jobs, 1, 1, err);
}

int size_check_frames(const cli *c, const char *work_dir, int jobs, int frames, int tables,
                      l2p_error *err)
{
    return frames > 1 ? check_render(c, work_dir, jobs, frames, tables, err) : L2P_OK;
}
