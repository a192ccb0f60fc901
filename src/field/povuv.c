/* POV-Ray 3.7.0.10's distribution 3 with `smooth`, computed as POV-Ray computes it: the
   face set-up of mesh.cpp (Compute_Mesh_Triangle, compute_smooth_triangle), the per-pixel
   face search and origin of tracepixel.cpp (CreateCameraRay) and the normal of
   Smooth_Mesh_Normal. docs/povray.md, "Distribution 3", states the facts. */
#include "field/povuv.h"

#include <stdlib.h>
#include <string.h>

/* POV-Ray's EPSILON (frame.h): Smooth_Mesh_Normal returns N1 for u below it. */
#define POV_EPSILON 1.0e-10

static vec3 fv(const float a[3]) { return v3(a[0], a[1], a[2]); }

static double axis_of(vec3 a, int i) { return i == 0 ? a.x : i == 1 ? a.y : a.z; }

/* POV-Ray's max3_coordinate: the index of the largest, later ones winning ties. */
static int max3_coordinate(double x, double y, double z)
{
    if (x > y)
        return x > z ? 0 : 2;
    return y > z ? 1 : 2;
}

/* Compute_Mesh_Triangle: vertices 1 and 2 are swapped when, seen along the dominant axis of
   the face normal cross(P3 - P1, P2 - P1), the face winds the other way. */
static bool needs_swap(vec3 p1, vec3 p2, vec3 p3)
{
    vec3 n = v3_cross(v3_sub(p3, p1), v3_sub(p2, p1));
    double len = v3_length(n);
    if (!(len > 0.0))
        return false;
    n = v3_scale(n, 1.0 / len);
    int axis = max3_coordinate(fabs(n.x), fabs(n.y), fabs(n.z));
    int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;   /* the two other axes, in order */
    double p1a = axis_of(p1, a), p1b = axis_of(p1, b), p2a = axis_of(p2, a), p2b = axis_of(p2, b);
    double p3a = axis_of(p3, a), p3b = axis_of(p3, b);
    return (p2a - p3a) * (p2b - p1b) < (p2b - p3b) * (p2a - p1a);
}

/* compute_smooth_triangle: Perp is the unit vector from P1 toward edge P2-P3, rounded to
   float32, then divided by P1's distance from that edge (so that u = 1 on the edge). */
static void smooth_frame(povuv_face *f)
{
    vec3 p1 = fv(f->p[0]), p2 = fv(f->p[1]), p3 = fv(f->p[2]);
    vec3 e = v3_sub(p3, p2);
    f->vaxis = max3_coordinate(fabs(e.x), fabs(e.y), fabs(e.z));
    vec3 t1 = v3_normalize(v3_sub(p2, p3));
    vec3 t2 = v3_sub(p1, p3);
    t1 = v3_scale(t1, v3_dot(t2, t1));
    vec3 perp = v3_normalize(v3_sub(t1, t2));
    float pf[3] = {(float)perp.x, (float)perp.y, (float)perp.z};
    double den = -v3_dot(t2, fv(pf));
    for (int i = 0; i < 3; i++)
        f->perp[i] = (float)(pf[i] / den);
}

/* The affine form of povuv_weighted_ray (povuv.h), about the first vertex's UV, where the
   weights of P2 and P3 are 0: there rel = o - P1 = b2 (P2 - P1) + b3 (P3 - P1), and the
   weights' gradients over UV are the cofactors of povuv_face_weights divided by its scale. */
static void affine_form(povuv_face *f)
{
    const double(*t)[2] = f->uv;
    const double scale = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
    const vec3 e1 = v3_sub(f->dp[1], f->dp[0]), e2 = v3_sub(f->dp[2], f->dp[0]);
    povuv_affine *a = &f->affine;
    a->u0 = t[0][0], a->v0 = t[0][1];
    a->o0 = f->dp[0];
    a->ou = v3_scale(v3_add(v3_scale(e1, t[2][1] - t[0][1]), v3_scale(e2, t[0][1] - t[1][1])), 1.0 / scale);
    a->ov = v3_scale(v3_add(v3_scale(e1, t[0][0] - t[2][0]), v3_scale(e2, t[1][0] - t[0][0])), 1.0 / scale);
    /* Smooth_Mesh_Normal's u = rel . Perp, and u v = (rel[vaxis] + (P1 - P2)[vaxis] u) / (P3 - P2)[vaxis] */
    const double uu_u = v3_dot(a->ou, f->dperp), uu_v = v3_dot(a->ov, f->dperp);
    const double uv_u = (axis_of(a->ou, f->vaxis) + (f->p1v - f->p2v) * uu_u) / f->p32v;
    const double uv_v = (axis_of(a->ov, f->vaxis) + (f->p1v - f->p2v) * uu_v) / f->p32v;
    a->r0 = f->dn1;
    a->ru = v3_add(v3_scale(f->dn21, uu_u), v3_scale(f->dn32, uv_u));
    a->rv = v3_add(v3_scale(f->dn21, uu_v), v3_scale(f->dn32, uv_v));
    f->has_affine = v3_isfinite(a->ou) && v3_isfinite(a->ov) && v3_isfinite(a->ru) && v3_isfinite(a->rv) &&
                    v3_isfinite(a->r0) && v3_isfinite(a->o0);
}

