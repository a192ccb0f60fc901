#include "base/workers.h"

#include <pthread.h>

void workers_run(void *(*worker)(void *), void *arg, int threads)
{
    pthread_t t[64];
    int started = 0;
    for (int i = 0; i < threads && i < 64; i++)
        if (pthread_create(&t[started], NULL, worker, arg) == 0)
            started++;
    if (started == 0)
        worker(arg);
    for (int i = 0; i < started; i++)
        pthread_join(t[i], NULL);
}
