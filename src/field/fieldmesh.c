/* The distribution-3 camera mesh: storage and the include POV-Ray reads. */
#include "field/fieldmesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void field_mesh_init(field_mesh *m, int render_w, int render_h)
{
    memset(m, 0, sizeof *m);
    m->render_w = render_w;
    m->render_h = render_h;
}

void field_mesh_free(field_mesh *m)
{
    free(m->pos), free(m->nrm), free(m->pix), free(m->tri);
    memset(m, 0, sizeof *m);
}

void field_mesh_clear(field_mesh *m) { m->vertices = m->faces = 0; }

static int grow(void **p, int *cap, int need, size_t size)
{
    if (need <= *cap)
        return 0;
    int n = *cap ? *cap * 2 : 16;
    while (n < need)
        n *= 2;
    void *q = realloc(*p, (size_t)n * size);
    if (!q)
        return -1;
    *p = q;
    *cap = n;
    return 0;
}

int field_mesh_vertex(field_mesh *m, vec3 pos, vec3 nrm, double x, double y)
{
    int cap = m->vertex_cap, need = m->vertices + 1;
    if (grow((void **)&m->pos, &cap, need, sizeof *m->pos) < 0)
        return -1;
    cap = m->vertex_cap;
    if (grow((void **)&m->nrm, &cap, need, sizeof *m->nrm) < 0)
        return -1;
    cap = m->vertex_cap;
    if (grow((void **)&m->pix, &cap, need, sizeof *m->pix) < 0)
        return -1;
    m->vertex_cap = cap;
    int k = m->vertices++;
    m->pos[k][0] = (float)pos.x, m->pos[k][1] = (float)pos.y, m->pos[k][2] = (float)pos.z;
    m->nrm[k][0] = (float)nrm.x, m->nrm[k][1] = (float)nrm.y, m->nrm[k][2] = (float)nrm.z;
    m->pix[k][0] = x, m->pix[k][1] = y;
    return k;
}

/* Vertex i's UV: povuv_pixel_uv for a position that need not be whole. Made when needed, not
   kept: a mesh is held until its render is written, and its vertices are most of it. */
static void uv_of(const field_mesh *m, int i, double uv[2])
{
    uv[0] = m->pix[i][0] / (m->render_w + 1);
    uv[1] = 1.0 - (m->pix[i][1] + 1) / (m->render_h + 1);
}

/* An array of at least n elements of size cut to n: a failed realloc leaves the block as it
   was, larger, which is as good. */
static void fit(void **p, int n, size_t size)
{
    void *q = *p && n > 0 ? realloc(*p, (size_t)n * size) : NULL;
    if (q)
        *p = q;
}

void field_mesh_shrink(field_mesh *m)
{
    fit((void **)&m->pos, m->vertices, sizeof *m->pos);
    fit((void **)&m->nrm, m->vertices, sizeof *m->nrm);
    fit((void **)&m->pix, m->vertices, sizeof *m->pix);
    fit((void **)&m->tri, m->faces, sizeof *m->tri);
    if (m->pos)
        m->vertex_cap = m->vertices;
    if (m->tri)
        m->face_cap = m->faces;
}

int field_mesh_face(field_mesh *m, int a, int b, int c)
{
    if (grow((void **)&m->tri, &m->face_cap, m->faces + 1, sizeof *m->tri) < 0)
        return -1;
    int k = m->faces++;
    m->tri[k][0] = a, m->tri[k][1] = b, m->tri[k][2] = c;
    return k;
}

int field_mesh_append(field_mesh *m, const field_mesh *src, int dx, int dy)
{
    int base = m->vertices;
    for (int i = 0; i < src->vertices; i++) {
        vec3 p = v3(src->pos[i][0], src->pos[i][1], src->pos[i][2]);
        vec3 n = v3(src->nrm[i][0], src->nrm[i][1], src->nrm[i][2]);
        if (field_mesh_vertex(m, p, n, src->pix[i][0] + dx, src->pix[i][1] + dy) < 0)
            return -1;
    }
    for (int k = 0; k < src->faces; k++)
        if (field_mesh_face(m, base + src->tri[k][0], base + src->tri[k][1], base + src->tri[k][2]) < 0)
            return -1;
    return 0;
}

typedef struct face_key {
    double area;
    int index;
} face_key;

static int larger_first(const void *pa, const void *pb)
{
    const face_key *a = pa, *b = pb;
    if (a->area != b->area)
        return a->area < b->area ? 1 : -1;
    return (a->index > b->index) - (a->index < b->index);
}

