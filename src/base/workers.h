/* Running one function on several threads that share its work. */
#ifndef LENS2POV_WORKERS_H
#define LENS2POV_WORKERS_H

/* worker(arg) on up to threads threads (at most 64) and waits for them all; on this thread
   when none starts. The worker takes its share of the work from arg (an atomic counter). */
void workers_run(void *(*worker)(void *), void *arg, int threads);

#endif
