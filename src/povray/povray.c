/* Running POV-Ray 3.7 on the chunks of a ray table: the processes, their progress and the
   scheduler (povray_run.c sets a run up). What each step relies on was found by experiment;
   see docs/povray.md. */
#include "povray/povray.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/prctl.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "base/outfile.h"
#include "base/progress.h"
#include "povray/povray_cmd.h"
#include "povray/povray_log.h"
#include "povray/povray_run.h"
#include "raytable/chunk_name.h"

enum {
    TICK_MS = 20,
    DRAW_EVERY_TICKS = 12,     /* redraw the bar 4 times a second */
    STOP_WAIT_TICKS = 250      /* SIGTERM, then 5 s, then SIGKILL */
};

/* ---------------------------------------------------------------- processes */

static void write_text(int fd, const char *a, const char *b)
{
    if (write(fd, a, strlen(a)) < 0 || write(fd, b, strlen(b)) < 0 || write(fd, "\n", 1) < 0)
        return;
}

/* In the child: a process group of its own (what it starts is stopped with it), default
   signal handling (ours would remove the run's files), SIGTERM when
   lens2pov dies however it dies (SIGKILL, the out-of-memory killer: the parent-death signal
   outlives execve; lens2pov forks from its main thread, whose end is the process's), stdin from
   /dev/null, stdout and stderr into the log, the scene's folder as working folder. Only
   async-signal-safe calls: the parent may have threads. */
static void exec_child(const run *r, char **argv, int log_fd, const sigset_t *old_mask,
                       pid_t parent)
{
    cleanup_child_own_group();
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent)   /* the parent died before prctl: nothing would stop us */
        _exit(127);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGHUP, SIG_DFL);
    sigprocmask(SIG_SETMASK, old_mask, NULL);
    const int null_fd = open("/dev/null", O_RDONLY);
    if (null_fd >= 0)
        dup2(null_fd, STDIN_FILENO);
    dup2(log_fd, STDOUT_FILENO);
    dup2(log_fd, STDERR_FILENO);
    if (chdir(r->scene_real_dir) != 0) {
        write_text(STDERR_FILENO, "lens2pov: cannot enter the scene's folder ", r->scene_real_dir);
    } else {
        execve(argv[0], argv, r->env);
        write_text(STDERR_FILENO, "lens2pov: cannot run ", argv[0]);
    }
    _exit(127);
}

/* Forks with the cleanup signals blocked, so that the child is registered for the signal
   handler before any signal can be handled. */
static pid_t spawn(const run *r, char **argv, int log_fd)
{
    sigset_t old;
    cleanup_block_signals(&old);
    const pid_t parent = getpid(), pid = fork();
    if (pid == 0)
        exec_child(r, argv, log_fd, &old, parent);
    if (pid > 0)
        cleanup_track_child_group(pid);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return pid;
}

static int start_job(run *r, job *j, int t, l2p_error *err)
{
    task_args a;
    int st = povray_task_prepare(r, t, &a, err);
    const povray_cmd cmd = {r->exe, a.ini, a.wrapper, a.output, r->scene_dir_for_povray,
                            r->frames ? r->frames[t] : 0};
    char **argv = st ? NULL : povray_argv(&cmd, &r->chunks[task_first(r, t)], r->opts);
    free(j->log_path);
    j->log_path = povray_task_file_name(r, t, "log");
    if (!st && (!argv || !j->log_path))
        st = povray_out_of_memory(err);
    const int fd = st ? -1 : open(j->log_path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (!st && fd < 0)
        st = l2p_fail(err, L2P_FAILED, j->log_path, 0, "cannot write: %s", strerror(errno));
    if (!st) {
        j->pid = spawn(r, argv, fd);
        if (j->pid < 0) {
            j->pid = 0;
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "cannot start POV-Ray: %s", strerror(errno));
        }
        j->task = t;
        j->frame = 0;
        j->parse_fraction = j->render_fraction = 0;
    }
    if (fd >= 0)
        close(fd);
    povray_free_argv(argv);
    povray_task_args_free(&a);
    return st;
}

