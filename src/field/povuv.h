/* A model of POV-Ray 3.7.0.10's mesh_camera distribution 3 with `smooth`: the ray POV-Ray makes
   for a pixel from a mesh2 of vertex_vectors (origins), normal_vectors (directions) and
   uv_vectors (image positions). docs/povray.md, "Distribution 3", has the facts it relies on. */
#ifndef LENS2POV_FIELD_POVUV_H
#define LENS2POV_FIELD_POVUV_H

#include <stdbool.h>
#include <stdint.h>
#include "base/vec3.h"

/* The ray of a face as affine functions of (u, v) (povuv_face_affine). */
typedef struct povuv_affine {
    double u0, v0;          /* the UV of the face's first vertex */
    vec3 o0, ou, ov;        /* origin o = o0 + (u - u0) ou + (v - v0) ov */
    vec3 r0, ru, rv;        /* unnormalized direction, the same way */
} povuv_affine;

/* One face as POV-Ray holds it after parsing: float32 vertices and normals (the normals
   normalized in double first), double UVs, possibly with vertices 1 and 2 swapped
   (Compute_Mesh_Triangle) and the smoothing frame of Smooth_Mesh_Normal: Perp (float32) and
   the dominant axis of edge P2-P3. */
typedef struct povuv_face {
    float p[3][3];      /* vertex positions, mesh space */
    float n[3][3];      /* unit normals, swapped with the vertices only for a smooth face */
    double uv[3][2];
    float perp[3];
    int vaxis;
    bool swapped;       /* vertices 1 and 2 (and their UVs) swapped */
    bool smooth;        /* normals not all equal: |N1 - N2|^2 or |N1 - N3|^2 above 1e-10 */
    /* The same in double, as povuv_weighted_ray uses them at every pixel: P1, P2, P3, N1,
       N2 - N1, N3 - N2, Perp, and along vaxis P1, P2 and P3 - P2. */
    vec3 dp[3], dn1, dn21, dn32, dperp;
    double p1v, p2v, p32v;
    povuv_affine affine;
    bool has_affine;        /* every coefficient finite */
} povuv_face;

/* A face from its file values (vertex k of the face: position, normal, UV). */
void povuv_face_init(povuv_face *f, const double pos[3][3], const double nrm[3][3],
                     const double uv[3][2]);

/* POV-Ray's UV barycentric weights of (u, v) in the face (tracepixel.cpp); the face is taken
   when all three are >= 0. */
void povuv_face_weights(const povuv_face *f, double u, double v, double b[3]);

/* Whether the face holds (u, v): its weights all >= 0, found without dividing (povuv.c says
   when that is the same). */
bool povuv_face_holds(const povuv_face *f, double u, double v);

/* The ray of (u, v) through the face, mesh space: origin = sum b_k P_k, direction the
   normalized Smooth_Mesh_Normal. False when the direction is not finite. */
bool povuv_face_ray(const povuv_face *f, double u, double v, vec3 *o, vec3 *d);

/* The same from (u, v)'s weights b (povuv_face_weights), when they are known already. */
bool povuv_weighted_ray(const povuv_face *f, const double b[3], vec3 *o, vec3 *d);

/* The same ray from the face's affine form, for the mesh builder's check of every pixel:
   the origin, and the direction unnormalized (*r, whose length is not 1). The weights of
   povuv_face_weights are affine in (u, v), hence so is the origin; so are Smooth_Mesh_Normal's
   u (the distance along Perp) and its product with v (the edge coordinate), and its normal
   N1 + u (N2 - N1) + (u v) (N3 - N2) uses only those two. The form differs from
   povuv_weighted_ray by rounding, and where u is below 1e-10, at P1, where POV-Ray takes N1
   itself and the form N1 plus 1e-10 of the normals' difference. Usable when f->has_affine. */
void povuv_affine_ray(const povuv_face *f, double u, double v, vec3 *o, vec3 *r);

/* A whole mesh with POV-Ray's 10 x 10 UV grid of faces (Parse_Mesh_Camera). */
typedef struct povuv_mesh {
    int faces;
    povuv_face *face;
    int words;                  /* 32-bit words a bit set */
    uint32_t *ucol[10], *vrow[10];
} povuv_mesh;

/* Takes ownership of face (malloc'd, faces entries). Returns -1 when out of memory. */
int povuv_mesh_init(povuv_mesh *m, povuv_face *face, int faces);
void povuv_mesh_free(povuv_mesh *m);

/* The face POV-Ray takes for (u, v): the first in index order, among those whose UV box
   shares the point's grid cell, whose weights are all >= 0; -1 for none (pixel not traced). */
int povuv_mesh_find(const povuv_mesh *m, double u, double v);

/* The UV a pixel of the final picture samples with the work-around for FS#261: the render
   is (W+1) x (H+1) pixels, only rows 1..H and columns 0..W-1 are rendered (+SR2 +EC<W>), and
   final pixel (px, py) is render pixel (px, py + 1): u = px / (W+1), v = 1 - (py+1) / (H+1). */
void povuv_pixel_uv(int width, int height, int px, int py, double *u, double *v);

#endif
