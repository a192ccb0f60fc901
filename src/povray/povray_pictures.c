/* Finished pictures: each chunk's picture reported once it is complete at its output_exr, a
   sequence's frames while their POV-Ray process still runs. POV-Ray writes a frame's picture
   once, closes it, and only then parses the next frame (its front end does both, in turn), so
   a frame whose file has been closed is complete: developing it can overlap the frames after
   it and POV-Ray's exit, about a quarter of a second of waiting (docs/povray.md). */
#include <errno.h>
#include <poll.h>
#include <stdalign.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>
#include "povray/povray_run.h"

int povray_picture_finished(run *r, int k, const char *written, l2p_error *err)
{
    if (r->reported[k])
        return L2P_OK;
    const char *out = r->chunks[k].output_exr;
    if (strcmp(written, out) != 0 && rename(written, out) != 0)
        return l2p_fail(err, L2P_FAILED, out, 0, "cannot move %s here: %s", written,
                        strerror(errno));
    r->reported[k] = true;
    return r->opts->picture_done ? r->opts->picture_done(r->opts->picture_ctx, k, err) : L2P_OK;
}

void povray_watch_frames(run *r)
{
    if (!r->frames || !r->opts->picture_done || r->notify_fd >= 0)
        return;
    const int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (fd >= 0 && inotify_add_watch(fd, r->work_dir, IN_CLOSE_WRITE) < 0) {
        close(fd);
        return;
    }
    r->notify_fd = fd;
}

/* The frame of a running job whose picture POV-Ray names name (in the work folder): its
   chunk, and in *path where it is; -1 for none. */
static int frame_named(const run *r, const char *name, char **path)
{
    const size_t dir = strlen(r->work_dir) + 1;
    for (int i = 0; i < r->job_slots; i++) {
        const job *j = &r->jobs[i];
        for (int f = 1; j->pid && f <= task_chunks(r, j->task); f++) {
            char *frame = povray_frame_output(r, j->task, f);
            if (frame && strlen(frame) > dir && strcmp(frame + dir, name) == 0) {
                *path = frame;
                return task_first(r, j->task) + f - 1;
            }
            free(frame);
        }
    }
    return -1;
}

int povray_collect_frames(run *r, l2p_error *err)
{
    if (r->notify_fd < 0)
        return L2P_OK;
    alignas(struct inotify_event) char buf[4096];
    int st = L2P_OK;
    ssize_t n;
    /* A lost event (a full queue) only delays that frame to its process's end. */
    while (!st && (n = read(r->notify_fd, buf, sizeof buf)) > 0)
        for (char *p = buf; p < buf + n && !st;) {
            const struct inotify_event *e = (const struct inotify_event *)p;
            char *path = NULL;
            const int k = e->len ? frame_named(r, e->name, &path) : -1;
            if (k >= 0)
                st = povray_picture_finished(r, k, path, err);
            free(path);
            p += sizeof *e + e->len;
        }
    return st;
}

void povray_wait_ms(const run *r, int ms)
{
    struct pollfd p = {.fd = r->notify_fd, .events = POLLIN};
    poll(&p, r->notify_fd >= 0, ms);   /* no descriptor: a plain wait */
}