static void sleep_ms(int ms)
{
    const struct timespec t = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

/* Stops every running job, with what it started (a wrapper's POV-Ray): SIGTERM to its
   process group, up to 5 s, then SIGKILL; reaps all of them. */
static void stop_jobs(run *r)
{
    for (int i = 0; i < r->job_slots; i++)
        if (r->jobs[i].pid)
            cleanup_signal_child(r->jobs[i].pid, SIGTERM);
    for (int tick = 0;; tick++) {
        int running = 0;
        for (int i = 0; i < r->job_slots; i++) {
            job *j = &r->jobs[i];
            if (!j->pid)
                continue;
            if (tick == STOP_WAIT_TICKS)
                cleanup_end_child_group(j->pid);   /* SIGKILL, then reaped */
            if (cleanup_reap_child_group(j->pid)) {
                cleanup_untrack_child(j->pid);
                j->pid = 0;
            } else {
                running++;
            }
        }
        if (!running)
            return;
        sleep_ms(TICK_MS);
    }
}

/* Where to look further: the log, if it outlives the run; else its last line, since the
   workspace goes with the run. */
static void log_hint(const run *r, const job *j, char *out, size_t n)
{
    if (r->opts->work_dir_kept) {
        snprintf(out, n, "log: %s", j->log_path);
        return;
    }
    char last[160];
    povray_log_last_line(j->log_path, last, sizeof last);
    if (last[0])
        snprintf(out, n, "its log ends \"%s\"; --keep-temp DIR keeps the logs", last);
    else
        snprintf(out, n, "its log is empty; --keep-temp DIR keeps the logs");
}

/* POV-Ray says a full disk only as a file it could not write ("Cannot access data in file",
   a halted render): when the work folder's file system has less than a mebibyte left, the
   message says so. */
static int with_full_disk(const run *r, int st, l2p_error *err)
{
    struct statvfs v;
    if (st && statvfs(r->opts->work_dir, &v) == 0 &&
        (double)v.f_bavail * (double)v.f_frsize < 1048576.0) {
        const size_t n = strlen(err->text);
        snprintf(err->text + n, sizeof err->text - n, " (the file system of %s is full)",
                 r->opts->work_dir);
    }
    return st;
}

/* Why a job failed, in POV-Ray's own words when its log has them (a sequence's: those of the
   frame it failed in). */
static int explain_failure(const run *r, job *j, int status, l2p_error *err)
{
    if (r->frames)
        j->frame = povray_log_frame(j->log_path, j->frame);
    char *wrapper = povray_task_file_name(r, j->task, "pov");
    const povray_log_names names = {r->opts->scene_path, r->scene_real_dir,
                                    {wrapper, r->chunks[job_chunk(r, j)].include_path},
                                    r->links, r->link_count};
    /* a process killed (out of memory, say) is not the scene's fault, whatever its log says */
    int st = WIFSIGNALED(status) ? 0 : povray_log_error(j->log_path, &names, err);
    free(wrapper);
    if (st)
        return st;
    char hint[256];
    log_hint(r, j, hint, sizeof hint);
    if (WIFSIGNALED(status))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "povray: killed by signal %d (%s)",
                        WTERMSIG(status), hint);
    return l2p_fail(err, L2P_FAILED, NULL, 0, "povray: failed with status %d (%s)",
                    WIFEXITED(status) ? WEXITSTATUS(status) : -1, hint);
}

/* A finished job: success needs exit status 0 and the EXR on disk; a sequence's frames not
   yet reported are moved to their chunks' output_exr, and every picture is reported. */
