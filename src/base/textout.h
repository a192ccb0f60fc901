/* A text file written through a large buffer, with whole numbers formatted by hand: printf's
   %g costs several times the rest of a ray's work. The file is an outfile (a temporary name,
   renamed when complete). The put functions also serve a bare buffer (no file) of known room. */
#ifndef LENS2POV_TEXTOUT_H
#define LENS2POV_TEXTOUT_H

#include <stdint.h>
#include <string.h>
#include "base/error.h"
#include "base/outfile.h"

enum { TEXT_OUT_BUFFER = 1 << 20 };

typedef struct text_out {
    outfile file;
    char *buf;     /* TEXT_OUT_BUFFER bytes and a 4 KB margin for a closing snprintf */
    size_t len;
} text_out;

int text_open(text_out *t, const char *path, l2p_error *err);

/* Writes the buffer out. */
int text_flush(text_out *t, l2p_error *err);

/* Makes room for n more bytes (n <= TEXT_OUT_BUFFER), flushing when needed. */
int text_reserve(text_out *t, size_t n, l2p_error *err);

/* Frees the buffer (the file stays as it is). */
void text_release(text_out *t);

/* Removes the temporary file and frees the buffer. */
void text_discard(text_out *t);

static inline void text_put(text_out *t, const char *s, size_t n)
{
    memcpy(t->buf + t->len, s, n);
    t->len += n;
}

static inline void text_put_str(text_out *t, const char *s) { text_put(t, s, strlen(s)); }

extern const char text_digit_pairs[201];

/* v in decimal, two digits a step. */
static inline void text_put_uint(text_out *t, uint64_t v)
{
    char tmp[24];
    int n = 0;
    while (v >= 100) {
        const unsigned r = (unsigned)(v % 100);
        v /= 100;
        tmp[n++] = text_digit_pairs[2 * r + 1];
        tmp[n++] = text_digit_pairs[2 * r];
    }
    if (v >= 10) {
        tmp[n++] = text_digit_pairs[2 * v + 1];
        tmp[n++] = text_digit_pairs[2 * v];
    } else {
        tmp[n++] = (char)('0' + v);
    }
    while (n)
        t->buf[t->len++] = tmp[--n];
}

#endif
