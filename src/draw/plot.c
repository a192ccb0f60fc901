#include "draw/plot.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "camera/fieldangle.h"
#include "optics/irradiance.h"
#include "optics/pupil.h"

static double film_radius(const camera *c, int row)
{
    return 0.5 * c->film.diagonal_mm * row / (PLOT_ROWS - 1);
}

/* The field angle of film radius r (camera/fieldangle.h), inside the reach of c's pupil
   (beyond a fisheye's image circle the lens images nothing). */
static bool imaged_angle(const field_angles *f, double r, double *theta)
{
    return r <= f->camera->pupil.reach_mm && field_angles_ray(f, r, theta);
}

int plot_distortion_table(FILE *out, const camera *c, l2p_error *err)
{
    field_angles f;
    if (field_angles_open(&f, c))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    /* Paraxial scale k = r / tan(theta) near the axis: the image height that a distortion-free
       lens (image height proportional to tan(theta)) would give is k tan(theta). */
    const double r0 = 1e-3 * film_radius(c, 1);
    double theta0;
    const double k = imaged_angle(&f, r0, &theta0) ? r0 / tan(theta0) : NAN;
    fprintf(out, "# %s: distortion of the chief ray against k tan(theta), k = %.9g mm\n"
                 "# film_radius_mm field_angle_deg paraxial_height_mm distortion_percent\n",
            c->lens.name, k);
    for (int row = 0; row < PLOT_ROWS; row++) {
        const double r = film_radius(c, row);
        double theta;
        if (row == 0) {
            fprintf(out, "0 0 0 0\n");
            continue;
        }
        if (!imaged_angle(&f, r, &theta))
            continue;   /* beyond a fisheye's image circle */
        /* At 90 degrees and beyond tan(theta) no longer grows: no paraxial height. */
        if (theta < 0.5 * M_PI)
            fprintf(out, "%.9g %.9g %.9g %.9g\n", r, theta * 180.0 / M_PI, k * tan(theta),
                    100.0 * (r / (k * tan(theta)) - 1.0));
        else   /* gnuplot reads NaN as a missing value */
            fprintf(out, "%.9g %.9g NaN NaN\n", r, theta * 180.0 / M_PI);
    }
    field_angles_close(&f);
    return L2P_OK;
}

/* E at film radius r through camera c: the full lens's passing directions, or with --trace
   thick its exit pupil, the stop's image, which is all a thick lens stops. */
static double irradiance_of(const camera *c, double r)
{
    if (c->trace == TRACE_KIND_THICK)
        return irradiance_through_disk(r, c->thick_exit_z_mm, c->thick_exit_radius_mm);
    return irradiance_at(&c->lens, v3(0, r, 0), PLOT_IRRADIANCE_GRID);
}

void plot_vignetting_table(FILE *out, const camera *const *cams, int count)
{
    double e0[8];
    fprintf(out, "# %s: relative illumination E(r)/E(0) %s\n# film_radius_mm", cams[0]->lens.name,
            cams[0]->trace == TRACE_KIND_THICK ? "through the thick lens's exit pupil (--trace thick)"
                                               : "from the lens's passing directions");
    for (int i = 0; i < count && i < 8; i++) {
        fprintf(out, " f/%.3g", cams[i]->f_number);
        e0[i] = irradiance_of(cams[i], 0.0);
    }
    fputc('\n', out);
    for (int row = 0; row < PLOT_ROWS; row++) {
        const double r = film_radius(cams[0], row);
        fprintf(out, "%.9g", r);
        for (int i = 0; i < count && i < 8; i++)
            fprintf(out, " %.9g", row == 0 ? 1.0 : irradiance_of(cams[i], r) / e0[i]);
        fputc('\n', out);
    }
}

/* The script, in the folder gnuplot runs in: names relative to it, so that no path needs
   quoting in gnuplot's language. */
static int write_script(const char *path, const char *what, const char *table, const char *title,
                        const char *const *labels, int count)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    /* noenhanced: a lens's name is text, its '_' and '^' no sub- or superscripts */
    fprintf(f, "set terminal pngcairo noenhanced size %d,%d font 'DejaVu Sans,10'\n"
               "set output 'plot.png'\nset grid\nset key bottom left\nset title '%s'\n"
               "set xlabel 'film radius (mm)'\n", PLOT_WIDTH_PX, PLOT_HEIGHT_PX, title);
    if (!strcmp(what, "distortion")) {
        fprintf(f, "set ylabel 'distortion (%%)'\nset y2tics nomirror\nset ytics nomirror\n"
                   "set y2label 'field angle (deg)'\n"
                   "plot '%s' using 1:4 with linespoints lw 2 pt 7 title 'distortion', \\\n"
                   "  '' using 1:2 axes x1y2 with lines dt 2 lw 1 title 'field angle'\n", table);
    } else {
        /* from 0 to 1.05 at least, further where a lens is brighter off the axis */
        fprintf(f, "set ylabel 'relative illumination E(r)/E(0)'\nset autoscale yfixmax\nset yrange [0:1.05<*]\nplot");
        for (int i = 0; i < count; i++)
            fprintf(f, "%s '%s' using 1:%d with linespoints lw 2 pt 7 title '%s'", i ? "," : "",
                    i ? "" : table, i + 2, labels[i]);
        fputc('\n', f);
    }
    return fclose(f) ? -1 : 0;
}

/* gnuplot in folder dir, its messages on our stderr; its exit status, 127 when it cannot run. */
static int spawn_gnuplot(const char *dir)
{
    sigset_t old;
    cleanup_block_signals(&old);
    const pid_t pid = fork();
    if (pid == 0) {
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        signal(SIGHUP, SIG_DFL);
        sigprocmask(SIG_SETMASK, &old, NULL);
        const int null_fd = open("/dev/null", O_RDWR);
        if (null_fd >= 0) {
            dup2(null_fd, STDIN_FILENO);
            dup2(null_fd, STDOUT_FILENO);
        }
        if (chdir(dir) == 0)
            execlp("gnuplot", "gnuplot", "plot.gp", (char *)NULL);
        _exit(127);
    }
    if (pid > 0)
        cleanup_track_child(pid);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (pid < 0)
        return 127;
    int status;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    cleanup_untrack_child(pid);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

int plot_run_gnuplot(const char *what, const char *dir, const char *table, const char *title,
                     const char *const *labels, int count, l2p_error *err)
{
    char script[4096];
    snprintf(script, sizeof script, "%s/plot.gp", dir);
    if (write_script(script, what, table, title, labels, count))
        return l2p_fail(err, L2P_FAILED, script, 0, "cannot write: %s", strerror(errno));
    const int status = spawn_gnuplot(dir);
    if (status == 127)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "cannot run gnuplot: install it (Debian's "
                        "gnuplot-nox package)");
    if (status)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "gnuplot failed (exit status %d)", status);
    return L2P_OK;
}
