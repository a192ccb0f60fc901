/* Finished pictures: each chunk's picture reported once it is complete at its output_exr.
   POV-Ray writes a picture once and closes it (a sequence's frame before it parses the next
   frame; docs/povray.md), so a picture whose file has been closed is complete: developing it
   can overlap the frames after it, and once a process's pictures are all in, what it still
   does is wind down, which the runner does not wait for (povray.c). */
#include <errno.h>
#include <poll.h>
#include <stdalign.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>
#include "povray/povargs.h"
#include "povray/povray_cmd.h"
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

/* POV-Ray options of the user's may make it do more after writing its picture (a
   Post_Frame_Command): runs with others than povargs_end_with_pictures allows are not
   watched. */
void povray_watch_pictures(run *r)
{
    if (!povargs_end_with_pictures(r->opts->user_args, r->opts->user_arg_count) ||
        r->notify_fd >= 0)
        return;
    const int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (fd >= 0 && inotify_add_watch(fd, r->work_dir, IN_CLOSE_WRITE) < 0) {
        close(fd);
        return;
    }
    r->notify_fd = fd;
}

/* Where task t's f-th picture (1-based) is written: a sequence's frame, or a chunk's
   output_exr. */
static char *task_picture(const run *r, int t, int f)
{
    return r->frames ? povray_frame_output(r, t, f) : absolute_path(r->chunks[t].output_exr);
}

/* The chunk of a running job whose picture is named name in the work folder, with in *path
   where it is; -1 for none. */
static int picture_named(const run *r, const char *name, char **path)
{
    const size_t dir = strlen(r->work_dir) + 1;
    for (int i = 0; i < r->job_slots; i++) {
        const job *j = &r->jobs[i];
        for (int f = 1; j->pid && f <= task_chunks(r, j->task); f++) {
            char *picture = task_picture(r, j->task, f);
            if (picture && strlen(picture) > dir && strncmp(picture, r->work_dir, dir - 1) == 0 &&
                picture[dir - 1] == '/' && strcmp(picture + dir, name) == 0) {
                *path = picture;
                return task_first(r, j->task) + f - 1;
            }
            free(picture);
        }
    }
    return -1;
}

int povray_collect_pictures(run *r, l2p_error *err)
{
    if (r->notify_fd < 0)
        return L2P_OK;
    alignas(struct inotify_event) char buf[4096];
    int st = L2P_OK;
    ssize_t n;
    /* A lost event (a full queue) only delays that picture to its process's end. */
    while (!st && (n = read(r->notify_fd, buf, sizeof buf)) > 0)
        for (char *p = buf; p < buf + n && !st;) {
            const struct inotify_event *e = (const struct inotify_event *)p;
            char *path = NULL;
            const int k = e->len ? picture_named(r, e->name, &path) : -1;
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
