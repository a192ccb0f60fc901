/* Running POV-Ray 3.7 on the chunks of a ray table. What each step relies on was found by
   experiment; see ../pov/README.md. */
#include "povray/povray.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "base/outfile.h"
#include "base/progress.h"
#include "povray/povray_cmd.h"
#include "povray/povray_log.h"
#include "raytable/chunk_name.h"

enum {
    TICK_MS = 20,
    DRAW_EVERY_TICKS = 12,     /* redraw the bar 4 times a second */
    STOP_WAIT_TICKS = 250,     /* SIGTERM, then 5 s, then SIGKILL */
    TRANSIENT_RETRIES = 5,     /* starts again of a chunk that failed for a passing cause, */
    TRANSIENT_PAUSE_MS = 100   /* the first after this pause, each next after twice the last */
};

/* ---------------------------------------------------------------- the run's shared state */

typedef struct job {
    pid_t pid;                 /* 0: slot free */
    int task;                  /* a chunk, or a sequence of them */
    int frame;                 /* of a sequence: the frame POV-Ray is at (1-based; 0 before) */
    char *log_path;
    double parse_fraction, render_fraction;
    int retries;               /* times this chunk was started again (retried) */
} job;

typedef struct run {
    const povray_chunk *chunks;
    int count;
    /* What one process renders: a chunk (frames NULL, tasks == count), or sequence t, the
       frames[t] chunks from first[t] on, as the frames of one animation. */
    const int *frames;
    int *first;
    int tasks;
    const povray_options *opts;
    char *exe;
    char *work_dir;
    char *chunk_prefix;        /* WORK/povray: the wrappers and logs are its chunk files */
    char *scene_real_dir;      /* the child's working folder */
    char *scene_for_povray, *scene_dir_for_povray;
    povray_path_link *links;
    int link_count;
    job *jobs;
    int job_slots;
    bool writing;              /* chunks still being written: their writer draws its own bar */
    progress bar;
} run;

static void free_run(run *r)
{
    free(r->exe);
    free(r->work_dir);
    free(r->chunk_prefix);
    free(r->scene_real_dir);
    free(r->scene_for_povray);
    free(r->scene_dir_for_povray);
    for (int i = 0; i < r->link_count; i++) {
        free(r->links[i].link);
        free(r->links[i].target);
    }
    free(r->links);
    for (int i = 0; r->jobs && i < r->job_slots; i++)
        free(r->jobs[i].log_path);
    free(r->jobs);
    free(r->first);
}

static int out_of_memory(l2p_error *err)
{
    return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
}

static int task_first(const run *r, int t)
{
    return r->frames ? r->first[t] : t;
}

static int task_chunks(const run *r, int t)
{
    return r->frames ? r->frames[t] : 1;
}

/* The chunk a job is at: a sequence's current frame (its first before POV-Ray names one). */
static int job_chunk(const run *r, const job *j)
{
    const int k = j->frame > 1 ? j->frame - 1 : 0;
    return task_first(r, j->task) + (k < task_chunks(r, j->task) ? k : task_chunks(r, j->task) - 1);
}

/* WORK/povray.cNNN.EXT, chunk NNN's wrapper and log; WORK/povray.sNNN.EXT, sequence NNN's. */
static char *task_file_name(const run *r, int t, const char *ext)
{
    return r->frames ? str_printf("%s.s%03d.%s", r->chunk_prefix, t, ext)
                     : chunk_file_name(r->chunk_prefix, t, ext);
}

/* A path POV-Ray can read: abs_path itself, or a symlink named name in work_dir. */
static int readable_for_povray(run *r, const char *abs_path, const char *name, char **out,
                               l2p_error *err)
{
    if (povray_path_is_plain(abs_path))
        return (*out = strdup(abs_path)) ? L2P_OK : out_of_memory(err);
    povray_path_link *grown = realloc(r->links, (size_t)(r->link_count + 1) * sizeof *grown);
    if (!grown)
        return out_of_memory(err);
    r->links = grown;
    povray_path_link *l = &r->links[r->link_count];
    l->link = str_printf("%s/%s", r->work_dir, name);
    l->target = strdup(abs_path);
    if (!l->link || !l->target) {
        free(l->link);
        free(l->target);
        return out_of_memory(err);
    }
    r->link_count++;
    unlink(l->link);
    if (symlink(abs_path, l->link) != 0)
        return l2p_fail(err, L2P_FAILED, l->link, 0, "cannot make a link: %s", strerror(errno));
    return (*out = strdup(l->link)) ? L2P_OK : out_of_memory(err);
}

