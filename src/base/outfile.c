#include "base/outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* Temporary paths to remove if a signal ends the run. A fixed table, so that the signal handler
   only reads memory that is never freed while it is registered. */
enum { MAX_TRACKED = 4096 };
static char *volatile tracked[MAX_TRACKED];

void outfile_track(const char *temp_path)
{
    for (int i = 0; i < MAX_TRACKED; i++)
        if (!tracked[i]) {
            tracked[i] = strdup(temp_path);
            return;
        }
}

void outfile_untrack(const char *temp_path)
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

void outfile_track_child(pid_t pid)
{
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (!children[i]) {
            children[i] = pid;
            return;
        }
}

void outfile_untrack_child(pid_t pid)
{
    for (int i = 0; i < MAX_CHILDREN; i++)
        if (children[i] == pid)
            children[i] = 0;
}

/* A folder, with whatever is in it, goes through rm -rf in a child process: fork, execve and
   waitpid are async-signal-safe, readdir is not. */
static void remove_path(const char *path)
{
    if (unlink(path) == 0 || rmdir(path) == 0)
        return;
    pid_t pid = fork();
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
            kill(children[i], SIGTERM);
            waitpid(children[i], NULL, 0);
        }
    for (int i = MAX_TRACKED - 1; i >= 0; i--)
        if (tracked[i])
            remove_path(tracked[i]);
    signal(sig, SIG_DFL);
    raise(sig);
}

void outfile_block_signals(sigset_t *old)
{
    sigset_t block;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigaddset(&block, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &block, old);
}

void outfile_install_signal_cleanup(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = remove_tracked_and_die;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
}

/* 48 random bits: getrandom's, or where it fails (an old kernel) the clock's and the process's
   mixed, which no one else can predict to the nanosecond either. */
static uint64_t random_bits(void)
{
    uint64_t r;
    if (getrandom(&r, sizeof r, 0) != (ssize_t)sizeof r) {
        struct timespec t;
        clock_gettime(CLOCK_REALTIME, &t);
        r = ((uint64_t)t.tv_sec * 1000000007u) ^ (uint64_t)t.tv_nsec ^ ((uint64_t)getpid() << 32);
        r ^= r >> 29;
        r *= 0xbf58476d1ce4e5b9ULL;
        r ^= r >> 32;
    }
    return r & 0xffffffffffffULL;
}

int outfile_create_temp(const char *prefix, const char *suffix, char **path)
{
    const size_t n = strlen(prefix) + strlen(suffix) + 13;
    char *p = malloc(n);
    if (!p) {
        errno = ENOMEM;
        return -1;
    }
    for (int attempt = 0; attempt < 64; attempt++) {
        snprintf(p, n, "%s%012llx%s", prefix, (unsigned long long)random_bits(), suffix);
        const int fd = open(p, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd >= 0) {
            *path = p;
            return fd;
        }
        if (errno != EEXIST)
            break;
    }
    const int e = errno;
    free(p);
    errno = e;
    return -1;
}

int outfile_check_path(const char *path, l2p_error *err)
{
    struct stat sb;
    if (!*path)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "an output file name is empty");
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "cannot write: Is a directory");
    const char *slash = strrchr(path, '/');
    char *dir = slash ? strndup(path, (size_t)(slash - path) + 1) : strdup(".");
    if (!dir)
        return l2p_fail(err, L2P_FAILED, path, 0, "out of memory");
    const char *why = stat(dir, &sb) != 0    ? strerror(errno)
                      : !S_ISDIR(sb.st_mode) ? strerror(ENOTDIR)
                      : access(dir, W_OK | X_OK) != 0 ? strerror(errno)
                                                       : NULL;
    free(dir);
    return why ? l2p_fail(err, L2P_BAD_INPUT, path, 0, "cannot write: %s", why) : L2P_OK;
}

int outfile_check_dir(const char *path, l2p_error *err)
{
    struct stat sb;
    if (!*path)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "an output folder name is empty");
    if (stat(path, &sb) != 0)
        return outfile_check_path(path, err);   /* to be made: its parent must take it */
    const char *why = !S_ISDIR(sb.st_mode) ? strerror(ENOTDIR)
                      : access(path, W_OK | X_OK) != 0 ? strerror(errno)
                                                        : NULL;
    return why ? l2p_fail(err, L2P_BAD_INPUT, path, 0, "cannot write: %s", why) : L2P_OK;
}

int outfile_open(outfile *f, const char *path, l2p_error *err)
{
    memset(f, 0, sizeof *f);
    char *prefix = malloc(strlen(path) + 5);
    f->final_path = strdup(path);
    if (!f->final_path || !prefix) {
        free(prefix);
        outfile_discard(f);
        return l2p_fail(err, L2P_FAILED, path, 0, "out of memory");
    }
    strcpy(prefix, path);
    strcat(prefix, ".tmp");
    const int fd = outfile_create_temp(prefix, "", &f->temp_path);
    free(prefix);
    if (fd >= 0)
        outfile_track(f->temp_path);
    f->fp = fd >= 0 ? fdopen(fd, "wb") : NULL;   /* close-on-exec: not inherited by POV-Ray */
    if (!f->fp) {
        const int e = errno;
        if (fd >= 0 && !f->fp)
            close(fd);
        outfile_discard(f);
        return l2p_fail(err, e == ENOENT || e == ENOTDIR ? L2P_BAD_INPUT : L2P_FAILED, path, 0,
                        "cannot write: %s", strerror(e));
    }
    return L2P_OK;
}

int outfile_finish(outfile *f, l2p_error *err)
{
    if (!f->fp)
        return L2P_OK;
    int bad = ferror(f->fp);
    bad |= fclose(f->fp) != 0;
    f->fp = NULL;
    if (bad)
        return l2p_fail(err, L2P_FAILED, f->final_path, 0, "write failed: %s", strerror(errno));
    return L2P_OK;
}

int outfile_commit(outfile *f, l2p_error *err)
{
    int st = outfile_finish(f, err);
    if (st)
        return st;
    if (rename(f->temp_path, f->final_path) != 0)
        return l2p_fail(err, L2P_FAILED, f->final_path, 0, "cannot rename into place: %s",
                        strerror(errno));
    outfile_untrack(f->temp_path);
    free(f->temp_path);
    free(f->final_path);
    memset(f, 0, sizeof *f);
    return L2P_OK;
}

void outfile_discard(outfile *f)
{
    if (f->fp)
        fclose(f->fp);
    if (f->temp_path) {
        unlink(f->temp_path);
        outfile_untrack(f->temp_path);
    }
    free(f->temp_path);
    free(f->final_path);
    memset(f, 0, sizeof *f);
}
