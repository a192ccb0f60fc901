#include "cli/sizecheck.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/sysinfo.h>
#include "raytable/raytable.h"

/* What a POV-Ray process takes with an empty scene, and what developing keeps a film pixel in
   (its sums), besides the faces. */
#define POVRAY_BASE_BYTES (16.0 * 1048576.0)
#define DEVELOP_BYTES_PER_PIXEL 32.0

static double crop_pixels(const camera_options *o)
{
    const double w = o->crop_x1 ? o->crop_x1 - o->crop_x0 : o->width;
    const double h = o->crop_y1 ? o->crop_y1 - o->crop_y0 : o->height;
    return w * h;
}

/* POV-Ray's processes at once, their chunks cut as render cuts them (chunk_faces_for), or
   developing after them, whichever takes more. */
static double render_memory(const cli *c, double faces, double pixels, int jobs)
{
    const double budget = (double)raytable_faces_for_memory(c->memory_mb);
    const double chunks = jobs * ceil(ceil(faces / budget) / jobs);
    const double chunk_faces = faces / chunks;
    const double at_once = chunks < jobs ? chunks : jobs;
    const double povray = at_once * (chunk_faces * RAYTABLE_POVRAY_BYTES_PER_FACE + POVRAY_BASE_BYTES);
    const double develop = faces * SIZE_MAP_BYTES_PER_FACE + chunk_faces * 16.0 +
                           pixels * DEVELOP_BYTES_PER_PIXEL;
    return povray > develop ? povray : develop;
}

size_estimate size_estimate_of(const cli *c, int jobs)
{
    const double pixels = crop_pixels(&c->cam);
    const double faces = pixels * c->cam.spp;
    size_estimate e = {.faces = faces};
    e.table_bytes = faces * (SIZE_INCLUDE_BYTES_PER_FACE + SIZE_MAP_BYTES_PER_FACE) + 8192.0;
    e.csv_bytes = c->rays_csv ? faces * SIZE_CSV_BYTES_PER_FACE : 0.0;
    if (jobs > 0) {
        e.renders_bytes = faces * SIZE_EXR_BYTES_PER_FACE;
        e.memory_bytes = render_memory(c, faces, pixels, jobs);
    }
    return e;
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
    return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                    "%.0f pixels x --spp %d is up to %.3g rays: about %s of %s%s%s, %s available; "
                    "give fewer pixels or samples (or --no-size-check to try anyway)",
                    crop_pixels(o), o->spp, crop_pixels(o) * o->spp, human(need, a), what,
                    where ? " in " : "", where ? where : "", human(have, b));
}

static int check_disk(const cli *c, const disk_need *needs, int n, l2p_error *err)
{
    double have[8], total[8];
    dev_t dev[8];
    char *folder[8] = {0};
    int st = L2P_OK;
    for (int i = 0; i < n && i < 8; i++) {
        folder[i] = folder_for(needs[i].path, needs[i].is_dir);
        total[i] = 0.0;
        if (!folder[i] || !free_bytes(folder[i], &have[i], &dev[i]))
            continue;
        for (int k = 0; k <= i; k++)   /* summed into the first need on the same device */
            if (folder[k] && dev[k] == dev[i]) {
                total[k] += needs[i].bytes;
                break;
            }
    }
    for (int i = 0; !st && i < n && i < 8; i++)
        if (folder[i] && total[i] > have[i])
            st = refuse(c, "disk", total[i], have[i], folder[i], err);
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
    const size_estimate e = size_estimate_of(c, 0);
    const disk_need needs[] = {{c->output, false, e.table_bytes},
                               {c->rays_csv ? c->rays_csv : c->output, false, e.csv_bytes}};
    return check_disk(c, needs, 2, err);
}

int size_check_render(const cli *c, const char *work_dir, int jobs, l2p_error *err)
{
    if (c->no_size_check)
        return L2P_OK;
    const size_estimate e = size_estimate_of(c, jobs);
    /* The CSV is written in the workspace, then moved (or copied) to --rays. */
    const disk_need needs[] = {{work_dir, true, e.table_bytes + e.renders_bytes + e.csv_bytes},
                               {c->rays_csv ? c->rays_csv : c->output, false, e.csv_bytes},
                               {c->output, false, crop_pixels(&c->cam) * 16.0}};
    int st = check_disk(c, needs, 3, err);
    const double have = available_memory();
    if (!st && have > 0.0 && e.memory_bytes > have)
        st = refuse(c, "memory (POV-Ray's processes at once, or developing)", e.memory_bytes,
                    have, NULL, err);
    return st;
}
