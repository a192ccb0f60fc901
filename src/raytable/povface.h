/* Triangles that carry rays to POV-Ray's mesh_camera, which shoots a face's ray from its
   centroid (P1 + P2 + P3) / 3 along normalize((P3 - P1) x (P2 - P1)) (see
   docs/povray.md). POV-Ray stores vertices as float32, so a face is only
   as good as the ratio of its vertices' distance from the mesh's origin to its own size. */
#ifndef LENS2POV_POVFACE_H
#define LENS2POV_POVFACE_H

#include <stdbool.h>
#include "base/vec3.h"

/* The triangle of the ray (o, d) alone, d a unit vector: equilateral, circumradius size,
   centred on o, vertices in POV-Ray's winding. */
void povface_single(vec3 o, vec3 d, double size, vec3 v[3]);

/* Two rays on two triangles that share an edge, so that they take four vertices instead of
   six: the edge v[0] v[1], then v[2] for ray 1 and v[3] for ray 2. Ray k's face is
   (v[0], v[1], v[k + 1]), or (v[1], v[0], v[k + 1]) when swap[k - 1]. Each face has its ray's
   origin as centroid and its direction as normal, exactly in real arithmetic. Returns false
   (v untouched) when float32 vertices would spoil the pair: rays nearly parallel, whose shared
   edge lies far away, or a ray close to the edge. A pair is coarser than two lone triangles of
   circumradius size, within bounds: float32 moves its origins by at most 1.3e-5 of size and
   its directions by a few 1e-7 rad (docs/povray.md). The coordinates are relative to the
   mesh's origin, and non-finite input is refused. */
bool povface_pair(vec3 o1, vec3 d1, vec3 o2, vec3 d2, double size, vec3 v[4], bool swap[2]);

#endif
