/* The adaptive mesh of one sub-image. Every pixel's exact ray is traced (the guarantee is
   checked at every pixel, so nothing less would do); cells whose corners are pixels are
   refined until, at every pixel a cell's faces contain, the model of POV-Ray's ray (povuv.c)
   is within the tolerance of the exact one: a passing cell as two faces along either
   diagonal, else halved the way its halves err less; a cell the lens partly blocks as the
   convex hull of its passing pixels, else split in four, down to single pixels. Pixels no
   face took get a tiny face of their own (docs/fields.md, "The mesh of a sub-image"). */
#include "field/subimage.h"

#include <stdlib.h>
#include <string.h>
#include "field/fieldpixels.h"

void field_tolerance_of(const camera *c, double pixels, field_tolerance *t)
{
    double pitch = c->film.width_mm / c->film.width;
    double f = fabs(c->thick.rear_focal_length_mm);
    double z = isfinite(c->focus_distance_units) ? c->focus_distance_units * c->unit_mm : INFINITY;
    z = fmin(z, 100 * f);
    t->pixels = pixels;
    t->angle_rad = pixels * pitch / f;
    t->origin_mm = pixels * pitch * z / f;
}

int field_render_size(int n)
{
    int p = 1;
    while (p - 1 < n)
        p *= 2;
    return p - 1;
}

typedef struct builder {
    const camera *c;
    const field_tolerance *tol;
    double per_sin2;           /* 1 / sin(tol->angle_rad)^2 */
    double per_origin2;        /* 1 / tol->origin_mm^2 */
    float *stricter;           /* a pixel's factor on the squared error, >= 1 (pixel_scale) */
    int w, h;
    ray *rays;                 /* mesh space: camera space less the front vertex */
    unsigned char *passed, *covered;
    int *sum;                  /* (w+1) x (h+1) prefix sums of passed */
    int *vid;                  /* mesh vertex of a pixel, -1 when none yet */
    field_mesh *m;
    field_stats *st;
    float *weights;            /* the caller's, may be NULL */
    bool oom;
} builder;

/* ---------------------------------------------------------------- tracing */

static void trace_all(builder *b, film_sample s, double weight_scale)
{
    const camera *c = b->c;
    sample_batch *batch = malloc(sizeof *batch);
    if (!batch) {
        b->oom = true;
        return;
    }
    const double front = c->lens.surface[0].vertex_z_mm;
    const long n = (long)b->w * b->h;
    for (long start = 0; start < n; start += CAMERA_BATCH) {
        field_trace_pixels(c, s, weight_scale, start,
                           (int)(n - start < CAMERA_BATCH ? n - start : CAMERA_BATCH), batch);
        for (int k = 0; k < batch->n; k++) {
            ray r = batch->out[k];
            const long i = start + k;
            r.o.z -= front;
            b->rays[i] = r;
            b->passed[i] = batch->passed[k];
            if (b->weights)
                b->weights[i] = batch->passed[k] ? (float)batch->weight[k] : 0.0f;
        }
    }
    free(batch);
    for (int y = 0; y < b->h; y++)
        for (int x = 0; x < b->w; x++)
            b->sum[(y + 1) * (b->w + 1) + x + 1] = b->passed[y * b->w + x] + b->sum[y * (b->w + 1) + x + 1] +
                                                   b->sum[(y + 1) * (b->w + 1) + x] - b->sum[y * (b->w + 1) + x];
}

/* The change of the exact direction a pixel step along (sx, sy) makes at pixel (x, y): half the
   difference of the neighbours' either side, or the difference with the one that passes;
   false when neither does. */
static bool direction_step(const builder *b, int x, int y, int sx, int sy, vec3 *step)
{
    const ray *r[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++) {
        const int nx = x + (k ? sx : -sx), ny = y + (k ? sy : -sy);
        if (nx >= 0 && ny >= 0 && nx < b->w && ny < b->h && b->passed[ny * b->w + nx])
            r[k] = &b->rays[ny * b->w + nx];
    }
    const ray *at = &b->rays[y * b->w + x];
    if (r[0] && r[1])
        *step = v3_scale(v3_sub(r[1]->d, r[0]->d), 0.5);
    else if (r[0] || r[1])
        *step = r[1] ? v3_sub(r[1]->d, at->d) : v3_sub(at->d, r[0]->d);
    return r[0] || r[1];
}