static void put3(float out[3], const double in[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = (float)in[i];
}

void povuv_face_init(povuv_face *f, const double pos[3][3], const double nrm[3][3],
                     const double uv[3][2])
{
    memset(f, 0, sizeof *f);
    for (int k = 0; k < 3; k++) {
        put3(f->p[k], pos[k]);
        /* normal_vectors are normalized in double when parsed and stored as float32 */
        vec3 n = v3_normalize(v3(nrm[k][0], nrm[k][1], nrm[k][2]));
        double nd[3] = {n.x, n.y, n.z};
        put3(f->n[k], nd);
        f->uv[k][0] = uv[k][0];
        f->uv[k][1] = uv[k][1];
    }
    /* Parse_Mesh2: a face is smooth unless its normals are equal to within 1e-10 squared */
    vec3 d1 = v3_sub(fv(f->n[0]), fv(f->n[1])), d2 = v3_sub(fv(f->n[0]), fv(f->n[2]));
    f->smooth = fabs(v3_dot(d1, d1)) > POV_EPSILON || fabs(v3_dot(d2, d2)) > POV_EPSILON;
    f->swapped = needs_swap(fv(f->p[0]), fv(f->p[1]), fv(f->p[2]));
    if (f->swapped) {
        float t[3];
        double tuv[2];
        memcpy(t, f->p[0], sizeof t), memcpy(f->p[0], f->p[1], sizeof t), memcpy(f->p[1], t, sizeof t);
        if (f->smooth)
            memcpy(t, f->n[0], sizeof t), memcpy(f->n[0], f->n[1], sizeof t), memcpy(f->n[1], t, sizeof t);
        memcpy(tuv, f->uv[0], sizeof tuv), memcpy(f->uv[0], f->uv[1], sizeof tuv);
        memcpy(f->uv[1], tuv, sizeof tuv);
    }
    smooth_frame(f);
    for (int k = 0; k < 3; k++)
        f->dp[k] = fv(f->p[k]);
    f->dn1 = fv(f->n[0]);
    f->dn21 = v3_sub(fv(f->n[1]), f->dn1);
    f->dn32 = v3_sub(fv(f->n[2]), fv(f->n[1]));
    f->dperp = fv(f->perp);
    f->p1v = f->p[0][f->vaxis];
    f->p2v = f->p[1][f->vaxis];
    f->p32v = (double)f->p[2][f->vaxis] - f->p[1][f->vaxis];
    affine_form(f);
}

void povuv_affine_ray(const povuv_face *f, double u, double v, vec3 *o, vec3 *r)
{
    const povuv_affine *a = &f->affine;
    const double du = u - a->u0, dv = v - a->v0;
    *o = v3_madd(v3_madd(a->o0, a->ou, du), a->ov, dv);
    *r = v3_madd(v3_madd(a->r0, a->ru, du), a->rv, dv);
}

/* tracepixel.cpp: scale = (P2-P1) x (P3-P1) in UV; B1 = ((P2-X) x (P3-X)) / scale, and so on
   around the face. Here the numerators, and the scale. */
static double weight_numerators(const povuv_face *f, double u, double v, double n[3])
{
    const double(*t)[2] = f->uv;
    n[0] = (t[1][0] - u) * (t[2][1] - v) - (t[2][0] - u) * (t[1][1] - v);
    n[1] = (t[2][0] - u) * (t[0][1] - v) - (t[0][0] - u) * (t[2][1] - v);
    n[2] = (t[0][0] - u) * (t[1][1] - v) - (t[1][0] - u) * (t[0][1] - v);
    return (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]);
}

void povuv_face_weights(const povuv_face *f, double u, double v, double b[3])
{
    const double scale = weight_numerators(f, u, v, b);
    for (int k = 0; k < 3; k++)
        b[k] /= scale;
}

/* With the UVs and (u, v) short binary fractions, as lens2pov's are, the numerators are exact,
   and a weight is >= 0 exactly when its numerator is 0 or has the scale's sign. */