/* Paths POV-Ray writes to or that lens2pov chose itself cannot be linked around. */
static int check_plain(const char *path, l2p_error *err)
{
    if (povray_path_is_plain(path))
        return L2P_OK;
    return l2p_fail(err, L2P_FAILED, path, 0,
                    "POV-Ray 3.7 cannot use this path (only plain ASCII without '\"' or '\\')");
}

/* ---------------------------------------------------------------- setting up */

static bool is_executable_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode) && access(path, X_OK) == 0;
}

/* The executable's absolute path (the child changes folder before execv). */
static int find_povray(run *r, l2p_error *err)
{
    const char *name = r->opts->povray;
    if (!name || !*name)
        name = getenv("LENS2POV_POVRAY");
    if (!name || !*name)
        name = "povray";
    if (strchr(name, '/')) {
        if (is_executable_file(name))
            return (r->exe = absolute_path(name)) ? L2P_OK : out_of_memory(err);
    } else {
        const char *path = getenv("PATH");
        char *dirs = strdup(path && *path ? path : "/usr/local/bin:/usr/bin:/bin");
        if (!dirs)
            return out_of_memory(err);
        char *save = NULL;
        for (char *d = strtok_r(dirs, ":", &save); d && !r->exe; d = strtok_r(NULL, ":", &save)) {
            char *candidate = str_printf("%s/%s", *d ? d : ".", name);
            if (candidate && is_executable_file(candidate))
                r->exe = absolute_path(candidate);
            free(candidate);
        }
        free(dirs);
        if (r->exe)
            return L2P_OK;
    }
    return l2p_fail(err, L2P_FAILED, NULL, 0, "%s: not found (install Debian's povray package)",
                    name);
}

/* The scene must exist (bad input otherwise); POV-Ray gets it and its folder, linked when
   their paths are not plain ASCII, and runs in that folder like `povray scene.pov` there. */
static int prepare_scene(run *r, l2p_error *err)
{
    const char *scene = r->opts->scene_path;
    if (access(scene, R_OK) != 0)
        return l2p_fail(err, L2P_BAD_INPUT, scene, 0, "cannot read: %s", strerror(errno));
    char *abs_scene = absolute_path(scene);
    r->scene_real_dir = abs_scene ? folder_of(abs_scene) : NULL;
    int st = r->scene_real_dir ? L2P_OK : out_of_memory(err);
    if (!st)
        st = readable_for_povray(r, abs_scene, "povray.scene.pov", &r->scene_for_povray, err);
    if (!st)
        st = readable_for_povray(r, r->scene_real_dir, "povray.scene-folder",
                                 &r->scene_dir_for_povray, err);
    free(abs_scene);
    return st;
}

static int prepare_run(run *r, const povray_chunk *chunks, int count, const int *frames,
                       int tasks, const povray_options *opts, l2p_error *err)
{
    memset(r, 0, sizeof *r);
    r->chunks = chunks;
    r->count = count;
    r->frames = frames;
    r->tasks = tasks;
    r->opts = opts;
    r->job_slots = opts->jobs > 0 ? opts->jobs : 1;
    if (r->job_slots > tasks)
        r->job_slots = tasks;
    if (frames && (r->first = malloc(sizeof *r->first * (size_t)tasks)) != NULL)
        for (int t = 0; t < tasks; t++)
            r->first[t] = t ? r->first[t - 1] + frames[t - 1] : 0;
    r->jobs = calloc((size_t)r->job_slots, sizeof *r->jobs);
    if (frames && !r->first)
        return out_of_memory(err);
    r->work_dir = absolute_path(opts->work_dir);
    r->chunk_prefix = r->work_dir ? str_printf("%s/povray", r->work_dir) : NULL;
    if (!r->jobs || !r->chunk_prefix)
        return out_of_memory(err);
    int st = check_plain(r->work_dir, err);
    if (!st)
        st = prepare_scene(r, err);
    if (!st)
        st = find_povray(r, err);
    return st;
}

/* ---------------------------------------------------------------- one task's files */

typedef struct chunk_args {
    char *wrapper, *ini, *output;
} chunk_args;

static void free_chunk_args(chunk_args *a)
{
    free(a->wrapper);
    free(a->ini);
    free(a->output);
}

/* Where POV-Ray writes frame f of sequence t: +O's name (WORK/povray.sNNN.f.exr) with the
   frame number before its extension, padded with zeros to the digits of the final frame. */
static char *frame_output(const run *r, int t, int f)
{
    int digits = 1;
    for (int final = r->frames[t] > 1 ? r->frames[t] : 2; final >= 10; final /= 10)
        digits++;
    return str_printf("%s.s%03d.f%0*d.exr", r->chunk_prefix, t, digits, f);
}

