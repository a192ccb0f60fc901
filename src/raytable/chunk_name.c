#include "raytable/chunk_name.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *chunk_file_name(const char *prefix, int index, const char *ext)
{
    const size_t n = strlen(prefix) + strlen(ext) + 32;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%s.c%03d.%s", prefix, index, ext);
    return p;
}