bool povuv_face_holds(const povuv_face *f, double u, double v)
{
    double n[3];
    const double scale = weight_numerators(f, u, v, n);
    if (scale > 0)
        return n[0] >= 0 && n[1] >= 0 && n[2] >= 0;
    if (scale < 0)
        return n[0] <= 0 && n[1] <= 0 && n[2] <= 0;
    double b[3];   /* 0/0 or x/0: as POV-Ray divides */
    povuv_face_weights(f, u, v, b);
    return b[0] >= 0 && b[1] >= 0 && b[2] >= 0;
}

bool povuv_face_ray(const povuv_face *f, double u, double v, vec3 *o, vec3 *d)
{
    double b[3];
    povuv_face_weights(f, u, v, b);
    return povuv_weighted_ray(f, b, o, d);
}

bool povuv_weighted_ray(const povuv_face *f, const double b[3], vec3 *o, vec3 *d)
{
    const vec3 *p = f->dp;
    *o = v3_add(v3_add(v3_scale(p[0], b[0]), v3_scale(p[1], b[1])), v3_scale(p[2], b[2]));
    /* Smooth_Mesh_Normal: u measures from P1 (0) to edge P2-P3 (1) along Perp; the line from
       P1 through the point meets that edge at v (one coordinate, the edge's dominant axis);
       N = N1 + u (N2 - N1 + v (N3 - N2)). */
    const vec3 rel = v3_sub(*o, p[0]);
    const double uu = v3_dot(rel, f->dperp);
    vec3 r = f->dn1;
    if (!(uu < POV_EPSILON)) {
        const double vv = (axis_of(rel, f->vaxis) / uu + f->p1v - f->p2v) / f->p32v;
        r = v3_add(f->dn1, v3_scale(v3_add(f->dn21, v3_scale(f->dn32, vv)), uu));
    }
    double len = v3_length(r);
    if (!(len > 0.0) || !isfinite(len))
        return false;
    *d = v3_scale(r, 1.0 / len);
    return v3_isfinite(*o) && v3_isfinite(*d);
}

/* Parse_Mesh_Camera: a face goes into columns int(10 u) and rows int(10 v) over its UV box,
   each capped at 9 (int() truncates toward zero). */
static int cell_of(double t)
{
    int c = (int)(t * 10);
    return c > 9 ? 9 : c;
}

int povuv_mesh_init(povuv_mesh *m, povuv_face *face, int faces)
{
    memset(m, 0, sizeof *m);
    m->faces = faces;
    m->face = face;
    m->words = (faces + 31) / 32;
    for (int c = 0; c < 10; c++) {
        m->ucol[c] = calloc((size_t)m->words + 1, sizeof(uint32_t));
        m->vrow[c] = calloc((size_t)m->words + 1, sizeof(uint32_t));
        if (!m->ucol[c] || !m->vrow[c])
            return -1;
    }
    for (int i = 0; i < faces; i++) {
        const double(*t)[2] = face[i].uv;
        int u0 = cell_of(fmin(t[0][0], fmin(t[1][0], t[2][0]))), u1 = cell_of(fmax(t[0][0], fmax(t[1][0], t[2][0])));
        int v0 = cell_of(fmin(t[0][1], fmin(t[1][1], t[2][1]))), v1 = cell_of(fmax(t[0][1], fmax(t[1][1], t[2][1])));
        for (int c = u0 < 0 ? 0 : u0; c <= u1; c++)
            m->ucol[c][i / 32] |= 1u << (i % 32);
        for (int c = v0 < 0 ? 0 : v0; c <= v1; c++)
            m->vrow[c][i / 32] |= 1u << (i % 32);
    }
    return 0;
}

void povuv_mesh_free(povuv_mesh *m)
{
    for (int c = 0; c < 10; c++) {
        free(m->ucol[c]);
        free(m->vrow[c]);
    }
    free(m->face);
    memset(m, 0, sizeof *m);
}

int povuv_mesh_find(const povuv_mesh *m, double u, double v)
{
    /* tracepixel.cpp: min((unsigned) (u * 10), 9); UVs here are never negative */
    int cu = cell_of(u), cv = cell_of(v);
    for (int w = 0; w < m->words; w++) {
        uint32_t bits = m->ucol[cu][w] & m->vrow[cv][w];
        for (int bit = 0; bits && bit < 32; bit++) {
            if (!(bits & (1u << bit)))
                continue;
            int i = w * 32 + bit;
            double b[3];
            povuv_face_weights(&m->face[i], u, v, b);
            if (b[0] >= 0 && b[1] >= 0 && b[2] >= 0)
                return i;
        }
    }
    return -1;
}

void povuv_pixel_uv(int width, int height, int px, int py, double *u, double *v)
{
    *u = (double)px / (width + 1);
    *v = 1.0 - (double)(py + 1) / (height + 1);
}
