/* Where temporary folders go: $TMPDIR when it is set and not empty, else /tmp. */
#ifndef LENS2POV_TEMPDIR_H
#define LENS2POV_TEMPDIR_H

#include <stdlib.h>

static inline const char *temp_root(void)
{
    const char *tmp = getenv("TMPDIR");
    return tmp && *tmp ? tmp : "/tmp";
}

#endif