static int check_finished(run *r, job *j, int status, l2p_error *err)
{
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return with_full_disk(r, explain_failure(r, j, status, err), err);
    int st = L2P_OK;
    for (int i = 0; i < task_chunks(r, j->task) && !st; i++) {
        const int k = task_first(r, j->task) + i;
        if (r->reported[k])
            continue;
        char *frame = r->frames ? povray_frame_output(r, j->task, i + 1) : NULL;
        const char *written = frame ? frame : r->chunks[k].output_exr;
        if (r->frames && !frame)
            st = povray_out_of_memory(err);
        else if (access(written, R_OK) != 0) {
            char hint[256];
            log_hint(r, j, hint, sizeof hint);
            st = with_full_disk(r, l2p_fail(err, L2P_FAILED, written, 0, "POV-Ray finished "
                                            "without writing it (%s)", hint), err);
        } else {
            st = povray_picture_finished(r, k, written, err);
        }
        free(frame);
    }
    return st;
}

/* ---------------------------------------------------------------- progress */

/* finished: the chunks of the tasks that have ended; a sequence's frames count as they go. */
static void draw_progress(run *r, int finished)
{
    if (!r->bar.enabled || r->writing)
        return;
    double sum = finished;
    int running = 0;
    for (int i = 0; i < r->job_slots; i++) {
        job *j = &r->jobs[i];
        if (!j->pid)
            continue;
        const int frame = r->frames ? povray_log_frame(j->log_path, j->frame) : 0;
        if (frame != j->frame) {
            j->frame = frame;
            j->parse_fraction = j->render_fraction = 0;
        }
        povray_log_progress(j->log_path, r->chunks[job_chunk(r, j)].faces, &j->parse_fraction,
                            &j->render_fraction);
        /* a frame whose pixels are all rendered is not done until its picture is written */
        sum += (j->frame > 1 ? j->frame - 1 : 0) + fmin(0.99, 0.5 * j->parse_fraction +
                                                            0.5 * j->render_fraction);
        running++;
    }
    char detail[64];
    snprintf(detail, sizeof detail, "%d of %d chunks done, %d running", finished, r->count,
             running);
    progress_update(&r->bar, sum / r->count, detail);
}

/* ---------------------------------------------------------------- the scheduler */

/* A run that failed for a passing cause is started again (povray_retry_transient).
   Returns whether it was. */
static bool retried(run *r, job *j, int status, int *st, l2p_error *err)
{
    if (*st || (WIFEXITED(status) && WEXITSTATUS(status) == 0) ||
        !povray_retry_transient(j->log_path, j->retries))
        return false;
    const int retries = j->retries + 1;
    *st = start_job(r, j, j->task, err);
    j->retries = retries;
    return true;
}

/* Reaps the jobs that ended; returns how many did, adds their chunks to *chunks, and gives
   the first failure in *st. */
static int reap_jobs(run *r, int *chunks, int *st, l2p_error *err)
{
    int ended = 0;
    for (int i = 0; i < r->job_slots; i++) {
        job *j = &r->jobs[i];
        int status;
        if (!j->pid || waitpid(j->pid, &status, WNOHANG) != j->pid)
            continue;
        cleanup_end_child_group(j->pid);   /* a wrapper that ended leaves nothing running */
        cleanup_untrack_child(j->pid);
        j->pid = 0;
        if (retried(r, j, status, st, err))
            continue;
        ended++;
        j->retries = 0;
        *chunks += task_chunks(r, j->task);
        if (!*st)
            *st = check_finished(r, j, status, err);
    }
    return ended;
}

static bool all_reported(const run *r, int t)
{
    for (int k = task_first(r, t); k < task_first(r, t) + task_chunks(r, t); k++)
        if (!r->reported[k])
            return false;
    return true;
}

/* A task whose pictures have all been reported is done: after closing its last picture
   POV-Ray only winds down (its threads' timed waits, a third to half a second;
   docs/povray.md), so it is killed, not waited for; had it already failed, that is the
   run's failure (*st) as when reap_jobs finds it. Returns how many ended so. */
