#include "base/textout.h"

#include <stdlib.h>

const char text_digit_pairs[201] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

int text_open(text_out *t, const char *path, l2p_error *err)
{
    t->len = 0;
    t->buf = malloc(TEXT_OUT_BUFFER + 4096);
    if (!t->buf)
        return l2p_fail(err, L2P_FAILED, path, 0, "out of memory");
    return outfile_open(&t->file, path, err);
}

int text_flush(text_out *t, l2p_error *err)
{
    if (t->len && fwrite(t->buf, 1, t->len, t->file.fp) != t->len)
        return l2p_fail(err, L2P_FAILED, t->file.final_path, 0, "write failed");
    t->len = 0;
    return L2P_OK;
}

int text_reserve(text_out *t, size_t n, l2p_error *err)
{
    return t->len + n > TEXT_OUT_BUFFER ? text_flush(t, err) : L2P_OK;
}

void text_release(text_out *t)
{
    free(t->buf);
    t->buf = NULL;
}

void text_discard(text_out *t)
{
    outfile_discard(&t->file);
    text_release(t);
}
