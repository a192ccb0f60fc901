/* The processors this process may run on: the default number of POV-Ray jobs and of tracing
   threads. */
#ifndef LENS2POV_CORES_H
#define LENS2POV_CORES_H

#include <unistd.h>

static inline int cores_online(void)
{
    const long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 && n < 4096 ? (int)n : 1;
}

#endif