static int retire_done_tasks(run *r, int *chunks, int *st, l2p_error *err)
{
    int ended = 0;
    for (int i = 0; r->notify_fd >= 0 && i < r->job_slots; i++) {
        job *j = &r->jobs[i];
        if (!j->pid || !all_reported(r, j->task))
            continue;
        int status = 0;
        cleanup_signal_child(j->pid, SIGKILL);
        while (waitpid(j->pid, &status, 0) < 0 && errno == EINTR)
            continue;
        cleanup_end_child_group(j->pid);
        if (!*st && WIFEXITED(status) && WEXITSTATUS(status) != 0)
            *st = explain_failure(r, j, status, err);
        cleanup_untrack_child(j->pid);
        j->pid = 0;
        j->retries = 0;
        *chunks += task_chunks(r, j->task);
        ended++;
    }
    return ended;
}

/* How many chunks are ready, and the count once known (r->count shrinks to it). */
static int poll_chunks(run *r, int *ready, l2p_error *err)
{
    if (!r->opts->chunks_ready) {
        *ready = r->count;
        return L2P_OK;
    }
    int total = -1;
    const int st = r->opts->chunks_ready(r->opts->ctx, ready, &total, err);
    if (!st && (total > r->count || *ready > r->count))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "%d chunks written, %d expected",
                        total > *ready ? total : *ready, r->count);
    if (!st && total >= 0)
        r->count = total;
    if (!r->frames)
        r->tasks = r->count;
    r->writing = !st && total < 0;
    return st;
}

static int schedule(run *r, l2p_error *err)
{
    int next = 0, finished = 0, chunks_done = 0, ready = 0, st = L2P_OK;
    bool told = !r->opts->started;
    povray_watch_pictures(r);
    for (int tick = 0; !st && finished < r->tasks; tick++) {
        st = poll_chunks(r, &ready, err);
        for (int i = 0; i < r->job_slots && next < r->tasks && !st &&
                        task_first(r, next) + task_chunks(r, next) <= ready; i++)
            if (!r->jobs[i].pid)
                st = start_job(r, &r->jobs[i], next++, err);
        if (!st && next > 0 && !told) {
            told = true;
            r->opts->started(r->opts->started_ctx);
        }
        if (!st)
            st = povray_collect_pictures(r, err);
        int ended = st ? 0 : reap_jobs(r, &chunks_done, &st, err);
        if (!st)
            ended += retire_done_tasks(r, &chunks_done, &st, err);
        finished += ended;
        if (ended || st)
            continue;  /* start the next chunks at once */
        if (tick % DRAW_EVERY_TICKS == 0)
            draw_progress(r, chunks_done);
        povray_wait_ms(r, TICK_MS);
    }
    if (!st)
        draw_progress(r, chunks_done);
    stop_jobs(r);  /* only a failed run has any left */
    return st;
}

static int render(const povray_chunk *chunks, int count, const int *frames, int tasks,
                  const povray_options *opts, l2p_error *err)
{
    if (count <= 0 || tasks <= 0)
        return L2P_OK;
    run r;
    int st = povray_run_prepare(&r, chunks, count, frames, tasks, opts, err);
    if (!st) {
        progress_start(&r.bar, "POV-Ray", opts->show_progress);
        st = schedule(&r, err);
        progress_finish(&r.bar);
    }
    povray_run_free(&r);
    return st;
}

int povray_render_chunks(const povray_chunk *chunks, int count, const povray_options *opts,
                         l2p_error *err)
{
    return render(chunks, count, NULL, count, opts, err);
}

int povray_render_sequences(const povray_chunk *chunks, const int *frames, int sequences,
                            const povray_options *opts, l2p_error *err)
{
    int count = 0;
    for (int t = 0; t < sequences; t++) {
        if (frames[t] < 1)
            return l2p_fail(err, L2P_FAILED, NULL, 0, "sequence %d has no chunks", t);
        count += frames[t];
    }
    if (opts->user_arg_count > 0 || opts->chunks_ready)
        return l2p_fail(err, L2P_FAILED, NULL, 0,
                        "sequences take neither POV-Ray's options nor chunks still being written");
    return render(chunks, count, frames, sequences, opts, err);
}
