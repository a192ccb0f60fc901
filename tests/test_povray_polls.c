/* The library that shortens POV-Ray's polls (src/povray/povray_polls.c) and the environment
   that preloads it into POV-Ray (src/povray/povray_env.c): in the process lens2pov started, a
   wait of up to 200 ms ends after 5 ms, as if its time had run out; longer
   waits, and every wait of any other process, last as long as asked; a render gets the same
   pictures bit for bit with the library and without, and POV-Ray is started with it.

   The library is dlopen()ed here (Criterion runs each test in a process of its own), its
   functions called through dlsym: what it does to a wait does not depend on how it was
   loaded. Waits that must not be shortened are checked to last at least as long as asked,
   which any correct wait does; shortened ones to end within half the time asked, ten times
   the 5 ms they take. */
#include <criterion/criterion.h>
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "image/image_io.h"
#include "povray/povray_env.h"
#include "support.h"

#define DGAUSS LENS_DIR "dgauss.50mm.dat"
#define L2P(out, errtext, ...) run_lens2pov(out, errtext, __VA_ARGS__, (char *)NULL)

typedef int nanosleep_fn(const struct timespec *, struct timespec *);
typedef int clock_nanosleep_fn(clockid_t, int, const struct timespec *, struct timespec *);
typedef int timedwait_fn(pthread_cond_t *, pthread_mutex_t *, const struct timespec *);

typedef struct polls {
    bool active;
    nanosleep_fn *nanosleep;
    clock_nanosleep_fn *clock_nanosleep;
    timedwait_fn *timedwait;
} polls;

