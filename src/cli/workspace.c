/* render's workspace: a folder of its own for the ray tables, renders and logs. */
#include "cli/workspace.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "base/tempdir.h"

/* Workspaces are named lens2pov.PID.XXXXXX. One whose process is gone (killed with SIGKILL,
   which no handler sees) is removed by the next render that looks in the same folder, when it
   is ours: so they never pile up. A process id taken again by another process keeps its
   folder until that one ends too. */
static void remove_stale_workspaces(const char *tmp)
{
    DIR *d = opendir(tmp);
    if (!d)
        return;
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        long pid;
        char rest[16];
        if (sscanf(e->d_name, "lens2pov.%ld.%15s", &pid, rest) != 2 || strlen(rest) != 6 ||
            pid <= 0 || (kill((pid_t)pid, 0) == 0 || errno != ESRCH))
            continue;
        workspace stale = {.keep = false};
        struct stat sb;
        snprintf(stale.dir, sizeof stale.dir, "%s/%s", tmp, e->d_name);
        if (lstat(stale.dir, &sb) == 0 && S_ISDIR(sb.st_mode) && sb.st_uid == getuid())
            workspace_remove(&stale);
    }
    closedir(d);
}

/* Two renders in one kept folder would write, and remove, each other's files: the folder is
   locked (flock, released when the process ends however it ends). */
static int lock_kept(workspace *w, l2p_error *err)
{
    w->lock_fd = open(w->dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (w->lock_fd < 0)
        return l2p_fail(err, L2P_BAD_INPUT, w->dir, 0, "cannot open folder: %s", strerror(errno));
    if (flock(w->lock_fd, LOCK_EX | LOCK_NB) != 0) {
        const int e = errno;
        close(w->lock_fd);
        w->lock_fd = -1;
        return e == EWOULDBLOCK
                   ? l2p_fail(err, L2P_BAD_INPUT, w->dir, 0, "another lens2pov render is using "
                              "this --keep-temp folder: give each render its own")
                   : l2p_fail(err, L2P_FAILED, w->dir, 0, "cannot lock folder: %s", strerror(e));
    }
    return L2P_OK;
}

int workspace_make(workspace *w, const char *keep, l2p_error *err)
{
    w->keep = keep != NULL;
    w->lock_fd = -1;
    if (w->keep) {
        snprintf(w->dir, sizeof w->dir, "%s", keep);
        w->made = mkdir(w->dir, 0777) == 0;
        if (!w->made && errno != EEXIST)
            return l2p_fail(err, L2P_BAD_INPUT, w->dir, 0, "cannot make folder: %s", strerror(errno));
        return lock_kept(w, err);
    }
    const char *tmp = temp_root();
    remove_stale_workspaces(tmp);
    snprintf(w->dir, sizeof w->dir, "%s/lens2pov.%ld.XXXXXX", tmp, (long)getpid());
    if (!mkdtemp(w->dir))
        return l2p_fail(err, L2P_FAILED, w->dir, 0, "cannot make a temporary folder: %s",
                        strerror(errno));
    cleanup_track(w->dir);
    return L2P_OK;
}

void workspace_remove(const workspace *w)
{
    if (w->keep) {
        if (w->lock_fd >= 0)
            close(w->lock_fd);   /* the lock goes with it */
        if (w->made)
            rmdir(w->dir);   /* made for a run refused before it wrote anything: not left empty */
        return;
    }
    DIR *d = opendir(w->dir);
    if (d) {
        char path[8192];
        for (struct dirent *e; (e = readdir(d)) != NULL;)
            if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
                snprintf(path, sizeof path, "%s/%s", w->dir, e->d_name);
                unlink(path);
            }
        closedir(d);
    }
    rmdir(w->dir);
    cleanup_untrack(w->dir);
}