/* The tolerance is a distance on the film: an error of angle e in the direction moves the
   ray's subject by at most e / s pixels, s the smallest angle a pixel step turns the exact
   direction by (the least singular value of the field's Jacobian, from the neighbours' rays).
   field_tolerance's angle is the centre's, p / f; where a pixel spans less (off the axis of
   most lenses: p cos^2(theta) / f radially through a distortion-free one), the pixel's errors
   count (p / f / s)^2 times, at most FIELD_MOST_STRICTER times; where it spans more, as at the
   centre, so that the angle stays within field_tolerance's too. */
static void pixel_scale(builder *b)
{
    const double centre = b->tol->angle_rad / b->tol->pixels;
    for (int y = 0; y < b->h; y++)
        for (int x = 0; x < b->w; x++) {
            const int i = y * b->w + x;
            vec3 jx, jy;
            b->stricter[i] = 1.0f;
            if (!b->passed[i] || !direction_step(b, x, y, 1, 0, &jx) || !direction_step(b, x, y, 0, 1, &jy))
                continue;
            const double gxx = v3_dot(jx, jx), gyy = v3_dot(jy, jy), gxy = v3_dot(jx, jy);
            const double tr = gxx + gyy, det = gxx * gyy - gxy * gxy;
            const double least2 = 0.5 * (tr - sqrt(fmax(tr * tr - 4 * det, 0.0)));
            const double k = centre * centre / least2;
            b->stricter[i] = (float)(k > 1 ? (k < FIELD_MOST_STRICTER ? k : FIELD_MOST_STRICTER) : 1);
        }
}

/* Passing pixels in [x0, x1] x [y0, y1] (inclusive). */
static long passing(const builder *b, int x0, int y0, int x1, int y1)
{
    const int W = b->w + 1;
    return (long)b->sum[(y1 + 1) * W + x1 + 1] - b->sum[y0 * W + x1 + 1] - b->sum[(y1 + 1) * W + x0] + b->sum[y0 * W + x0];
}

/* ---------------------------------------------------------------- faces and checks */

/* The face of three pixels as POV-Ray will hold it (float32 origins and directions). */
static void pixel_face(const builder *b, const int px[3][2], povuv_face *f)
{
    double pos[3][3], nrm[3][3], uv[3][2];
    for (int k = 0; k < 3; k++) {
        const ray *r = &b->rays[px[k][1] * b->w + px[k][0]];
        float p[3] = {(float)r->o.x, (float)r->o.y, (float)r->o.z}, n[3] = {(float)r->d.x, (float)r->d.y, (float)r->d.z};
        for (int i = 0; i < 3; i++)
            pos[k][i] = p[i], nrm[k][i] = n[i];
        uv[k][0] = px[k][0] / (double)(b->m->render_w + 1);
        uv[k][1] = 1.0 - (px[k][1] + 1) / (double)(b->m->render_h + 1);
    }
    povuv_face_init(f, pos, nrm, uv);
}

/* The square of the error of the model's ray (origin o, direction d of any length) against the
   exact one, in units of the tolerance. For a unit a, |a x d| / |d| is the sine of the angle
   between a and d: below a right angle, comparing sines is comparing angles, without an atan2
   at every pixel; squares spare the square roots. */
static double ray_error_squared(const builder *b, const ray *exact, vec3 o, vec3 d)
{
    const double d2 = v3_dot(d, d);
    if (!(d2 > 0) || !isfinite(d2) || !v3_isfinite(o) || !(v3_dot(exact->d, d) > 0))
        return INFINITY;
    const vec3 turn = v3_cross(exact->d, d);
    vec3 e = v3_sub(o, exact->o);
    vec3 across = v3_sub(e, v3_scale(exact->d, v3_dot(e, exact->d)));
    const double sin2 = v3_dot(turn, turn) / d2 * b->per_sin2, off2 = v3_dot(across, across) * b->per_origin2;
    return sin2 > off2 ? sin2 : off2;
}

/* Whether pixel (x, y) is fine with face f: outside it, or inside with a ray within the
   tolerance, less FIELD_AFFINE_MARGIN when the face's affine form gives the ray. *worst is the
   largest error seen, in units of the tolerance. */
