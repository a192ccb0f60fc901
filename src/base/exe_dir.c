#include "base/exe_dir.h"

#include <errno.h>
#include <string.h>
#include <unistd.h>

bool exe_dir(char *dir, size_t size, const char **why)
{
    const ssize_t n = readlink("/proc/self/exe", dir, size);
    if (n <= 0 || (size_t)n >= size) {
        *why = n < 0 ? strerror(errno) : "path too long";
        return false;
    }
    dir[n] = '\0';
    char *slash = strrchr(dir, '/');
    if (!slash) {
        *why = "not an absolute path";
        return false;
    }
    *slash = '\0';
    return true;
}