/* The library as the process whose parent is parent_pid would have it. */
static polls load(long parent_pid)
{
    char path[PATH_MAX + 64], pid[32];
    cr_assert(povray_polls_library(path, sizeof path), "the library is not beside run_tests");
    snprintf(pid, sizeof pid, "%ld", parent_pid);
    cr_assert_eq(setenv("LENS2POV_POLLS_PARENT", pid, 1), 0);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    cr_assert_not_null(h, "%s", dlerror());
    bool (*active)(void) = (bool (*)(void))dlsym(h, "lens2pov_polls_active");
    polls p = {active && active(), (nanosleep_fn *)dlsym(h, "nanosleep"),
               (clock_nanosleep_fn *)dlsym(h, "clock_nanosleep"),
               (timedwait_fn *)dlsym(h, "pthread_cond_timedwait")};
    cr_assert(active && p.nanosleep && p.clock_nanosleep && p.timedwait);
    return p;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static struct timespec ms(long n) { return (struct timespec){n / 1000, n % 1000 * 1000000L}; }

static double slept_s(const polls *p, long n)
{
    const struct timespec t = ms(n);
    const double start = now_s();
    cr_assert_eq(p->nanosleep(&t, NULL), 0);
    return now_s() - start;
}

static double clock_slept_s(const polls *p, long n)
{
    const struct timespec t = ms(n);
    const double start = now_s();
    cr_assert_eq(p->clock_nanosleep(CLOCK_MONOTONIC, 0, &t, NULL), 0);
    return now_s() - start;
}

/* A wait of n ms on a condition variable of the given clock that nobody signals: it times
   out (ETIMEDOUT) either way; the seconds it took. */
static double waited_s(const polls *p, clockid_t clock, long n)
{
    pthread_condattr_t a;
    pthread_cond_t c;
    pthread_mutex_t m = PTHREAD_MUTEX_INITIALIZER;
    pthread_condattr_init(&a);
    pthread_condattr_setclock(&a, clock);
    pthread_cond_init(&c, &a);
    const double start = now_s();   /* before the deadline is set: no more than asked */
    struct timespec deadline;
    clock_gettime(clock, &deadline);
    deadline.tv_nsec += n * 1000000L;
    deadline.tv_sec += deadline.tv_nsec / 1000000000L;
    deadline.tv_nsec %= 1000000000L;
    pthread_mutex_lock(&m);
    int r;
    while ((r = p->timedwait(&c, &m, &deadline)) == 0)
        continue;
    pthread_mutex_unlock(&m);
    const double took = now_s() - start;
    cr_assert_eq(r, ETIMEDOUT);
    pthread_cond_destroy(&c);
    pthread_condattr_destroy(&a);
    return took;
}

Test(povray_polls, a_poll_ends_early_in_the_process_lens2pov_started)
{
    const polls p = load((long)getppid());
    cr_assert(p.active);
    cr_expect_lt(slept_s(&p, 200), 0.1);
    cr_expect_lt(clock_slept_s(&p, 100), 0.05);
    /* not a valid wait: refused as before */
    const struct timespec bad = {0, 1000000000L};
    cr_expect_eq(p.nanosleep(&bad, NULL), -1);
    cr_expect_eq(errno, EINVAL);
    cr_expect_lt(waited_s(&p, CLOCK_MONOTONIC, 150), 0.075);
    cr_expect_lt(waited_s(&p, CLOCK_REALTIME, 150), 0.075);
    /* longer than any poll: left alone */
    cr_expect_geq(slept_s(&p, 250), 0.25);
    cr_expect_geq(waited_s(&p, CLOCK_MONOTONIC, 300), 0.3);
    cr_expect_geq(waited_s(&p, CLOCK_REALTIME, 300), 0.3);
}

Test(povray_polls, other_processes_keep_their_waits)
{
    const polls p = load((long)getppid() + 1);
    cr_assert_not(p.active);
    cr_expect_geq(slept_s(&p, 60), 0.06);
    cr_expect_geq(clock_slept_s(&p, 60), 0.06);
    cr_expect_geq(waited_s(&p, CLOCK_MONOTONIC, 60), 0.06);
    cr_expect_geq(waited_s(&p, CLOCK_REALTIME, 60), 0.06);
}

/* How many of env's entries start with prefix; the last in *found. */
static int entries(char **env, const char *prefix, const char **found)
{
    int n = 0;
    for (size_t i = 0; env[i]; i++)
        if (strncmp(env[i], prefix, strlen(prefix)) == 0)
            n++, *found = env[i];
    return n;
}

Test(povray_polls, povray_gets_the_library_before_the_users)
{
    char path[PATH_MAX + 64], want[2 * PATH_MAX], pid[64];
    cr_assert(povray_polls_library(path, sizeof path));
    setenv("LD_PRELOAD", "/opt/theirs.so", 1);
    setenv("LENS2POV_POLLS_PARENT", "1", 1);
    setenv("LENS2POV_TEST_KEPT", "yes", 1);
    char **env = povray_environment();
    cr_assert_not_null(env);
    const char *e = NULL;
    snprintf(want, sizeof want, "LD_PRELOAD=%s:/opt/theirs.so", path);
    cr_expect_eq(entries(env, "LD_PRELOAD=", &e), 1);
    cr_expect_str_eq(e, want);
    snprintf(pid, sizeof pid, "LENS2POV_POLLS_PARENT=%ld", (long)getpid());
    cr_expect_eq(entries(env, "LENS2POV_POLLS_PARENT=", &e), 1);
    cr_expect_str_eq(e, pid);
    cr_expect_eq(entries(env, "LENS2POV_TEST_KEPT=yes", &e), 1);
    povray_environment_free(env);

    setenv("LENS2POV_POVRAY_POLLS", "off", 1);
    cr_expect_not(povray_polls_library(path, sizeof path));
    env = povray_environment();
    cr_expect_eq(entries(env, "LD_PRELOAD=", &e), 1);
    cr_expect_str_eq(e, "LD_PRELOAD=/opt/theirs.so");
    povray_environment_free(env);
}

/* A scene whose camera moves with the clock, rendered as a two-frame animation: the probe
   and the render both run POV-Ray through a script that notes what it was given and then
   becomes POV-Ray (exec: the same process, lens2pov its parent). */
static const char *SCENE =
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
    "light_source { <-3, 5, -4> rgb 1 }\n"
    "plane { y, 0 pigment { checker rgb 0.9 rgb 0.1 scale 0.5 } }\n"
    "sphere { <0.3, 0.8, 0.5>, 0.8 pigment { rgb <0.8, 0.2, 0.1> } }\n"
    "camera { location <clock - 0.5, 1, -4> look_at <0, 0.7, 0> angle 40 }\n";

static float *frame(const char *dir, const char *name, int *w, int *h)
{
    float *px = NULL;
    cr_assert_eq(image_read_rgba(tmp_path(dir, name), w, h, &px, NULL), 0, "%s", name);
    return px;
}

Test(povray_polls, pictures_are_the_same_with_the_library_and_without)
{
    const char *dir = test_tmpdir();
    char scene[600], script[600], text[1600];
    snprintf(scene, sizeof scene, "%s/scene.pov", dir);
    write_text(scene, SCENE);
    snprintf(script, sizeof script, "%s/notepov", dir);
    snprintf(text, sizeof text,
             "#!/bin/sh\necho \"$PPID $LENS2POV_POLLS_PARENT $LD_PRELOAD\" >> '%s/given'\n"
             "exec povray \"$@\"\n", dir);
    write_text(script, text);
    cr_assert_eq(chmod(script, 0755), 0);
    setenv("LENS2POV_POVRAY", script, 1);
    const char *const modes[2] = {"on", "off"};
    for (int i = 0; i < 2; i++) {
        setenv("LENS2POV_POVRAY_POLLS", modes[i], 1);
        char out[64], *errtext = NULL;
        snprintf(out, sizeof out, "%s.exr", modes[i]);
        const int st = L2P(NULL, &errtext, "render", scene, DGAUSS, "--width", "40", "--height",
                           "30", "--spp", "4", "-q", "-o", tmp_path(dir, out), "--", "+KFI1",
                           "+KFF2");
        cr_assert_eq(st, 0, "%s", errtext ? errtext : "");
        free(errtext);
    }
    for (int f = 1; f <= 2; f++) {
        char on[32], off[32];
        snprintf(on, sizeof on, "on%d.exr", f);
        snprintf(off, sizeof off, "off%d.exr", f);
        int w, h, w2, h2;
        float *a = frame(dir, on, &w, &h), *b = frame(dir, off, &w2, &h2);
        cr_assert(w == w2 && h == h2);
        cr_expect_eq(memcmp(a, b, sizeof *a * 4 * (size_t)w * (size_t)h), 0, "frame %d differs", f);
        free(a);
        free(b);
    }
    /* With the library on, every POV-Ray was lens2pov's child and had it preloaded first;
       with it off, none. */
    char path[PATH_MAX + 64];
    unsetenv("LENS2POV_POVRAY_POLLS");
    cr_assert(povray_polls_library(path, sizeof path));
    char *given = read_text(tmp_path(dir, "given"), NULL);
    cr_assert_not_null(given);
    int with = 0, without = 0;
    for (char *line = strtok(given, "\n"); line; line = strtok(NULL, "\n")) {
        long ppid, parent;
        char preload[PATH_MAX + 64] = "";
        const int n = sscanf(line, "%ld %ld %s", &ppid, &parent, preload);
        preload[strcspn(preload, ":")] = '\0';   /* the user's own preloads follow */
        if (n == 3 && ppid == parent && strcmp(preload, path) == 0)
            with++;
        else if (n < 2)
            without++;
    }
    cr_expect_geq(with, 2, "%s", given);   /* the probe and at least one render */
    cr_expect_geq(without, 2, "%s", given);
    free(given);
    unsetenv("LENS2POV_POVRAY");
}
