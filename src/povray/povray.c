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
    TRANSIENT_RETRIES = 2      /* starts again of a chunk that failed for a passing cause */
};

/* ---------------------------------------------------------------- the run's shared state */

typedef struct job {
    pid_t pid;                 /* 0: slot free */
    int chunk;
    char *log_path;
    double parse_fraction, render_fraction;
    int retries;               /* times this chunk was started again (retried) */
} job;

typedef struct run {
    const povray_chunk *chunks;
    int count;
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
}

static int out_of_memory(l2p_error *err)
{
    return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
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

static int prepare_run(run *r, const povray_chunk *chunks, int count, const povray_options *opts,
                       l2p_error *err)
{
    memset(r, 0, sizeof *r);
    r->chunks = chunks;
    r->count = count;
    r->opts = opts;
    r->job_slots = opts->jobs > 0 ? opts->jobs : 1;
    if (r->job_slots > count)
        r->job_slots = count;
    r->jobs = calloc((size_t)r->job_slots, sizeof *r->jobs);
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

/* ---------------------------------------------------------------- one chunk's files */

typedef struct chunk_args {
    char *wrapper, *ini, *output;
} chunk_args;

static void free_chunk_args(chunk_args *a)
{
    free(a->wrapper);
    free(a->ini);
    free(a->output);
}

static int prepare_chunk(run *r, int index, chunk_args *a, l2p_error *err)
{
    const povray_chunk *c = &r->chunks[index];
    memset(a, 0, sizeof *a);
    char *include = absolute_path(c->include_path), *ini = absolute_path(c->ini_path);
    char *inc_name = chunk_file_name("povray", index, "inc");
    char *ini_name = chunk_file_name("povray", index, "ini");
    char *pov_inc = NULL;
    a->wrapper = chunk_file_name(r->chunk_prefix, index, "pov");
    a->output = absolute_path(c->pov_output ? c->pov_output : c->output_exr);
    int st = include && ini && inc_name && ini_name && a->wrapper && a->output
                 ? L2P_OK : out_of_memory(err);
    if (!st && (access(include, R_OK) != 0 || access(ini, R_OK) != 0))
        st = l2p_fail(err, L2P_FAILED, access(include, R_OK) ? include : ini, 0,
                      "cannot read: %s", strerror(errno));
    if (!st)
        st = check_plain(a->output, err);
    if (!st)
        unlink(c->output_exr);  /* a stale EXR must not pass for this run's */
    if (!st)
        st = readable_for_povray(r, include, inc_name, &pov_inc, err);
    if (!st)
        st = readable_for_povray(r, ini, ini_name, &a->ini, err);
    if (!st)
        st = povray_write_wrapper(a->wrapper, r->scene_for_povray, pov_inc, index, c, r->opts,
                                  err);
    free(include);
    free(ini);
    free(inc_name);
    free(ini_name);
    free(pov_inc);
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

static int start_job(run *r, job *j, int index, l2p_error *err)
{
    chunk_args a;
    int st = prepare_chunk(r, index, &a, err);
    const povray_cmd cmd = {r->exe, a.ini, a.wrapper, a.output, r->scene_dir_for_povray};
    char **argv = st ? NULL : povray_argv(&cmd, &r->chunks[index], r->opts);
    free(j->log_path);
    j->log_path = chunk_file_name(r->chunk_prefix, index, "log");
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
        j->chunk = index;
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

/* Why a job failed, in POV-Ray's own words when its log has them. */
static int explain_failure(const run *r, const job *j, int status, l2p_error *err)
{
    char *wrapper = chunk_file_name(r->chunk_prefix, j->chunk, "pov");
    const povray_log_names names = {r->opts->scene_path, r->scene_real_dir,
                                    {wrapper, r->chunks[j->chunk].include_path},
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

/* A finished job: success needs exit status 0 and the EXR on disk. */
static int check_finished(const run *r, const job *j, int status, l2p_error *err)
{
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return explain_failure(r, j, status, err);
    const char *out = r->chunks[j->chunk].output_exr;
    if (access(out, R_OK) != 0)
        return l2p_fail(err, L2P_FAILED, out, 0, "POV-Ray finished without writing it (log: %s)",
                        j->log_path);
    return L2P_OK;
}

/* ---------------------------------------------------------------- progress */

static void draw_progress(run *r, int finished)
{
    if (!r->bar.enabled || r->writing)
        return;
    double sum = finished;
    int running = 0;
    for (int i = 0; i < r->job_slots; i++)
        if (r->jobs[i].pid) {
            povray_log_progress(r->jobs[i].log_path, r->chunks[r->jobs[i].chunk].faces,
                                &r->jobs[i].parse_fraction, &r->jobs[i].render_fraction);
            sum += 0.5 * r->jobs[i].parse_fraction + 0.5 * r->jobs[i].render_fraction;
            running++;
        }
    char detail[64];
    snprintf(detail, sizeof detail, "%d of %d chunks done, %d running", finished, r->count,
             running);
    progress_update(&r->bar, sum / r->count, detail);
}

/* ---------------------------------------------------------------- the scheduler */

/* A run that failed for a passing cause (povray_log_transient) is started again, at most
   TRANSIENT_RETRIES times a chunk, with a warning. Returns whether it was. */
static bool retried(run *r, job *j, int status, int *st, l2p_error *err)
{
    if (*st || (WIFEXITED(status) && WEXITSTATUS(status) == 0) || j->retries >= TRANSIENT_RETRIES ||
        !povray_log_transient(j->log_path))
        return false;
    fprintf(stderr, "lens2pov: warning: POV-Ray timed out starting its threads on chunk %d (a "
                    "loaded machine); starting it again\n", j->chunk);
    const int retries = j->retries + 1;
    *st = start_job(r, j, j->chunk, err);
    j->retries = retries;
    return true;
}

/* Reaps the jobs that ended; returns how many did, and the first failure in *st. */
static int reap_jobs(run *r, int *st, l2p_error *err)
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
    r->writing = !st && total < 0;
    return st;
}

static int schedule(run *r, l2p_error *err)
{
    int next = 0, finished = 0, ready = 0, st = L2P_OK;
    for (int tick = 0; !st && finished < r->count; tick++) {
        st = poll_chunks(r, &ready, err);
        for (int i = 0; i < r->job_slots && next < ready && next < r->count && !st; i++)
            if (!r->jobs[i].pid)
                st = start_job(r, &r->jobs[i], next++, err);
        const int ended = st ? 0 : reap_jobs(r, &st, err);
        finished += ended;
        if (ended || st)
            continue;  /* start the next chunks at once */
        if (tick % DRAW_EVERY_TICKS == 0)
            draw_progress(r, finished);
        sleep_ms(TICK_MS);
    }
    if (!st)
        draw_progress(r, finished);
    stop_jobs(r);  /* only a failed run has any left */
    return st;
}

int povray_render_chunks(const povray_chunk *chunks, int count, const povray_options *opts,
                         l2p_error *err)
{
    if (count <= 0)
        return L2P_OK;
    run r;
    int st = prepare_run(&r, chunks, count, opts, err);
    if (!st) {
        progress_start(&r.bar, "POV-Ray", opts->show_progress);
        st = schedule(&r, err);
        progress_finish(&r.bar);
    }
    free_run(&r);
    return st;
}