static bool pixel_ok(const builder *b, const povuv_face *f, int x, int y, double *worst)
{
    static const double most = (1 - FIELD_AFFINE_MARGIN) * (1 - FIELD_AFFINE_MARGIN);
    double u, v, w[3];
    povuv_pixel_uv(b->m->render_w, b->m->render_h, x, y, &u, &v);
    if (!povuv_face_holds(f, u, v))
        return true;
    if (!b->passed[y * b->w + x])
        return false;
    vec3 o, d;
    if (f->has_affine)
        povuv_affine_ray(f, u, v, &o, &d);
    else if (povuv_face_weights(f, u, v, w), !povuv_weighted_ray(f, w, &o, &d))
        return false;
    const double e2 = ray_error_squared(b, &b->rays[y * b->w + x], o, d) * b->stricter[y * b->w + x];
    if (e2 > *worst * *worst)
        *worst = sqrt(e2);
    return e2 <= (f->has_affine ? most : 1.0);
}

/* Whether the pixel nearest the centroid of the face whose corners are the pixels px is fine
   with face f: the error of interpolating a smooth field peaks inside a face. */
static bool centroid_ok(const builder *b, const povuv_face *f, const int px[3][2], double *worst)
{
    return pixel_ok(b, f, (px[0][0] + px[1][0] + px[2][0] + 1) / 3, (px[0][1] + px[1][1] + px[2][1] + 1) / 3,
                    worst);
}

/* Whether every pixel of [x0, x1] x [y0, y1] is fine with face f, whose corners are the
   pixels px. The centroid goes first: a face that fails mostly fails there, at once. */
static bool face_ok(const builder *b, const povuv_face *f, const int px[3][2], int x0, int y0, int x1,
                    int y1, double *worst)
{
    if (!centroid_ok(b, f, px, worst))
        return false;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++)
            if (!pixel_ok(b, f, x, y, worst))
                return false;
    return true;
}

static int vertex_of(builder *b, int x, int y)
{
    int *id = &b->vid[y * b->w + x];
    if (*id < 0) {
        const ray *r = &b->rays[y * b->w + x];
        *id = field_mesh_vertex(b->m, r->o, r->d, x, y);
        if (*id < 0)
            b->oom = true;
    }
    return *id;
}

static void emit(builder *b, const int px[3][2], double worst)
{
    int a = vertex_of(b, px[0][0], px[0][1]), c = vertex_of(b, px[1][0], px[1][1]);
    int d = vertex_of(b, px[2][0], px[2][1]);
    if (a < 0 || c < 0 || d < 0 || field_mesh_face(b->m, a, c, d) < 0) {
        b->oom = true;
        return;
    }
    for (int k = 0; k < 3; k++)
        b->covered[px[k][1] * b->w + px[k][0]] = 1;
    b->st->worst_pixels = fmax(b->st->worst_pixels, worst * b->tol->pixels);
}

/* ---------------------------------------------------------------- the cells */

/* A cell's two faces, split along the diagonal from its top-right to its bottom-left corner
   (diagonal 0) or from its top-left to its bottom-right corner (diagonal 1). */
static void cell_faces(int x0, int y0, int x1, int y1, int diagonal, int t[2][3][2])
{
    const int corner[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    static const int of[2][2][3] = {{{0, 1, 3}, {1, 2, 3}}, {{0, 1, 2}, {0, 2, 3}}};
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 3; j++)
            memcpy(t[k][j], corner[of[diagonal][k][j]], sizeof t[k][j]);
}

/* A whole passing cell: both faces, if every pixel they contain is within the tolerance, along
   either diagonal. Which diagonal keeps the error smaller depends on the direction in which
   the field bends most, mostly radial with a lens's distortion, so both are tried. */
static bool try_cell(builder *b, int x0, int y0, int x1, int y1)
{
    for (int diagonal = 0; diagonal < 2; diagonal++) {
        int t[2][3][2];
        povuv_face f[2];
        double worst = 0;
        bool ok = true;
        cell_faces(x0, y0, x1, y1, diagonal, t);
        for (int k = 0; k < 2 && ok; k++) {
            pixel_face(b, (const int(*)[2])t[k], &f[k]);
            ok = face_ok(b, &f[k], (const int(*)[2])t[k], x0, y0, x1, y1, &worst);
        }
        if (!ok)
            continue;
        for (int k = 0; k < 2; k++)
            emit(b, (const int(*)[2])t[k], worst);
        for (int y = y0; y <= y1; y++)
            memset(b->covered + (size_t)y * b->w + x0, 1, (size_t)(x1 - x0 + 1));
        return true;
    }
    return false;
}

