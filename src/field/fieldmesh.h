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
    double (*pix)[2];     /* the vertex's place in the final picture of the render, pixels;
                             its UV (povuv_pixel_uv) is dyadic, exact in the file */
    int (*tri)[3];
    int render_w, render_h;   /* the final picture of the render (POV-Ray renders one more) */
} field_mesh;

/* An empty mesh for a render whose final picture is render_w x render_h. Choosing render_w + 1
   and render_h + 1 powers of two makes every UV a short binary fraction. */
void field_mesh_init(field_mesh *m, int render_w, int render_h);
void field_mesh_free(field_mesh *m);
void field_mesh_clear(field_mesh *m);   /* no vertices, no faces; keeps the memory */

/* Appends a vertex (rounded to float32 as POV-Ray stores it) at pixel position (x, y) of the
   render's final picture (a pixel's own position is whole) and returns its index, -1 when out
   of memory. */
int field_mesh_vertex(field_mesh *m, vec3 pos, vec3 nrm, double x, double y);

/* Its arrays cut to what it holds (a mesh kept until its render is written takes no more). */
void field_mesh_shrink(field_mesh *m);

/* Appends src moved by (dx, dy) pixels, its UVs recomputed for m's render. With both
   renders' sizes plus one powers of two, the UV barycentric weights of every pixel are the
   same before and after: they are computed exactly, and an affine map of the plane keeps
   them. Returns -1 when out of memory. */
int field_mesh_append(field_mesh *m, const field_mesh *src, int dx, int dy);
int field_mesh_face(field_mesh *m, int a, int b, int c);

/* Puts the faces in order of their pixel area, largest first (ties keep their order).
   POV-Ray takes, for each pixel, the first face in order that holds it, scanning the faces of
   one cell of a 10 x 10 grid over UV; largest first, most pixels find theirs early. Any order
   gives the same rays: a pixel that several faces hold was checked against each of them.
   Returns -1 when out of memory. */
int field_mesh_sort_faces_by_area(field_mesh *m);

/* Face k as POV-Ray parses it. */
void field_mesh_povuv_face(const field_mesh *m, int k, povuv_face *f);

/* The include: `#declare NAME = mesh2 {...}` with vertex_vectors, normal_vectors, uv_vectors
   and face_indices, then the camera `mesh_camera { 1 3 mesh { NAME matrix <m> } smooth }`.
   world is the mesh-to-world map as POV-Ray's 4x3 matrix (rows: images of x, y, z, then the
   translation). placement names a transform applied after it (an animation frame's), NULL:
   none. Returns 0, or -1 on a write error. */
int field_mesh_write_include(FILE *out, const field_mesh *m, const char *name, const double world[12],
                             const char *placement);

#endif
