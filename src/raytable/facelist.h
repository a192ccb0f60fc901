/* The faces of one mesh2 while its vertices are written: where each face's three vertices lie
   among those written before it, two bits a face, replayed into face_indices at the end (the
   vertices come first in a mesh2, so the indices cannot be written as the faces come). */
#ifndef LENS2POV_FACELIST_H
#define LENS2POV_FACELIST_H

#include <stdint.h>
#include "base/textout.h"

/* Where a face's vertices lie among the n written before it, as bits. A face of its own is
   <n, n+1, n+2>; one that shares the edge of the face before is <n-3, n-2, n>. */
enum face_kind {
    FACE_SWAPPED = 1,       /* its first two vertices in the other order */
    FACE_SHARES_EDGE = 2,   /* the edge of the face before, and one vertex of its own */
    FACE_GIVES_EDGE = 4     /* the next face shares its first two vertices (not stored) */
};

typedef struct face_list {
    uint8_t *kinds;         /* FACE_SWAPPED | FACE_SHARES_EDGE, four faces a byte */
    size_t cap;
    long long faces, vertices;
} face_list;

/* Adds a face of the given kind; -1 out of memory. */
int face_list_add(face_list *f, unsigned kind);

/* "face_indices { N," and the faces' index triples. */
int face_list_write(const face_list *f, text_out *t, l2p_error *err);

void face_list_free(face_list *f);

#endif
