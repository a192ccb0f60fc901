/* _Fork (glibc 2.34), for the signal handler. */
#define _GNU_SOURCE
#include "base/cleanup.h"

#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

/* Temporary paths to remove if a signal ends the run. A fixed table, so that the signal handler
   only reads memory that is never freed while it is registered. */
enum { MAX_TRACKED = 4096 };
static char *volatile tracked[MAX_TRACKED];

void cleanup_track(const char *temp_path)
{
    for (int i = 0; i < MAX_TRACKED; i++)
        if (!tracked[i]) {
            tracked[i] = strdup(temp_path);
            return;
        }
}

void cleanup_untrack(const char *temp_path)
{
    for (int i = 0; i < MAX_TRACKED; i++)
        if (tracked[i] && strcmp(tracked[i], temp_path) == 0) {
            char *p = tracked[i];
            tracked[i] = NULL;
            free(p);
            return;
        }
}

/* Child processes to stop with us (POV-Ray), and their count. */
enum { MAX_CHILDREN = 256 };
static volatile pid_t children[MAX_CHILDREN];

void cleanup_track_child(pid_t pid)
{
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (!children[i]) {
            children[i] = pid;
            return;
        }
}

void cleanup_untrack_child(pid_t pid)
{
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (children[i] == pid)
            children[i] = 0;
}

void cleanup_child_own_group(void)
{
    setpgid(0, 0);
}

void cleanup_track_child_group(pid_t pid)
{
    setpgid(pid, pid);   /* as the child does itself: whichever comes first */
    prctl(PR_SET_CHILD_SUBREAPER, 1);   /* what it leaves behind comes to us */
    cleanup_track_child(pid);
}

int cleanup_signal_child(pid_t pid, int sig)
{
    return kill(-pid, sig) == 0 || errno != ESRCH ? 0 : kill(pid, sig);
}

bool cleanup_reap_child_group(pid_t pid)
{
    pid_t w;
    while ((w = waitpid(-pid, NULL, WNOHANG)) > 0 || (w < 0 && errno == EINTR))
        continue;
    return w < 0;
}

void cleanup_end_child_group(pid_t pid)
{
    /* What is left is ours (the subreaper) and keeps the group's number from being reused. */
    if (cleanup_reap_child_group(pid))
        return;
    kill(-pid, SIGKILL);
    while (waitpid(-pid, NULL, 0) > 0 || errno == EINTR)
        continue;
}

/* A folder, with whatever is in it, goes through rm -rf in a child process: _Fork, execve and
   waitpid are async-signal-safe, readdir is not. Not fork: glibc's takes malloc's locks, and a
   signal that came inside malloc (dlopen of the image library, on this thread) deadlocked. */
static void remove_path(const char *path)
{
    if (unlink(path) == 0 || rmdir(path) == 0)
        return;
    pid_t pid = _Fork();
    if (pid == 0) {
        char *const argv[] = {"rm", "-rf", "--", (char *)path, NULL};
        char *const envp[] = {NULL};
        execve("/bin/rm", argv, envp);
        _exit(127);
    }
    if (pid > 0)
        waitpid(pid, NULL, 0);
}

/* Only async-signal-safe calls here. */
static void remove_tracked_and_die(int sig)
{
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (children[i] > 0) {
            cleanup_signal_child(children[i], SIGTERM);
            while (waitpid(-children[i], NULL, 0) > 0 || errno == EINTR)
                continue;
            while (waitpid(children[i], NULL, 0) < 0 && errno == EINTR)   /* one of ours */
                continue;
        }
    for (int i = MAX_TRACKED - 1; i >= 0; i--)
        if (tracked[i])
            remove_path(tracked[i]);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* Ctrl-Z: the children, each in a process group of its own that the terminal does not stop,
   are stopped with us and continued with us (the job-control handler of Stevens and Rago,
   "Advanced Programming in the UNIX Environment", 10.20). Only async-signal-safe calls. */
static void stop_with_children(int sig)
{
    const int saved = errno;
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (children[i] > 0)
            cleanup_signal_child(children[i], SIGSTOP);
    sigset_t tstp;
    sigemptyset(&tstp);
    sigaddset(&tstp, sig);
    signal(sig, SIG_DFL);
    raise(sig);
    sigprocmask(SIG_UNBLOCK, &tstp, NULL);   /* stops here until SIGCONT */
    sigprocmask(SIG_BLOCK, &tstp, NULL);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = stop_with_children;
    sigaction(sig, &sa, NULL);
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (children[i] > 0)
            cleanup_signal_child(children[i], SIGCONT);
    errno = saved;
}

void cleanup_block_signals(sigset_t *old)
{
    sigset_t block;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigaddset(&block, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &block, old);
}

int cleanup_start_thread(pthread_t *t, void *(*fn)(void *), void *arg)
{
    sigset_t old;
    cleanup_block_signals(&old);
    const int r = pthread_create(t, NULL, fn, arg);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return r;
}

void cleanup_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = remove_tracked_and_die;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
    struct sigaction was;   /* a shell without job control has it ignored: so do we */
    if (sigaction(SIGTSTP, NULL, &was) == 0 && was.sa_handler != SIG_IGN) {
        sa.sa_handler = stop_with_children;
        sigaction(SIGTSTP, &sa, NULL);
    }
}
