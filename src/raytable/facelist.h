/* The faces of one mesh2 while its vertices are written: where each face's three vertices lie
   among those written before it, two bits a face, replayed into face_indices at the end (the
   vertices come first in a mesh2, so the indices cannot be written as the faces come). */
#ifndef LENS2POV_FACELIST_H
#define LENS2POV_FACELIST_H

#include <stdint.h>
#include "base/textout.h"

/* With n vertices written before the face: */
enum face_code {
    FACE_OWN = 0,           /* <n, n+1, n+2>, three vertices of its own */
    FACE_OWN_SWAPPED = 1,   /* <n+1, n, n+2> */
    FACE_SHARED = 2,        /* <n-3, n-2, n>, the edge of the face before and one of its own */
    FACE_SHARED_SWAPPED = 3 /* <n-2, n-3, n> */
};

typedef struct face_list {
    uint8_t *codes;         /* four faces a byte */
    size_t cap;
    long long faces, vertices;
} face_list;

/* Adds a face; -1 out of memory. */
int face_list_add(face_list *f, enum face_code code);

/* "face_indices { N," and the faces' index triples. */
int face_list_write(const face_list *f, text_out *t, l2p_error *err);

void face_list_free(face_list *f);

#endif
