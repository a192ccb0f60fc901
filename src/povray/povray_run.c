/* Setting up a POV-Ray run: the executable, the scene and its folder as POV-Ray can read them,
   and each task's wrapper, ini and output (povray_run.h). */
#include "povray/povray_run.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "povray/povray_cmd.h"
#include "povray/povray_env.h"
#include "raytable/chunk_name.h"

int povray_out_of_memory(l2p_error *err)
{
    return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
}

void povray_run_free(run *r)
{
    free(r->exe);
    povray_environment_free(r->env);
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
    free(r->reported);
    if (r->notify_fd >= 0)
        close(r->notify_fd);
}

/* WORK/povray.cNNN.EXT, chunk NNN's wrapper and log; WORK/povray.sNNN.EXT, sequence NNN's. */
char *povray_task_file_name(const run *r, int t, const char *ext)
{
    return r->frames ? str_printf("%s.s%03d.%s", r->chunk_prefix, t, ext)
                     : chunk_file_name(r->chunk_prefix, t, ext);
}

/* A path POV-Ray can read: abs_path itself, or a symlink named name in work_dir. */
static int readable_for_povray(run *r, const char *abs_path, const char *name, char **out,
                               l2p_error *err)
{
    if (povray_path_is_plain(abs_path))
        return (*out = strdup(abs_path)) ? L2P_OK : povray_out_of_memory(err);
    povray_path_link *grown = realloc(r->links, (size_t)(r->link_count + 1) * sizeof *grown);
    if (!grown)
        return povray_out_of_memory(err);
    r->links = grown;
    povray_path_link *l = &r->links[r->link_count];
    l->link = str_printf("%s/%s", r->work_dir, name);
    l->target = strdup(abs_path);
    if (!l->link || !l->target) {
        free(l->link);
        free(l->target);
        return povray_out_of_memory(err);
    }
    r->link_count++;
    unlink(l->link);
    if (symlink(abs_path, l->link) != 0)
        return l2p_fail(err, L2P_FAILED, l->link, 0, "cannot make a link: %s", strerror(errno));
    return (*out = strdup(l->link)) ? L2P_OK : povray_out_of_memory(err);
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

/* The executable's absolute path (the child changes folder before execve). */
static int find_povray(run *r, l2p_error *err)
{
    const char *name = r->opts->povray;
    if (!name || !*name)
        name = getenv("LENS2POV_POVRAY");
    if (!name || !*name)
        name = "povray";
    if (strchr(name, '/')) {
        if (is_executable_file(name))
            return (r->exe = absolute_path(name)) ? L2P_OK : povray_out_of_memory(err);
    } else {
        const char *path = getenv("PATH");
        char *dirs = strdup(path && *path ? path : "/usr/local/bin:/usr/bin:/bin");
        if (!dirs)
            return povray_out_of_memory(err);
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
    int st = r->scene_real_dir ? L2P_OK : povray_out_of_memory(err);
    if (!st)
        st = readable_for_povray(r, abs_scene, "povray.scene.pov", &r->scene_for_povray, err);
    if (!st)
        st = readable_for_povray(r, r->scene_real_dir, "povray.scene-folder",
                                 &r->scene_dir_for_povray, err);
    free(abs_scene);
    return st;
}

int povray_run_prepare(run *r, const povray_chunk *chunks, int count, const int *frames,
                       int tasks, const povray_options *opts, l2p_error *err)
{
    memset(r, 0, sizeof *r);
    r->notify_fd = -1;
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
    r->reported = calloc((size_t)count, sizeof *r->reported);
    if ((frames && !r->first) || !r->reported)
        return povray_out_of_memory(err);
    r->work_dir = absolute_path(opts->work_dir);
    r->chunk_prefix = r->work_dir ? str_printf("%s/%s", r->work_dir,
                                               opts->file_name ? opts->file_name : "povray")
                                  : NULL;
    if (!r->jobs || !r->chunk_prefix)
        return povray_out_of_memory(err);
    int st = check_plain(r->work_dir, err);
    if (!st)
        st = prepare_scene(r, err);
    if (!st)
        st = find_povray(r, err);
    if (!st && !(r->env = povray_environment()))
        st = povray_out_of_memory(err);
    return st;
}

/* ---------------------------------------------------------------- one task's files */

void povray_task_args_free(task_args *a)
{
    free(a->wrapper);
    free(a->ini);
    free(a->output);
}

/* Where POV-Ray writes frame f of sequence t: +O's name (WORK/povray.sNNN.f.exr) with the
   frame number before its extension, padded with zeros to the digits of the final frame. */
char *povray_frame_output(const run *r, int t, int f)
{
    int digits = 1;
    for (int final = r->frames[t] > 1 ? r->frames[t] : 2; final >= 10; final /= 10)
        digits++;
    return str_printf("%s.s%03d.f%0*d.exr", r->chunk_prefix, t, digits, f);
}

int povray_task_prepare(run *r, int t, task_args *a, l2p_error *err)
{
    const int first = task_first(r, t), n = task_chunks(r, t);
    const povray_chunk *c = &r->chunks[first];
    memset(a, 0, sizeof *a);
    char **include = calloc((size_t)n, sizeof *include), **pov_inc = calloc((size_t)n, sizeof *pov_inc);
    char *ini = absolute_path(c->ini_path), *ini_name = chunk_file_name("povray", first, "ini");
    a->wrapper = povray_task_file_name(r, t, "pov");
    a->output = r->frames ? povray_task_file_name(r, t, "f.exr")
                          : absolute_path(c->pov_output ? c->pov_output : c->output_exr);
    int st = include && pov_inc && ini && ini_name && a->wrapper && a->output
                 ? L2P_OK : povray_out_of_memory(err);
    for (int i = 0; i < n && !st; i++)
        if (!(include[i] = absolute_path(r->chunks[first + i].include_path)))
            st = povray_out_of_memory(err);
        else if (access(include[i], R_OK) != 0)
            st = l2p_fail(err, L2P_FAILED, include[i], 0, "cannot read: %s", strerror(errno));
    if (!st && access(ini, R_OK) != 0)
        st = l2p_fail(err, L2P_FAILED, ini, 0, "cannot read: %s", strerror(errno));
    if (!st)
        st = check_plain(a->output, err);
    for (int i = 0; i < n && !st; i++) {
        unlink(r->chunks[first + i].output_exr);  /* a stale EXR must not pass for this run's */
        char *stale = r->frames ? povray_frame_output(r, t, i + 1) : NULL;
        if (stale)
            unlink(stale);
        char *inc_name = chunk_file_name("povray", first + i, "inc");
        st = inc_name && (stale || !r->frames)
                 ? readable_for_povray(r, include[i], inc_name, &pov_inc[i], err)
                 : povray_out_of_memory(err);
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