static int prepare_task(run *r, int t, chunk_args *a, l2p_error *err)
{
    const int first = task_first(r, t), n = task_chunks(r, t);
    const povray_chunk *c = &r->chunks[first];
    memset(a, 0, sizeof *a);
    char **include = calloc((size_t)n, sizeof *include), **pov_inc = calloc((size_t)n, sizeof *pov_inc);
    char *ini = absolute_path(c->ini_path), *ini_name = chunk_file_name("povray", first, "ini");
    a->wrapper = task_file_name(r, t, "pov");
    a->output = r->frames ? task_file_name(r, t, "f.exr")
                          : absolute_path(c->pov_output ? c->pov_output : c->output_exr);
    int st = include && pov_inc && ini && ini_name && a->wrapper && a->output
                 ? L2P_OK : out_of_memory(err);
    for (int i = 0; i < n && !st; i++)
        if (!(include[i] = absolute_path(r->chunks[first + i].include_path)))
            st = out_of_memory(err);
        else if (access(include[i], R_OK) != 0)
            st = l2p_fail(err, L2P_FAILED, include[i], 0, "cannot read: %s", strerror(errno));
    if (!st && access(ini, R_OK) != 0)
        st = l2p_fail(err, L2P_FAILED, ini, 0, "cannot read: %s", strerror(errno));
    if (!st)
        st = check_plain(a->output, err);
    for (int i = 0; i < n && !st; i++) {
        unlink(r->chunks[first + i].output_exr);  /* a stale EXR must not pass for this run's */
        char *stale = r->frames ? frame_output(r, t, i + 1) : NULL;
        if (stale)
            unlink(stale);
        char *inc_name = chunk_file_name("povray", first + i, "inc");
        st = inc_name && (stale || !r->frames)
                 ? readable_for_povray(r, include[i], inc_name, &pov_inc[i], err)
                 : out_of_memory(err);
        free(stale);
        free(inc_name);
    }
    if (!st)
        st = readable_for_povray(r, ini, ini_name, &a->ini, err);
    if (!st)
        st = r->frames ? povray_write_sequence_wrapper(a->wrapper, r->scene_for_povray,
                                                       (const char *const *)pov_inc, n, t,
                                                       r->opts, err)
                       : povray_write_wrapper(a->wrapper, r->scene_for_povray, pov_inc[0],
                                              first, c, r->opts, err);
    for (int i = 0; i < n && include && pov_inc; i++) {
        free(include[i]);
        free(pov_inc[i]);
    }
    free(include);
    free(pov_inc);
    free(ini);
    free(ini_name);
    return st;
}

/* ---------------------------------------------------------------- processes */

static void write_text(int fd, const char *a, const char *b)
{
    if (write(fd, a, strlen(a)) < 0 || write(fd, b, strlen(b)) < 0 || write(fd, "\n", 1) < 0)
        return;
}

/* In the child: default signal handling (ours would remove the run's files), SIGTERM when
   lens2pov dies however it dies (SIGKILL, the out-of-memory killer: the parent-death signal
   outlives execv; lens2pov forks from its main thread, whose end is the process's), stdin from
   /dev/null, stdout and stderr into the log, the scene's folder as working folder. Only
   async-signal-safe calls: the parent may have threads. */
static void exec_child(const run *r, char **argv, int log_fd, const sigset_t *old_mask,
                       pid_t parent)
{
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
        execv(argv[0], argv);
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
        cleanup_track_child(pid);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return pid;
}

static int start_job(run *r, job *j, int t, l2p_error *err)
{
    chunk_args a;
    int st = prepare_task(r, t, &a, err);
    const povray_cmd cmd = {r->exe, a.ini, a.wrapper, a.output, r->scene_dir_for_povray,
                            r->frames ? r->frames[t] : 0};
    char **argv = st ? NULL : povray_argv(&cmd, &r->chunks[task_first(r, t)], r->opts);
    free(j->log_path);
    j->log_path = task_file_name(r, t, "log");
    if (!st && (!argv || !j->log_path))
        st = out_of_memory(err);
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
    free_chunk_args(&a);
    return st;
}

