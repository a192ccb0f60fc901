#include "base/error.h"

#include <stdarg.h>
#include <stdio.h>

int l2p_fail(l2p_error *err, int status, const char *file, int line, const char *fmt, ...)
{
    if (!err)
        return status;
    size_t n = 0;
    if (file && line > 0)
        n = (size_t)snprintf(err->text, sizeof err->text, "%s:%d: ", file, line);
    else if (file)
        n = (size_t)snprintf(err->text, sizeof err->text, "%s: ", file);
    if (n >= sizeof err->text)
        n = sizeof err->text - 1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->text + n, sizeof err->text - n, fmt, ap);
    va_end(ap);
    err->status = status;
    return status;
}
