#include "render.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>
#include "camera.h"
#include "develop.h"
#include "image_io.h"
#include "outfile.h"
#include "povray.h"
#include "raytable.h"

static int check_inputs(const cli *c, l2p_error *err)
{
    if (c->positional_count != 2)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "render takes SCENE.pov LENS (see --help)");
    if (!c->output)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "-o is required");
    const char *dot = strrchr(c->output, '.');
    if (!dot || (strcasecmp(dot, ".png") && strcasecmp(dot, ".exr") && strcasecmp(dot, ".tif") &&
                 strcasecmp(dot, ".tiff")))
        return l2p_fail(err, L2P_BAD_INPUT, c->output, 0, "unknown image type (use .png, .exr or .tif)");
    FILE *f = fopen(c->positional[0], "r");
    if (!f)
        return l2p_fail(err, L2P_BAD_INPUT, c->positional[0], 0, "cannot read: %s", strerror(errno));
    fclose(f);
    return L2P_OK;
}

static int number_of_cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

/* Chunks small enough for the memory budget, as many as a multiple of the jobs and with the
   same number of faces, so that the parses, which POV-Ray does on one thread, run side by side
   and end together (3 chunks on 2 jobs would take two rounds for one and a half chunks' work). */
static long long chunk_faces_for(const camera *cam, const cli *c, int jobs)
{
    const long long budget = raytable_faces_for_memory(c->memory_mb);
    long long faces = raytable_count_faces(cam);
    if (faces < 0)   /* out of memory to count: every sample, an upper bound */
        faces = (long long)(cam->crop_x1 - cam->crop_x0) * (cam->crop_y1 - cam->crop_y0) *
                cam->samples.spp;
    const long long needed = (faces + budget - 1) / budget;
    const long long chunks = needed < 1 ? jobs : (needed + jobs - 1) / jobs * jobs;
    const long long per_chunk = (faces + chunks - 1) / chunks;
    return per_chunk > 0 ? per_chunk : 1;
}

typedef struct workspace {
    char dir[4096];
    bool keep;
} workspace;

static int make_workspace(workspace *w, const cli *c, l2p_error *err)
{
    w->keep = c->keep_temp != NULL;
    if (w->keep) {
        snprintf(w->dir, sizeof w->dir, "%s", c->keep_temp);
        if (mkdir(w->dir, 0777) != 0 && errno != EEXIST)
            return l2p_fail(err, L2P_BAD_INPUT, w->dir, 0, "cannot make folder: %s", strerror(errno));
        return L2P_OK;
    }
    const char *tmp = getenv("TMPDIR");
    snprintf(w->dir, sizeof w->dir, "%s/lens2pov.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(w->dir))
        return l2p_fail(err, L2P_FAILED, w->dir, 0, "cannot make a temporary folder: %s",
                        strerror(errno));
    outfile_track(w->dir);
    return L2P_OK;
}

/* Removes the workspace and its files (nothing in it has folders). */
static void remove_workspace(const workspace *w)
{
    if (w->keep)
        return;
    DIR *d = opendir(w->dir);
    if (d) {
        char path[8192];
        for (struct dirent *e; (e = readdir(d)) != NULL;)
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                snprintf(path, sizeof path, "%s/%s", w->dir, e->d_name);
                unlink(path);
            }
        closedir(d);
    }
    rmdir(w->dir);
    outfile_untrack(w->dir);
}

static char *chunk_exr_path(const char *include_path)
{
    char *p = strdup(include_path);
    if (p)
        memcpy(p + strlen(p) - 3, "exr", 3);
    return p;
}

/* POV-Ray on every chunk, then develop. */
static int render_chunks(const cli *c, const workspace *w, const povmesh_chunk_info *chunks,
                         int count, int jobs, l2p_error *err)
{
    povray_chunk *pc = calloc((size_t)count, sizeof *pc);
    const char **exrs = calloc((size_t)count, sizeof *exrs);
    int st = pc && exrs ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int i = 0; i < count && !st; i++) {
        pc[i].include_path = chunks[i].include_path;
        pc[i].ini_path = chunks[i].ini_path;
        pc[i].faces = chunks[i].faces;
        pc[i].output_exr = exrs[i] = chunk_exr_path(chunks[i].include_path);
        if (!exrs[i])
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    /* Every process may use every core: the chunks cost the same to parse but not to shade
       (sky against floor), and a process left shading alone then gets the idle cores. With a
       core each, bench.pov took 8.0-9.0 s against 6.9-7.5 s (four turns, 2 cores). */
    const povray_options po = {c->positional[0], w->dir, jobs, number_of_cores(), !c->quiet, NULL};
    if (!st)
        st = povray_render_chunks(pc, count, &po, err);
    char map_path[8192];
    snprintf(map_path, sizeof map_path, "%s/rays.map", w->dir);
    samplemap map;
    if (!st && !(st = samplemap_read(map_path, &map, err))) {
        st = develop_files(&map, exrs, count, c->output, err);
        samplemap_free(&map);
    }
    for (int i = 0; exrs && i < count; i++)
        free((char *)exrs[i]);
    free(exrs);
    free(pc);
    return st;
}

int render_command(const cli *c, l2p_error *err)
{
    int st = check_inputs(c, err);
    camera cam;
    if (st || (st = image_io_ready(err)))   /* before the long work that needs it at the end */
        return st;
    lens l;
    if ((st = lens_read(c->positional[1], &l, err)))
        return st;
    if ((st = camera_setup(&cam, &l, &c->cam, err))) {
        camera_free(&cam);
        return st;
    }
    const int jobs = c->jobs > 0 ? c->jobs : number_of_cores();
    workspace w;
    povmesh_chunk_info *chunks = NULL;
    int count = 0;
    if (!(st = make_workspace(&w, c, err))) {
        char prefix[8192];
        snprintf(prefix, sizeof prefix, "%s/rays", w.dir);
        st = raytable_write(&cam, prefix, c->rays_csv, chunk_faces_for(&cam, c, jobs), !c->quiet,
                            &chunks, &count, NULL, err);
        if (!st)
            st = render_chunks(c, &w, chunks, count, jobs, err);
        povmesh_free_chunks(chunks, count);
        remove_workspace(&w);
    }
    camera_free(&cam);
    return st;
}
