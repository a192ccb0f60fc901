#include "raytable/facelist.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>

int face_list_add(face_list *f, unsigned kind)
{
    const unsigned stored = kind & (FACE_SWAPPED | FACE_SHARES_EDGE);
    const size_t byte = (size_t)(f->faces >> 2);
    if (byte >= f->cap) {
        const size_t cap = f->cap ? 2 * f->cap : 4096;
        uint8_t *grown = realloc(f->kinds, cap);
        if (!grown)
            return -1;
        memset(grown + f->cap, 0, cap - f->cap);
        f->kinds = grown;
        f->cap = cap;
    }
    f->kinds[byte] |= (uint8_t)(stored << (2 * (f->faces & 3)));
    f->faces++;
    f->vertices += stored & FACE_SHARES_EDGE ? 1 : 3;
    return 0;
}

static void put_triple(text_out *t, uint64_t a, uint64_t b, uint64_t c)
{
    t->buf[t->len++] = '<';
    text_put_uint(t, a);
    t->buf[t->len++] = ',';
    text_put_uint(t, b);
    t->buf[t->len++] = ',';
    text_put_uint(t, c);
    text_put(t, ">,\n", 3);
}

int face_list_write(const face_list *f, text_out *t, l2p_error *err)
{
    int st = text_reserve(t, 64, err);
    if (st)
        return st;
    t->len += (size_t)snprintf(t->buf + t->len, 64, "  face_indices { %lld,\n", f->faces);
    uint64_t n = 0;   /* vertices before the face */
    /* A face takes at most 3 * 20 + 6 bytes; batches of 4096 fit in 4096 * 72. */
    for (long long done = 0; done < f->faces;) {
        const long long end = f->faces - done < 4096 ? f->faces : done + 4096;
        if ((st = text_reserve(t, 4096 * 72, err)) != 0)
            return st;
        for (; done < end; done++) {
            const unsigned kind = f->kinds[done >> 2] >> (2 * (done & 3)) & 3;
            const bool swapped = kind & FACE_SWAPPED;
            if (!(kind & FACE_SHARES_EDGE)) {
                put_triple(t, swapped ? n + 1 : n, swapped ? n : n + 1, n + 2);
                n += 3;
            } else {
                put_triple(t, swapped ? n - 2 : n - 3, swapped ? n - 3 : n - 2, n);
                n += 1;
            }
        }
    }
    return L2P_OK;
}

void face_list_free(face_list *f)
{
    free(f->kinds);
    f->kinds = NULL;
    f->cap = 0;
}