/* A cell one pixel wide and high: each face of three passing corners whose pixels (its
   corners) are within the tolerance, trying both diagonals. */
static void finest(builder *b, int x0, int y0, int x1, int y1)
{
    const int corner[4][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    for (int skip = 0; skip < 4; skip++) {
        int t[3][2], n = 0;
        for (int k = 0; k < 4; k++)
            if (k != skip)
                memcpy(t[n++], corner[k], sizeof t[0]);
        bool all = true, new_pixel = false;
        for (int k = 0; k < 3; k++) {
            all = all && b->passed[t[k][1] * b->w + t[k][0]];
            new_pixel = new_pixel || !b->covered[t[k][1] * b->w + t[k][0]];
        }
        povuv_face f;
        double worst = 0;
        if (!all || !new_pixel)
            continue;
        pixel_face(b, (const int(*)[2])t, &f);
        if (face_ok(b, &f, (const int(*)[2])t, x0, y0, x1, y1, &worst))
            emit(b, (const int(*)[2])t, worst);
    }
}

/* A cell the lens partly blocks: the convex hull of its passing pixels (each row's first and
   last), as a fan of faces from its first corner. Where the passing region is convex, as the
   intersection of the stop's and the rims' images is, the hull holds no blocked pixel, and a
   few long faces follow an edge that single pixels would take two faces each to draw. Taken
   when every face keeps the tolerance and holds no blocked pixel, as every face must. */
enum { HULL_MOST = 2 * (FIELD_BASE_CELL + 1) };

static int hull_of(const builder *b, int x0, int y0, int x1, int y1, int hull[][2])
{
    int pts[HULL_MOST][2], n = 0, m = 0;
    for (int y = y0; y <= y1; y++) {
        const unsigned char *row = b->passed + (size_t)y * b->w;
        int first = x0, last = x1;
        while (first <= x1 && !row[first])
            first++;
        while (last > first && !row[last])
            last--;
        if (first > x1)
            continue;
        pts[n][0] = first, pts[n++][1] = y;
        if (last > first)
            pts[n][0] = last, pts[n++][1] = y;
    }
    /* Andrew's monotone chain over points sorted by (y, x), collinear points dropped */
    for (int pass = 0; pass < 2; pass++) {
        const int start = m;
        for (int k = 0; k < n; k++) {
            const int *q = pts[pass ? n - 1 - k : k];
            while (m >= start + 2 &&
                   (long)(hull[m - 1][0] - hull[m - 2][0]) * (q[1] - hull[m - 2][1]) -
                   (long)(hull[m - 1][1] - hull[m - 2][1]) * (q[0] - hull[m - 2][0]) <= 0)
                m--;
            hull[m][0] = q[0], hull[m++][1] = q[1];
        }
        m--;   /* each chain's last point starts the other */
    }
    return m;
}

static bool try_hull(builder *b, int x0, int y0, int x1, int y1)
{
    int hull[2 * HULL_MOST][2];
    if (x1 - x0 > FIELD_BASE_CELL || y1 - y0 > FIELD_BASE_CELL)
        return false;
    const int faces = hull_of(b, x0, y0, x1, y1, hull) - 2;
    if (faces < 1)
        return false;
    int fan[2 * HULL_MOST][3][2];
    povuv_face f[2 * HULL_MOST];
    double worst = 0;
    for (int k = 0; k < faces; k++) {
        memcpy(fan[k][0], hull[0], sizeof fan[k][0]);
        memcpy(fan[k][1], hull[k + 1], sizeof fan[k][1]);
        memcpy(fan[k][2], hull[k + 2], sizeof fan[k][2]);
        pixel_face(b, (const int(*)[2])fan[k], &f[k]);
        if (!face_ok(b, &f[k], (const int(*)[2])fan[k], x0, y0, x1, y1, &worst))
            return false;
    }
    for (int k = 0; k < faces; k++)
        emit(b, (const int(*)[2])fan[k], worst);
    /* the pixels the faces hold, as POV-Ray finds them */
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            double u, v;
            povuv_pixel_uv(b->m->render_w, b->m->render_h, x, y, &u, &v);
            for (int k = 0; k < faces && !b->covered[y * b->w + x]; k++)
                b->covered[y * b->w + x] = povuv_face_holds(&f[k], u, v);
        }
    return true;
}

