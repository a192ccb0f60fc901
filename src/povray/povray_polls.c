/* lens2pov-povray-polls.so, preloaded (LD_PRELOAD) into the POV-Ray processes lens2pov starts:
   POV-Ray 3.7's threads hand work to each other by polling, each poll a timed wait of 10 to
   100 ms, so a run idles about 0.2 s before its first frame and about a quarter of a second
   between frames. Here every such wait of at most LONGEST_POLL_NS ends after POLL_NS instead,
   as if its time had run out. Longer waits are left as they are (POV-Ray crashed at start-up
   when those were cut short too), except that a long wait on a condition variable resumed
   within LONGEST_POLL_NS of its deadline counts as a poll. What POV-Ray computes does not
   change, only how soon its threads look again (docs/povray.md, "Polls"). A shorter POLL_NS
   costs POV-Ray CPU time that a render which keeps both cores busy misses.

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
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

static const long long POLL_NS = 5000000;           /* what a poll is shortened to */
static const long long LONGEST_POLL_NS = 200000000; /* POV-Ray polls every 10, 50 or 100 ms */
static const long long NS = 1000000000;

typedef int cond_timedwait_fn(pthread_cond_t *, pthread_mutex_t *, const struct timespec *);

static bool active;   /* set by start(), which may run after other libraries' constructors */

/* Exported so that a test can see whether the library acts in a process. */
bool lens2pov_polls_active(void) { return active; }

__attribute__((constructor)) static void start(void)
{
    const char *parent = getenv("LENS2POV_POLLS_PARENT");
    active = parent && *parent && atoll(parent) == (long long)getppid();
}

/* The next definition of a function, looked up on first use. pthread_cond_timedwait has two
   versions on x86-64 (the old one for programs of 2002 and before); the newer is the one
   programs link to, and on other architectures the only one, under another version name. */
static cond_timedwait_fn *real_cond_timedwait(void)
{
    static cond_timedwait_fn *f;
    if (!f) {
        void *p = dlvsym(RTLD_NEXT, "pthread_cond_timedwait", "GLIBC_2.3.2");
        f = (cond_timedwait_fn *)(p ? p : dlsym(RTLD_NEXT, "pthread_cond_timedwait"));
    }
    return f;
}

/* A relative wait's length, or -1 when it is not a valid one. */
static long long length_ns(const struct timespec *t)
{
    if (t->tv_nsec < 0 || t->tv_nsec >= NS || t->tv_sec < 0 || t->tv_sec > 1)
        return -1;
    return t->tv_sec * NS + t->tv_nsec;
}

static bool is_poll(long long ns) { return active && ns > POLL_NS && ns <= LONGEST_POLL_NS; }

/* The sleeps go straight to the kernel: no lookup can fail, even before start(). */
int nanosleep(const struct timespec *req, struct timespec *rem)
{
    const struct timespec poll = {0, POLL_NS};
    return (int)syscall(SYS_nanosleep, req && is_poll(length_ns(req)) ? &poll : req, rem);
}

int clock_nanosleep(clockid_t clock, int flags, const struct timespec *req, struct timespec *rem)
{
    const struct timespec poll = {0, POLL_NS};
    if (req && !(flags & TIMER_ABSTIME) && is_poll(length_ns(req)))
        req = &poll;
    /* the system call returns -1 and sets errno; clock_nanosleep returns the error */
    const int saved = errno;
    const long r = syscall(SYS_clock_nanosleep, clock, flags, req, rem);
    const int e = r == 0 ? 0 : errno;
    errno = saved;
    return e;
}

/* The deadline is absolute on the clock the condition variable was made with, which cannot be
   asked; Boost's are monotonic (time since boot), glibc's default is the real time (since
   1970). The two are decades apart, so the clock whose now lies just before the deadline is
   the one. */
int pthread_cond_timedwait(pthread_cond_t *cond, pthread_mutex_t *mutex,
                           const struct timespec *deadline)
{
    cond_timedwait_fn *wait = real_cond_timedwait();
    if (!wait)
        return ENOSYS;
    if (active && deadline->tv_nsec >= 0 && deadline->tv_nsec < NS) {
        const clockid_t clocks[2] = {CLOCK_MONOTONIC, CLOCK_REALTIME};
        for (int i = 0; i < 2; i++) {
            struct timespec now;
            clock_gettime(clocks[i], &now);
            if (deadline->tv_sec < now.tv_sec || deadline->tv_sec - now.tv_sec > 1)
                continue;
            const long long left = (deadline->tv_sec - now.tv_sec) * NS +
                                   (deadline->tv_nsec - now.tv_nsec);
            if (is_poll(left)) {
                const long long t = now.tv_nsec + POLL_NS;
                const struct timespec sooner = {now.tv_sec + t / NS, t % NS};
                return wait(cond, mutex, &sooner);
            }
        }
    }
    return wait(cond, mutex, deadline);
}
