/* `lens2pov plot`: distortion or vignetting against film radius, drawn by gnuplot
   (src/draw/plot.h). The table and gnuplot's script are written in a temporary folder; the
   table is also printed on stdout, the chart renamed into place when complete. */
#include "cli/commands.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "base/outfile.h"
#include "base/tempdir.h"
#include "cli/framing.h"
#include "draw/plot.h"

/* The f-numbers of the vignetting chart after the one asked for (the full opening by default):
   those the lens can stop down to. */
static const double STOPS[] = {4.0, 8.0, 16.0};
enum { MAX_CAMERAS = 4 };

typedef struct plot_job {
    camera cams[MAX_CAMERAS];
    const camera *cam_ptr[MAX_CAMERAS];
    int count;
    char dir[4096];    /* the temporary folder; empty until made */
    char labels[MAX_CAMERAS][32];
} plot_job;

static int load_cameras(const cli *c, bool vignetting, plot_job *j, l2p_error *err)
{
    int st = framing_load_camera(c, c->positional[0], &j->cams[0], err);
    if (st)
        return st;
    j->count = 1;
    cli_warn(c, &j->cams[0], false);
    for (int i = 0; vignetting && i < 3; i++) {
        if (!(STOPS[i] > 1.01 * j->cams[0].f_number))
            continue;
        cli stopped = *c;
        stopped.cam.f_number = STOPS[i];
        stopped.cam.aperture_diameter_mm = NAN;
        if ((st = framing_load_camera(&stopped, c->positional[0], &j->cams[j->count], err)))
            return st;
        j->count++;
    }
    for (int i = 0; i < j->count; i++) {
        j->cam_ptr[i] = &j->cams[i];
        snprintf(j->labels[i], sizeof j->labels[i], "f/%.3g%s", j->cams[i].f_number,
                 i == 0 && isnan(c->cam.f_number) && isnan(c->cam.aperture_diameter_mm) ? " (full)" : "");
    }
    return L2P_OK;
}

static char *path_in(const plot_job *j, const char *name)
{
    static char path[2][4096 + 64];
    static int turn;
    turn ^= 1;
    snprintf(path[turn], sizeof path[turn], "%s/%s", j->dir, name);
    return path[turn];
}

/* Copies a whole file into an open stream. */
static int copy_file(const char *from, FILE *to, l2p_error *err)
{
    FILE *f = fopen(from, "rb");
    if (!f)
        return l2p_fail(err, L2P_FAILED, from, 0, "cannot read gnuplot's output");
    char buffer[65536];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, f)) > 0)
        fwrite(buffer, 1, n, to);
    const int bad = ferror(f) | ferror(to);
    fclose(f);
    return bad ? l2p_fail(err, L2P_FAILED, from, 0, "cannot copy") : L2P_OK;
}

static int write_table(const plot_job *j, bool vignetting, l2p_error *err)
{
    FILE *f = fopen(path_in(j, "table.dat"), "w");
    if (!f)
        return l2p_fail(err, L2P_FAILED, j->dir, 0, "cannot write the table");
    int st = L2P_OK;
    if (vignetting)
        plot_vignetting_table(f, j->cam_ptr, j->count);
    else
        st = plot_distortion_table(f, j->cam_ptr[0], err);
    if (fclose(f) && !st)
        st = l2p_fail(err, L2P_FAILED, j->dir, 0, "cannot write the table");
    return st;
}

/* The lens's name in the chart's title, without what gnuplot's quoted strings would take as
   their end. */
static void title_of(const camera *cam, const char *what, char *title, size_t size)
{
    snprintf(title, size, "%s: %s", cam->lens.name, what);
    for (char *p = title; *p; p++)
        if (*p == '\'' || *p == '\\' || (unsigned char)*p < 32 || (unsigned char)*p > 126)
            *p = '_';
}

static int draw(const cli *c, plot_job *j, bool vignetting, l2p_error *err)
{
    snprintf(j->dir, sizeof j->dir, "%s/lens2pov-plot.XXXXXX", temp_root());
    if (!mkdtemp(j->dir)) {
        j->dir[0] = '\0';
        return l2p_fail(err, L2P_FAILED, NULL, 0, "cannot make a temporary folder in %s: %s",
                        temp_root(), strerror(errno));
    }
    cleanup_track(j->dir);
    char title[256];
    title_of(&j->cams[0], c->what, title, sizeof title);
    const char *labels[MAX_CAMERAS];
    for (int i = 0; i < j->count; i++)
        labels[i] = j->labels[i];
    int st = write_table(j, vignetting, err);
    if (!st)
        st = plot_run_gnuplot(c->what, j->dir, "table.dat", title, labels, j->count, err);
    outfile out;
    if (!st && !(st = outfile_open(&out, c->output, err))) {
        st = copy_file(path_in(j, "plot.png"), out.fp, err);
        if (!st)
            st = outfile_commit(&out, err);
        outfile_discard(&out);
    }
    if (!st)
        st = copy_file(path_in(j, "table.dat"), stdout, err);
    return st;
}

static void remove_dir(plot_job *j)
{
    if (!j->dir[0])
        return;
    static const char *const names[] = {"table.dat", "plot.gp", "plot.png"};
    for (int i = 0; i < 3; i++)
        unlink(path_in(j, names[i]));
    rmdir(j->dir);
    cleanup_untrack(j->dir);
}

int plot_command(const cli *c, l2p_error *err)
{
    int st = cli_expect_arguments(c, 1, true, err);
    if (st)
        return st;
    if (!c->what)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--what distortion|vignetting is required");
    const bool vignetting = !strcmp(c->what, "vignetting");
    if (!vignetting && strcmp(c->what, "distortion"))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                        "--what: expected distortion or vignetting, got '%s'", c->what);
    if ((st = outfile_check_suffix(c->output, ".png", "PNG", err)) || (st = outfile_check_path(c->output, err)))
        return st;
    plot_job *j = calloc(1, sizeof *j);
    if (!j)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    st = load_cameras(c, vignetting, j, err);
    if (!st)
        st = draw(c, j, vignetting, err);
    remove_dir(j);
    for (int i = 0; i < j->count; i++)
        camera_free(&j->cams[i]);
    free(j);
    return st;
}
