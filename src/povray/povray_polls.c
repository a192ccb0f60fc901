/* lens2pov-povray-polls.so, preloaded (LD_PRELOAD) into the POV-Ray processes lens2pov starts:
   POV-Ray 3.7's threads hand work to each other by polling, each poll a timed wait of 10 to
   100 ms, so a run idles about half a second before its first frame and about a quarter of a
   second between frames. Here every such wait of at most LONGEST_POLL_NS ends after POLL_NS
   instead, as if its time had run out; longer waits are left as they are (POV-Ray crashed at
   start-up when those were cut short too). What POV-Ray computes does not change, only how
   soon its threads look again (docs/povray.md, "Polls"). A shorter POLL_NS costs POV-Ray CPU
   time that a render which keeps both cores busy misses.

   The library is built without the sanitizers (POV-Ray has no sanitizer runtime) and is not
   part of liblens2pov. It acts only in the process lens2pov started itself: the one whose
   parent's pid is LENS2POV_POLLS_PARENT, so that programs POV-Ray or a stand-in script start
   keep their waits. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

static const long long POLL_NS = 5000000;           /* what a poll is shortened to */
static const long long LONGEST_POLL_NS = 200000000; /* POV-Ray polls every 10, 50 or 100 ms */
static const long long NS = 1000000000;

static bool active;
static int (*real_nanosleep)(const struct timespec *, struct timespec *);
static int (*real_clock_nanosleep)(clockid_t, int, const struct timespec *, struct timespec *);
static int (*real_cond_timedwait)(pthread_cond_t *, pthread_mutex_t *, const struct timespec *);

/* Exported so that a test can see whether the library acts in a process. */
bool lens2pov_polls_active(void) { return active; }

__attribute__((constructor)) static void start(void)
{
    real_nanosleep = (int (*)(const struct timespec *, struct timespec *))dlsym(RTLD_NEXT, "nanosleep");
    real_clock_nanosleep = (int (*)(clockid_t, int, const struct timespec *, struct timespec *))
        dlsym(RTLD_NEXT, "clock_nanosleep");
    real_cond_timedwait = (int (*)(pthread_cond_t *, pthread_mutex_t *, const struct timespec *))
        dlvsym(RTLD_NEXT, "pthread_cond_timedwait", "GLIBC_2.3.2");
    const char *parent = getenv("LENS2POV_POLLS_PARENT");
    active = parent && *parent && atoll(parent) == (long long)getppid() && real_nanosleep &&
             real_clock_nanosleep && real_cond_timedwait;
}

static long long ns_of(const struct timespec *t) { return t->tv_sec * NS + t->tv_nsec; }
static struct timespec timespec_of(long long ns) { return (struct timespec){ns / NS, ns % NS}; }

static bool is_poll(long long ns) { return active && ns > POLL_NS && ns <= LONGEST_POLL_NS; }

int nanosleep(const struct timespec *req, struct timespec *rem)
{
    if (!real_nanosleep)
        return errno = ENOSYS, -1;
    if (!req || !is_poll(ns_of(req)))
        return real_nanosleep(req, rem);
    const struct timespec poll = timespec_of(POLL_NS);
    return real_nanosleep(&poll, rem);
}

int clock_nanosleep(clockid_t clock, int flags, const struct timespec *req, struct timespec *rem)
{
    if (!real_clock_nanosleep)
        return ENOSYS;
    if (!req || (flags & TIMER_ABSTIME) || !is_poll(ns_of(req)))
        return real_clock_nanosleep(clock, flags, req, rem);
    const struct timespec poll = timespec_of(POLL_NS);
    return real_clock_nanosleep(clock, flags, &poll, rem);
}

/* The deadline is absolute on the clock the condition variable was made with, which cannot be
   asked; Boost's are monotonic (time since boot), glibc's default is the real time (since
   1970). The two are decades apart, so the clock whose now lies just before the deadline is
   the one. */
int pthread_cond_timedwait(pthread_cond_t *cond, pthread_mutex_t *mutex,
                           const struct timespec *deadline)
{
    if (!real_cond_timedwait)
        return ENOSYS;
    if (active) {
        const clockid_t clocks[2] = {CLOCK_MONOTONIC, CLOCK_REALTIME};
        for (int i = 0; i < 2; i++) {
            struct timespec now;
            clock_gettime(clocks[i], &now);
            if (is_poll(ns_of(deadline) - ns_of(&now))) {
                const struct timespec sooner = timespec_of(ns_of(&now) + POLL_NS);
                return real_cond_timedwait(cond, mutex, &sooner);
            }
        }
    }
    return real_cond_timedwait(cond, mutex, deadline);
}