/* The model's error, in tolerances, at the pixels nearest the centroids of a passing cell's two
   faces (split along diagonal 0), where interpolating a smooth field errs most. */
static double centroid_error(const builder *b, int x0, int y0, int x1, int y1)
{
    int t[2][3][2];
    double worst = 0;
    cell_faces(x0, y0, x1, y1, 0, t);
    for (int k = 0; k < 2; k++) {
        povuv_face f;
        pixel_face(b, (const int(*)[2])t[k], &f);
        centroid_ok(b, &f, (const int(*)[2])t[k], &worst);
    }
    return worst;
}

/* Which way to halve a passing cell that failed: the halves whose faces err less at their
   centroids. Where a lens's distortion bends the field most depends on its projection (across
   the radius for a fisheye, along it for a rectilinear lens) and on the cell's place on the
   film, so the two are compared rather than assumed. */
static bool halve_along_x(const builder *b, int x0, int y0, int x1, int y1)
{
    const int mx = (x0 + x1) / 2, my = (y0 + y1) / 2;
    return centroid_error(b, x0, y0, mx, y1) + centroid_error(b, mx, y0, x1, y1) <=
           centroid_error(b, x0, y0, x1, my) + centroid_error(b, x0, my, x1, y1);
}

static void build_cell(builder *b, int x0, int y0, int x1, int y1);

/* The four cells of [x0, x1] x [y0, y1] about (mx, my); only two when one side stays whole
   (mx == x1 or my == y1). */
static void split_four(builder *b, int x0, int y0, int x1, int y1, int mx, int my)
{
    build_cell(b, x0, y0, mx, my);
    if (mx < x1)
        build_cell(b, mx, y0, x1, my);
    if (my < y1)
        build_cell(b, x0, my, mx, y1);
    if (mx < x1 && my < y1)
        build_cell(b, mx, my, x1, y1);
}

/* The base grid's line nearest the middle of [a0, a1], which is more than one base cell long
   and starts on the grid. */
static int base_middle(int a0, int a1)
{
    const int cells = (a1 - a0 + FIELD_BASE_CELL - 1) / FIELD_BASE_CELL;
    return a0 + FIELD_BASE_CELL * ((cells + 1) / 2);
}

static void build_cell(builder *b, int x0, int y0, int x1, int y1)
{
    if (b->oom || x1 <= x0 || y1 <= y0)
        return;
    long area = (long)(x1 - x0 + 1) * (y1 - y0 + 1), pass = passing(b, x0, y0, x1, y1);
    if (pass == 0)
        return;
    if (pass == area && try_cell(b, x0, y0, x1, y1))
        return;
    /* Larger than the base grid: tried whole, else split on the base grid, so that below it
       the mesh is the one the base grid alone makes. */
    const bool big_x = x1 - x0 > FIELD_BASE_CELL, big_y = y1 - y0 > FIELD_BASE_CELL;
    if (big_x || big_y) {
        split_four(b, x0, y0, x1, y1, big_x ? base_middle(x0, x1) : x1, big_y ? base_middle(y0, y1) : y1);
        return;
    }
    bool sx = x1 - x0 >= 2, sy = y1 - y0 >= 2;
    if (pass < area && (sx || sy) && try_hull(b, x0, y0, x1, y1))
        return;
    if (!sx && !sy) {
        finest(b, x0, y0, x1, y1);
        return;
    }
    /* A passing cell is halved, not split in four: where the error grows faster one way, the
       halves are often within the tolerance already, two faces each where a split in four
       makes eight (docs/fields.md). */
    if (pass == area) {
        const bool along_x = sx && (!sy || halve_along_x(b, x0, y0, x1, y1));
        const int mx = along_x ? (x0 + x1) / 2 : x1, my = along_x ? y1 : (y0 + y1) / 2;
        build_cell(b, x0, y0, mx, my);
        build_cell(b, along_x ? mx : x0, along_x ? y0 : my, x1, y1);
        return;
    }
    split_four(b, x0, y0, x1, y1, sx ? (x0 + x1) / 2 : x1, sy ? (y0 + y1) / 2 : y1);
}

/* ---------------------------------------------------------------- lone pixels */

/* A passing pixel no face took (its neighbours are blocked, or no face through it was within
   the tolerance): a small face of its own, a quarter pixel around its UV point so that it
   contains no other pixel, whose UV centroid is the pixel. Its three origins sit
   LONE_SPREAD_MM apart around the exact origin, across the ray (equal or collinear origins
   leave POV-Ray's smoothing frame undefined), and all three carry the exact direction, so
   that any weights give it back. */
