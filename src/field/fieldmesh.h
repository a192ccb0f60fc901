/* A distribution-3 camera mesh being built: vertices with the float32 positions and normals
   POV-Ray will hold, their UVs, and faces. */
#ifndef LENS2POV_FIELD_FIELDMESH_H
#define LENS2POV_FIELD_FIELDMESH_H

#include <stdio.h>
#include "field/povuv.h"

typedef struct field_mesh {
    int vertices, faces;
    int vertex_cap, face_cap;
    float (*pos)[3];      /* mesh space: camera space minus the lens's front vertex, mm */
    float (*nrm)[3];      /* ray directions, as written (POV-Ray normalizes them again) */
    double (*uv)[2];      /* dyadic: exact in the file */
    int (*tri)[3];
} field_mesh;

void field_mesh_init(field_mesh *m);
void field_mesh_free(field_mesh *m);
void field_mesh_clear(field_mesh *m);   /* no vertices, no faces; keeps the memory */

/* Appends a vertex (rounded to float32 as POV-Ray stores it) and returns its index, -1 when
   out of memory. */
int field_mesh_vertex(field_mesh *m, vec3 pos, vec3 nrm, double u, double v);
int field_mesh_face(field_mesh *m, int a, int b, int c);

/* Face k as POV-Ray parses it. */
void field_mesh_povuv_face(const field_mesh *m, int k, povuv_face *f);

/* The include: `#declare NAME = mesh2 {...}` with vertex_vectors, normal_vectors, uv_vectors
   and face_indices, then the camera `mesh_camera { 1 3 mesh { NAME matrix <m> } smooth }`.
   world is the mesh-to-world map as POV-Ray's 4x3 matrix (rows: images of x, y, z, then the
   translation). Returns 0, or -1 on a write error. */
int field_mesh_write_include(FILE *out, const field_mesh *m, const char *name, const double world[12]);

#endif
