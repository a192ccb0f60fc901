/* A whole file read into memory. */
#ifndef LENS2POV_READFILE_H
#define LENS2POV_READFILE_H

#include <stddef.h>

/* The file at path, NUL-terminated (malloc'd), *n its length; NULL with errno set when it
   cannot be read (ENOMEM when memory ran out). */
char *read_whole_file(const char *path, size_t *n);

#endif
