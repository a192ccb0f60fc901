#include "base/readfile.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

char *read_whole_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    for (size_t got; buf && (got = fread(buf + len, 1, cap - len, f)) > 0;) {
        len += got;
        char *grown = len == cap ? realloc(buf, cap *= 2) : buf;
        if (!grown)
            free(buf);
        buf = grown;
    }
    const int read_error = ferror(f);
    fclose(f);
    if (!buf || read_error) {
        const int why = buf ? EIO : ENOMEM;
        free(buf);
        errno = why;
        return NULL;
    }
    buf[len] = '\0';   /* len < cap: the loop grows the buffer when it is full */
    *n = len;
    return buf;
}
