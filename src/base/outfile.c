#include "base/outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "base/cleanup.h"

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

char *outfile_target(const char *path)
{
    char *p = strdup(path);
    for (int links = 0; p; links++) {
        struct stat sb;
        if (lstat(p, &sb) != 0 || !S_ISLNK(sb.st_mode))
            return p;
        char to[PATH_MAX];
        const ssize_t n = readlink(p, to, sizeof to - 1);
        if (n < 0 || links == 40) {
            free(p);
            errno = n < 0 ? errno : ELOOP;
            return NULL;
        }
        to[n] = '\0';
        const char *slash = strrchr(p, '/');
        char *next = to[0] == '/' || !slash ? strdup(to) : malloc((size_t)(slash - p) + 2 + (size_t)n);
        if (next && to[0] != '/' && slash)
            sprintf(next, "%.*s/%s", (int)(slash - p), p, to);
        free(p);
        p = next;
    }
    errno = ENOMEM;
    return NULL;
}

int outfile_check_suffix(const char *path, const char *suffix, const char *format, l2p_error *err)
{
    const char *slash = strrchr(path, '/'), *name = slash ? slash + 1 : path;
    const size_t n = strlen(name), k = strlen(suffix);
    if (n > k && !strcasecmp(name + n - k, suffix))
        return L2P_OK;
    if (n == k && !strcasecmp(name, suffix))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "no file name before %s", suffix);
    return l2p_fail(err, L2P_BAD_INPUT, path, 0, "this command writes %s: give a name ending in %s", format,
                    suffix);
}

int outfile_check_not_input(const char *output, const char *input, const char *what, l2p_error *err)
{
    struct stat a, b;
    if (stat(output, &a) != 0 || stat(input, &b) != 0 || a.st_dev != b.st_dev || a.st_ino != b.st_ino)
        return L2P_OK;
    return l2p_fail(err, L2P_BAD_INPUT, output, 0, "is %s (%s): an output would overwrite it; give "
                    "another name", what, input);
}

/* outfile_check_path for the target of the path given. */
static int check_target(const char *given, const char *path, l2p_error *err)
{
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return l2p_fail(err, L2P_BAD_INPUT, given, 0, "cannot write: Is a directory");
    /* A device or a pipe cannot be replaced by a file renamed onto it. */
    if (stat(path, &sb) == 0 && !S_ISREG(sb.st_mode))
        return l2p_fail(err, L2P_BAD_INPUT, given, 0, "is not a regular file: outputs are written "
                        "beside their name and renamed onto it when complete; give a file name");
    const char *slash = strrchr(path, '/');
    char *dir = slash ? strndup(path, (size_t)(slash - path) + 1) : strdup(".");
    if (!dir)
        return l2p_fail(err, L2P_FAILED, given, 0, "out of memory");
    const char *why = stat(dir, &sb) != 0    ? strerror(errno)
                      : !S_ISDIR(sb.st_mode) ? strerror(ENOTDIR)
                      : access(dir, W_OK | X_OK) != 0 ? strerror(errno)
                                                       : NULL;
    free(dir);
    return why ? l2p_fail(err, L2P_BAD_INPUT, given, 0, "cannot write: %s", why) : L2P_OK;
}

int outfile_check_path(const char *given, l2p_error *err)
{
    if (!*given)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "an output file name is empty");
    char *target = outfile_target(given);
    if (!target)
        return l2p_fail(err, errno == ENOMEM ? L2P_FAILED : L2P_BAD_INPUT, given, 0, "cannot write: %s",
                        strerror(errno));
    const int st = check_target(given, target, err);
    free(target);
    return st;
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
    f->final_path = outfile_target(path);
    if (!f->final_path)
        return l2p_fail(err, errno == ENOMEM ? L2P_FAILED : L2P_BAD_INPUT, path, 0, "cannot write: %s",
                        strerror(errno));
    char *prefix = malloc(strlen(f->final_path) + 5);
    if (!prefix) {
        outfile_discard(f);
        return l2p_fail(err, L2P_FAILED, path, 0, "out of memory");
    }
    strcpy(prefix, f->final_path);
    strcat(prefix, ".tmp");
    const int fd = outfile_create_temp(prefix, "", &f->temp_path);
    free(prefix);
    if (fd >= 0)
        cleanup_track(f->temp_path);
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
    cleanup_untrack(f->temp_path);
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
        cleanup_untrack(f->temp_path);
    }
    free(f->temp_path);
    free(f->final_path);
    memset(f, 0, sizeof *f);
}