int field_mesh_sort_faces_by_area(field_mesh *m)
{
    if (m->faces < 2)
        return 0;   /* nothing to order (and no array yet when there are no faces) */
    face_key *key = malloc(sizeof *key * (size_t)m->faces + 1);
    int (*tri)[3] = malloc(sizeof *tri * (size_t)m->faces + 1);
    if (!key || !tri) {
        free(key), free(tri);
        return -1;
    }
    for (int k = 0; k < m->faces; k++) {
        const double *a = m->pix[m->tri[k][0]], *b = m->pix[m->tri[k][1]], *c = m->pix[m->tri[k][2]];
        key[k].area = fabs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
        key[k].index = k;
    }
    qsort(key, (size_t)m->faces, sizeof *key, larger_first);
    for (int k = 0; k < m->faces; k++)
        memcpy(tri[k], m->tri[key[k].index], sizeof tri[k]);
    memcpy(m->tri, tri, sizeof *tri * (size_t)m->faces);
    free(key), free(tri);
    return 0;
}

void field_mesh_povuv_face(const field_mesh *m, int k, povuv_face *f)
{
    double pos[3][3], nrm[3][3], uv[3][2];
    for (int j = 0; j < 3; j++) {
        int i = m->tri[k][j];
        for (int c = 0; c < 3; c++)
            pos[j][c] = m->pos[i][c], nrm[j][c] = m->nrm[i][c];
        uv_of(m, i, uv[j]);
    }
    povuv_face_init(f, pos, nrm, uv);
}

static int write_camera(FILE *out, const char *name, const double world[12], const char *placement);

/* %.9g gives back a float32 exactly; %.17g a dyadic UV exactly (it has few digits). */
int field_mesh_write_include(FILE *out, const field_mesh *m, const char *name, const double world[12],
                             const char *placement)
{
    /* as the pixel table's include (docs/povray.md, "Output and gamma"): raise the language
       version to 3.7 only when it is lower, and put it back */
    fprintf(out, "// lens2pov ray field: sub-images of rays for mesh_camera (distribution 3, smooth).\n"
                 "#if (version < 3.7)\n  #declare Lens2pov_Version = version;\n  #version 3.7;\n#end\n");
    if (m->faces == 0) {
        /* A render none of whose pixels the lens passes (POV-Ray refuses a mesh without
           vertices): one face of zero area, in space and in UV, with equal normals. POV-Ray
           drops it when parsing, and kept, its UV weights would be 0/0 at every pixel (as
           povuv_mesh_find computes them): no pixel is traced, all black, alpha 0. */
        fprintf(out, "#declare %s = mesh2 {\n  vertex_vectors { 3, <0,0,0>, <0,0,0>, <0,0,0> }\n"
                     "  normal_vectors { 3, <0,0,1>, <0,0,1>, <0,0,1> }\n"
                     "  uv_vectors { 3, <0,0>, <0,0>, <0,0> }\n  face_indices { 1, <0,1,2> }\n", name);
        return write_camera(out, name, world, placement);
    }
    fprintf(out, "#declare %s = mesh2 {\n  vertex_vectors { %d", name, m->vertices);
    for (int i = 0; i < m->vertices; i++)
        fprintf(out, ",\n<%.9g,%.9g,%.9g>", m->pos[i][0], m->pos[i][1], m->pos[i][2]);
    fprintf(out, " }\n  normal_vectors { %d", m->vertices);
    for (int i = 0; i < m->vertices; i++)
        fprintf(out, ",\n<%.9g,%.9g,%.9g>", m->nrm[i][0], m->nrm[i][1], m->nrm[i][2]);
    fprintf(out, " }\n  uv_vectors { %d", m->vertices);
    for (int i = 0; i < m->vertices; i++) {
        double uv[2];
        uv_of(m, i, uv);
        fprintf(out, ",\n<%.17g,%.17g>", uv[0], uv[1]);
    }
    fprintf(out, " }\n  face_indices { %d", m->faces);
    for (int i = 0; i < m->faces; i++)
        fprintf(out, ",\n<%d,%d,%d>", m->tri[i][0], m->tri[i][1], m->tri[i][2]);
    fprintf(out, " }\n");
    return write_camera(out, name, world, placement);
}

/* The end of the mesh, and the camera of it with its transforms. */
static int write_camera(FILE *out, const char *name, const double world[12], const char *placement)
{
    fprintf(out, "  hierarchy off\n}\n");
    fprintf(out, "camera { mesh_camera { 1 3 mesh { %s matrix <", name);
    for (int i = 0; i < 12; i++)
        fprintf(out, "%.17g%s", world[i], i < 11 ? ", " : "");
    fprintf(out, ">%s%s%s } smooth } }\n#undef %s\n", placement ? " transform { " : "",
            placement ? placement : "", placement ? " }" : "", name);
    fprintf(out, "#ifdef (Lens2pov_Version)\n  #version Lens2pov_Version;\n  #undef Lens2pov_Version\n#end\n");
    return ferror(out) ? -1 : 0;
}
