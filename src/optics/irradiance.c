#include "optics/irradiance.h"

#include <math.h>
#include <stdbool.h>
#include "optics/chief.h"
#include "optics/trace_batch.h"

/* The coarse grid's cells on a side: a cell of 2/128 in direction cosines is a quarter of the
   narrowest set measured (a film-side cone of half-angle 1 / (2 N) at f/16). */
#define COARSE_CELLS 128

typedef struct grid {
    double a0, b0, h;   /* cell (i, j) is centred on (a0 + (i + 0.5) h, b0 + (j + 0.5) h) */
    int n;
} grid;

/* Passing cells of the grid, traced a batch at a time; their bounding box grows *box (amin,
   amax, bmin, bmax). */
static long count_passing(const lens *l, vec3 p, const grid *g, double *box)
{
    long count = 0;
    const long cells = (long)g->n * g->n;
    for (long start = 0; start < cells; start += TRACE_BATCH_MAX) {
        const int m = cells - start < TRACE_BATCH_MAX ? (int)(cells - start) : TRACE_BATCH_MAX;
        trace_batch b;
        double a[TRACE_BATCH_MAX], bb[TRACE_BATCH_MAX];
        for (int k = 0; k < m; k++) {
            a[k] = g->a0 + ((start + k) % g->n + 0.5) * g->h;
            bb[k] = g->b0 + ((start + k) / g->n + 0.5) * g->h;
            const double q = a[k] * a[k] + bb[k] * bb[k];
            b.ox[k] = p.x;
            b.oy[k] = p.y;
            b.oz[k] = p.z;
            b.dx[k] = a[k];
            b.dy[k] = bb[k];
            b.dz[k] = sqrt(fmax(0.0, 1.0 - q));
            b.status[k] = q < 1.0 ? TRACE_PASSED : TRACE_MISSED;   /* toward the lens only */
        }
        trace_batch_toward_scene(l, &b, m);
        for (int k = 0; k < m; k++) {
            if (b.status[k] != TRACE_PASSED)
                continue;
            count++;
            box[0] = fmin(box[0], a[k]);
            box[1] = fmax(box[1], a[k]);
            box[2] = fmin(box[2], bb[k]);
            box[3] = fmax(box[3], bb[k]);
        }
    }
    return count;
}

/* A set narrower than the coarse grid's cells (a small stop: at f/50 the cone's half-angle is
   1/100) can fall between their centres. It lies about the chief ray, the ray through the
   stop's centre: grids of 16 x 16 cells centred on its direction cosines, a quarter as wide
   each time, until one finds it; *h gets its cell. */
static long find_about_chief(const lens *l, vec3 p, double *box, double *h)
{
    chief_lens c;
    if (chief_lens_open(&c, l))
        return 0;
    const double r = hypot(p.x, p.y);
    double slope;
    long count = 0;
    if (chief_slope(&c, r, &slope)) {
        const double along = slope / sqrt(1.0 + slope * slope);
        const double a = r > 0.0 ? along * p.x / r : 0.0, b = r > 0.0 ? along * p.y / r : 0.0;
        for (double width = 8.0 * 2.0 / COARSE_CELLS; !count && width > 1e-12; width *= 0.25) {
            const grid g = {a - 0.5 * width, b - 0.5 * width, width / 16, 16};
            count = count_passing(l, p, &g, box);
            *h = g.h;
        }
    }
    chief_lens_close(&c);
    return count;
}

double irradiance_at(const lens *l, vec3 p, int n)
{
    double box[4] = {1, -1, 1, -1};
    const grid coarse = {-1.0, -1.0, 2.0 / COARSE_CELLS, COARSE_CELLS};
    double h = coarse.h;
    if (count_passing(l, p, &coarse, box) == 0 && find_about_chief(l, p, box, &h) == 0)
        return 0.0;
    const double side = fmax(box[1] - box[0], box[3] - box[2]) + 5.0 * h;
    const grid fine = {box[0] - 2.5 * h, box[2] - 2.5 * h, side / n, n};
    double unused[4] = {1, -1, 1, -1};
    return (double)count_passing(l, p, &fine, unused) * fine.h * fine.h;
}

double irradiance_through_disk(double r_mm, double z_mm, double radius_mm)
{
    const double z2 = z_mm * z_mm, r2 = r_mm * r_mm, R2 = radius_mm * radius_mm;
    const double s = z2 + r2 + R2;
    return 0.5 * M_PI * (1.0 - (z2 + r2 - R2) / sqrt(s * s - 4.0 * r2 * R2));
}