static void sleep_ms(int ms)
{
    const struct timespec t = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

/* Stops every running job: SIGTERM, up to 5 s, then SIGKILL; reaps all of them. */
static void stop_jobs(run *r)
{
    for (int i = 0; i < r->job_slots; i++)
        if (r->jobs[i].pid)
            kill(r->jobs[i].pid, SIGTERM);
    for (int tick = 0;; tick++) {
        int running = 0;
        for (int i = 0; i < r->job_slots; i++) {
            job *j = &r->jobs[i];
            if (!j->pid)
                continue;
            if (tick == STOP_WAIT_TICKS)
                kill(j->pid, SIGKILL);
            const pid_t w = waitpid(j->pid, NULL, tick >= STOP_WAIT_TICKS ? 0 : WNOHANG);
            if (w == j->pid || (w < 0 && errno == ECHILD)) {
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

/* Why a job failed, in POV-Ray's own words when its log has them (a sequence's: those of the
   frame it failed in). */
static int explain_failure(const run *r, job *j, int status, l2p_error *err)
{
    if (r->frames)
        j->frame = povray_log_frame(j->log_path, j->frame);
    char *wrapper = task_file_name(r, j->task, "pov");
    const povray_log_names names = {r->opts->scene_path, r->scene_real_dir,
                                    {wrapper, r->chunks[job_chunk(r, j)].include_path},
                                    r->links, r->link_count};
    int st = povray_log_error(j->log_path, &names, err);
    free(wrapper);
    if (st)
        return st;
    if (WIFSIGNALED(status))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "povray: killed by signal %d (log: %s)",
                        WTERMSIG(status), j->log_path);
    return l2p_fail(err, L2P_FAILED, NULL, 0, "povray: failed with status %d (log: %s)",
                    WIFEXITED(status) ? WEXITSTATUS(status) : -1, j->log_path);
}

/* A finished job: success needs exit status 0 and the EXR on disk; a sequence's frames are
   moved to their chunks' output_exr. */
static int check_finished(const run *r, job *j, int status, l2p_error *err)
{
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return explain_failure(r, j, status, err);
    int st = L2P_OK;
    for (int i = 0; i < task_chunks(r, j->task) && !st; i++) {
        const char *out = r->chunks[task_first(r, j->task) + i].output_exr;
        char *frame = r->frames ? frame_output(r, j->task, i + 1) : NULL;
        const char *written = frame ? frame : out;
        if (r->frames && !frame)
            st = out_of_memory(err);
        else if (access(written, R_OK) != 0)
            st = l2p_fail(err, L2P_FAILED, written, 0,
                          "POV-Ray finished without writing it (log: %s)", j->log_path);
        else if (frame && rename(frame, out) != 0)
            st = l2p_fail(err, L2P_FAILED, out, 0, "cannot move %s here: %s", frame,
                          strerror(errno));
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
        sum += (j->frame > 1 ? j->frame - 1 : 0) + 0.5 * j->parse_fraction +
               0.5 * j->render_fraction;
        running++;
    }
    char detail[64];
    snprintf(detail, sizeof detail, "%d of %d chunks done, %d running", finished, r->count,
             running);
    progress_update(&r->bar, sum / r->count, detail);
}

/* ---------------------------------------------------------------- the scheduler */

/* A run that failed for a passing cause (povray_log_transient) is started again, at most
   TRANSIENT_RETRIES times a task, with a warning. The pauses between starts grow (0.1 s to
   1.6 s) because the cause is load: vfeSession::Initialize gives POV-Ray's worker thread 3 s
   to start, and starts that fail come in runs. Returns whether it was started again. */
static bool retried(run *r, job *j, int status, int *st, l2p_error *err)
{
    if (*st || (WIFEXITED(status) && WEXITSTATUS(status) == 0) || j->retries >= TRANSIENT_RETRIES ||
        !povray_log_transient(j->log_path))
        return false;
    fprintf(stderr, "lens2pov: warning: POV-Ray timed out starting its threads (a loaded "
                    "machine); starting it again\n");
    const int retries = j->retries + 1;
    sleep_ms(TRANSIENT_PAUSE_MS << j->retries);
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
    for (int tick = 0; !st && finished < r->tasks; tick++) {
        st = poll_chunks(r, &ready, err);
        for (int i = 0; i < r->job_slots && next < r->tasks && !st &&
                        task_first(r, next) + task_chunks(r, next) <= ready; i++)
            if (!r->jobs[i].pid)
                st = start_job(r, &r->jobs[i], next++, err);
        const int ended = st ? 0 : reap_jobs(r, &chunks_done, &st, err);
        finished += ended;
        if (ended || st)
            continue;  /* start the next chunks at once */
        if (tick % DRAW_EVERY_TICKS == 0)
            draw_progress(r, chunks_done);
        sleep_ms(TICK_MS);
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
    int st = prepare_run(&r, chunks, count, frames, tasks, opts, err);
    if (!st) {
        progress_start(&r.bar, "POV-Ray", opts->show_progress);
        st = schedule(&r, err);
        progress_finish(&r.bar);
    }
    free_run(&r);
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