#define LONE_SPREAD_MM 0.01

static void lone_face(builder *b, int x, int y)
{
    const ray *r = &b->rays[y * b->w + x];
    vec3 side = fabs(r->d.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
    vec3 e1 = v3_normalize(v3_cross(r->d, side)), e2 = v3_cross(r->d, e1);
    const double c = -0.5, s = sqrt(3.0) / 2;
    vec3 off[3] = {e1, v3_add(v3_scale(e1, c), v3_scale(e2, s)), v3_sub(v3_scale(e1, c), v3_scale(e2, s))};
    const double dx[3] = {0.25, -0.125, -0.125}, dy[3] = {0, 0.25, -0.25};
    int id[3];
    for (int k = 0; k < 3; k++) {
        id[k] = field_mesh_vertex(b->m, v3_madd(r->o, off[k], LONE_SPREAD_MM), r->d, x + dx[k], y + dy[k]);
        if (id[k] < 0) {
            b->oom = true;
            return;
        }
    }
    int f = field_mesh_face(b->m, id[0], id[1], id[2]);
    if (f < 0) {
        b->oom = true;
        return;
    }
    povuv_face pf;
    double worst = 0;
    field_mesh_povuv_face(b->m, f, &pf);
    if (!pixel_ok(b, &pf, x, y, &worst))
        b->st->worst_pixels = INFINITY;   /* cannot happen: reported, and refused by the caller */
    b->st->worst_pixels = fmax(b->st->worst_pixels, worst * b->tol->pixels);
    b->covered[y * b->w + x] = 1;
    b->st->lone_faces++;
}

/* ---------------------------------------------------------------- the sub-image */

/* The coarsest cells: corners every base_cell pixels, and the last row and column. */
static void build_grid(builder *b, int base)
{
    for (int y0 = 0; y0 < b->h - 1; y0 += base)
        for (int x0 = 0; x0 < b->w - 1; x0 += base) {
            int x1 = x0 + base < b->w - 1 ? x0 + base : b->w - 1;
            int y1 = y0 + base < b->h - 1 ? y0 + base : b->h - 1;
            build_cell(b, x0, y0, x1, y1);
        }
    for (int y = 0; y < b->h && !b->oom; y++)
        for (int x = 0; x < b->w && !b->oom; x++)
            if (b->passed[y * b->w + x] && !b->covered[y * b->w + x])
                lone_face(b, x, y);
}

int field_build_subimage(const camera *c, film_sample s, double weight_scale,
                         const field_tolerance *t, int base_cell, field_mesh *out, float *weights,
                         field_stats *st, l2p_error *err)
{
    builder b = {.c = c, .tol = t, .per_sin2 = 1.0 / (sin(t->angle_rad) * sin(t->angle_rad)),
                 .per_origin2 = 1.0 / (t->origin_mm * t->origin_mm),
                 .w = c->crop_x1 - c->crop_x0, .h = c->crop_y1 - c->crop_y0,
                 .m = out, .st = st, .weights = weights};
    const size_t n = (size_t)b.w * b.h;
    memset(st, 0, sizeof *st);
    field_mesh_clear(out);
    b.rays = malloc(n * sizeof *b.rays);
    b.passed = calloc(n, 1);
    b.covered = calloc(n, 1);
    b.sum = calloc((size_t)(b.w + 1) * (b.h + 1), sizeof *b.sum);
    b.vid = malloc(n * sizeof *b.vid);
    b.stricter = malloc(n * sizeof *b.stricter);
    b.oom = !b.rays || !b.passed || !b.covered || !b.sum || !b.vid || !b.stricter;
    if (!b.oom) {
        memset(b.vid, 0xff, n * sizeof *b.vid);
        trace_all(&b, s, weight_scale);
        pixel_scale(&b);
    }
    if (!b.oom)
        build_grid(&b, base_cell < 1 ? 1 : base_cell);
    for (size_t i = 0; i < n && !b.oom; i++)
        st->passed += b.passed[i];
    st->blocked = (long)n - st->passed;
    st->faces = out->faces;
    st->vertices = out->vertices;
    free(b.rays), free(b.passed), free(b.covered), free(b.sum), free(b.vid), free(b.stricter);
    if (b.oom)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory building a ray field");
    return L2P_OK;
}
