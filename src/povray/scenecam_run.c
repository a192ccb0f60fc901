/* Running POV-Ray on the copy of the scene whose camera statements print their items
   (scenecam_text.c), once for every frame POV-Ray's own options give, and reading each frame's
   camera from what it printed (scenecam.c). */
#include "povray/scenecam.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "base/outfile.h"
#include "base/readfile.h"
#include "base/tempdir.h"
#include "povray/povargs.h"
#include "povray/povray_env.h"
#include "povray/povray_log.h"

extern char **environ;

static int write_all(const char *path, const char *s, l2p_error *err)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return l2p_fail(err, L2P_FAILED, path, 0, "cannot write: %s", strerror(errno));
    const bool ok = fwrite(s, 1, strlen(s), f) == strlen(s);
    if (fclose(f) != 0 || !ok)
        return l2p_fail(err, L2P_FAILED, path, 0, "cannot write: %s", strerror(errno));
    return L2P_OK;
}

static bool plain_path(const char *p)
{
    for (; *p; p++)
        if (*p < 0x20 || *p > 0x7e || *p == '"' || *p == '\\')
            return false;
    return true;
}

static char *folder_of(const char *path)
{
    char *abs = NULL;
    if (path[0] == '/') {
        abs = strdup(path);
    } else {
        char cwd[4096];
        if (getcwd(cwd, sizeof cwd) && (abs = malloc(strlen(cwd) + strlen(path) + 2)))
            sprintf(abs, "%s/%s", cwd, path);
    }
    char *slash = abs ? strrchr(abs, '/') : NULL;
    if (slash)
        slash[slash == abs ? 1 : 0] = '\0';
    return abs;
}

/* POV-Ray parses the copy in the scene's folder, as the render will run it: the same
   povray.ini, the same includes. One pixel is traced; the parse is what counts. */
typedef struct probe_args {
    char *const *user;         /* POV-Ray's own options from the command line, first */
    int user_count;
} probe_args;

/* Whether the ini at path has a setting, outside its ';' comments, that names frames, the
   clock or the language version (Initial_Frame, Clock, Version, +KFF, +MV, ...), or another
   ini. A missing file has none. */
static bool ini_sets_frames_or_version(const char *path)
{
    FILE *f = fopen(path, "r");
    bool found = false;
    char line[1024];
    while (f && !found && fgets(line, sizeof line, f)) {
        line[strcspn(line, ";")] = '\0';
        for (char *c = line; *c; c++)
            *c = (char)tolower((unsigned char)*c);
        found = strstr(line, "frame") || strstr(line, "clock") || strstr(line, "version") ||
                strstr(line, "subset") || strstr(line, "+k") || strstr(line, "-k") ||
                strstr(line, "+mv") || strstr(line, ".ini");
    }
    if (f)
        fclose(f);
    return found;
}

/* Whether an ini POV-Ray reads before the scene could set its language version or make it
   animate: a povray.ini in the scene's folder, the user's own, one named by POVINI, or a
   system-wide one with such a setting (Debian's has none). Then the camera's rules and frames
   are POV-Ray's to find. */
static bool settings_may_differ(const char *dir)
{
    char buf[POVARGS_INIS][POVARGS_INI_PATH];
    const char *ini[POVARGS_INIS];
    povargs_default_inis(dir, buf, ini);
    if (ini[0])   /* POVINI named: whatever it holds */
        return true;
    for (int i = 1; i < POVARGS_INIS - 1; i++)
        if (ini[i] && access(ini[i], F_OK) == 0)
            return true;
    return ini_sets_frames_or_version(ini[POVARGS_INIS - 1]);
}

bool scene_inis_set_frames(const char *scene)
{
    char *dir = folder_of(scene);
    char buf[POVARGS_INIS][POVARGS_INI_PATH];
    const char *ini[POVARGS_INIS];
    bool found = false;
    if (dir)
        povargs_default_inis(dir, buf, ini);
    for (int i = 0; dir && !found && i < POVARGS_INIS; i++)
        found = ini[i] && ini_sets_frames_or_version(ini[i]);
    free(dir);
    return found;
}

/* The marks of a probe that has done its work, in the order it prints them: the frame line
   of a still (frame 0 of final frame 0; an ini can make POV-Ray render an animation even
   without options), PARSED after the copy's last line (every camera statement that runs has
   printed), and POV-Ray's own RENDERING line, since a block the scene leaves open would print
   PARSED too and fail only then. */
static const char PARSED[] = "lens2pov-parsed|";
static const char *const DONE_MARKS[] = {"lens2pov-frame 0 0 ", PARSED, "==== [Rendering...]"};
enum { DONE_STAGES = sizeof DONE_MARKS / sizeof *DONE_MARKS };

/* Whether the log holds mark at or after *pos; *pos moves past it when it does, else to
   where the next look starts. */
static bool log_has(const char *log, const char *mark, long *pos)
{
    const size_t len = strlen(mark);
    FILE *f = fopen(log, "rb");
    if (!f || fseek(f, *pos, SEEK_SET) != 0) {
        if (f)
            fclose(f);
        return false;
    }
    char buf[4096];
    bool found = false;
    for (size_t got; !found && (got = fread(buf, 1, sizeof buf, f)) >= len;) {
        size_t i = 0;
        while (i + len <= got && memcmp(buf + i, mark, len))
            i++;
        found = i + len <= got;
        *pos += (long)(found ? i + len : i);   /* a mark cut at the block's end is read again */
        fseek(f, *pos, SEEK_SET);
    }
    fclose(f);
    return found;
}

/* The probe's wait status (exit status 1 when it cannot be had). With early, a still whose
   parse has ended well is killed: what it still does (trace a pixel, wind down, about 0.4 s)
   is not needed; it counts as a success. */
static int wait_probe(pid_t pid, const char *log, bool early)
{
    int status = 0;
    for (long pos = 0, stage = 0;;) {
        const pid_t w = waitpid(pid, &status, early ? WNOHANG : 0);
        if (w == pid) {
            cleanup_end_child_group(pid);   /* a wrapper that ended leaves nothing running */
            return status;
        }
        if (w < 0 && errno != EINTR)
            return 1 << 8;
        if (w == 0 && log_has(log, DONE_MARKS[stage], &pos)) {
            if (++stage < DONE_STAGES)
                continue;
            cleanup_end_child_group(pid);
            return 0;
        }
        nanosleep(&(struct timespec){0, 5000000L}, NULL);
    }
}

static int run_probe(const char *dir, const char *copy, const char *log, int w, int h,
                     const probe_args *pa, l2p_error *err)
{
    const char *exe = getenv("LENS2POV_POVRAY");
    exe = exe && *exe ? exe : "povray";
    char in[4300], size_w[32], size_h[32], rows[64], cols[64];
    snprintf(in, sizeof in, "+I\"%s\"", copy);
    snprintf(size_w, sizeof size_w, "+W%d", w);
    snprintf(size_h, sizeof size_h, "+H%d", h);
    /* +SR2: a whole number above 1 is a pixel, 1 itself the fraction 1.0 */
    snprintf(rows, sizeof rows, "+SR%d", h > 1 ? 2 : 1);
    snprintf(cols, sizeof cols, "+SC%d", w > 1 ? 2 : 1);
    char end_rows[64], end_cols[64];
    snprintf(end_rows, sizeof end_rows, "+ER%d", h > 1 ? 2 : 1);
    snprintf(end_cols, sizeof end_cols, "+EC%d", w > 1 ? 2 : 1);
    /* +GA first: a user's -GA (or All_Console=Off) silences every stream, and a later +GD
       alone does not bring the debug stream back */
    char *own[] = {in, size_w, size_h, rows, end_rows, cols, end_cols, "-F", "-D",
                   "-P", "-C", "-A", "+GA", "-GS", "-GR", "+GD"};
    enum { OWN = sizeof own / sizeof own[0] };
    char **argv = calloc((size_t)pa->user_count + OWN + 2, sizeof *argv);
    if (!argv)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    int n = 0;
    argv[n++] = (char *)exe;
    for (int i = 0; i < pa->user_count; i++)   /* before ours, which override them */
        argv[n++] = pa->user[i];
    for (int i = 0; i < OWN; i++)
        argv[n++] = own[i];
    char **env = povray_environment();
    if (!env) {
        free(argv);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    const int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) {
        free(argv);
        povray_environment_free(env);
        return l2p_fail(err, L2P_FAILED, log, 0, "cannot write: %s", strerror(errno));
    }
    sigset_t old;
    cleanup_block_signals(&old);
    const pid_t pid = fork();
    if (pid == 0) {
        cleanup_child_own_group();
        prctl(PR_SET_PDEATHSIG, SIGTERM);   /* gone with lens2pov, however it ends */
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        signal(SIGHUP, SIG_DFL);
        sigprocmask(SIG_SETMASK, &old, NULL);
        const int null_fd = open("/dev/null", O_RDONLY);
        if (null_fd >= 0)
            dup2(null_fd, STDIN_FILENO);
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        environ = env;   /* execvp searches PATH and passes environ */
        if (chdir(dir) == 0)
            execvp(exe, argv);
        _exit(127);
    }
    if (pid > 0)
        cleanup_track_child_group(pid);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    close(fd);
    free(argv);
    povray_environment_free(env);
    if (pid < 0)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "cannot start POV-Ray: %s", strerror(errno));
    const int status = wait_probe(pid, log, povargs_end_with_pictures(pa->user, pa->user_count));
    cleanup_untrack_child(pid);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "%s: cannot run it (install Debian's povray "
                        "package) or cannot enter %s", exe, dir);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? L2P_OK : -1;
}


/* POV-Ray's options after "--" that POV-Ray itself refused ("Problem with option setting",
   without naming the option): the message names them all. */
static bool refused_options(const char *log, const probe_args *pa, l2p_error *err)
{
    static const char problem[] = "Problem with option setting";
    size_t n = 0;
    char *text = read_whole_file(log, &n);
    bool refused = false;
    for (size_t i = 0; text && !refused && i + sizeof problem - 1 <= n; i++)
        refused = !memcmp(text + i, problem, sizeof problem - 1);
    free(text);
    if (!refused)
        return false;
    char opts[600] = "";
    for (int i = 0; i < pa->user_count; i++)
        snprintf(opts + strlen(opts), sizeof opts - strlen(opts), "%s%s", i ? " " : "",
                 pa->user[i]);
    l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "-- %s: POV-Ray refuses these options (\"%s\", "
             "\"Failed to parse command-line option\"; it does not say which)", opts, problem);
    return true;
}

/* The copy, included by a file that first prints the frame POV-Ray is on and last PARSED. */
static int write_probe_files(const char *work, const char *rewritten, char *copy, char *top,
                             size_t cap, l2p_error *err)
{
    snprintf(copy, cap, "%s/scene-camera.pov", work);
    snprintf(top, cap, "%s/scene-frame.pov", work);
    char text[4400];
    snprintf(text, sizeof text,
             "#debug concat(\"lens2pov-frame \", str(frame_number, 0, 0), \" \", "
             "str(final_frame, 0, 0), \" \", str(clock, 0, 17), \"|\\n\")\n"
             "#include \"%s\"\n#debug \"%s\\n\"\n", copy, PARSED);
    int st = write_all(copy, rewritten, err);
    return st ? st : write_all(top, text, err);
}

static int one_default_frame(const char *scene, scene_frames *out, l2p_error *err)
{
    out->frame = calloc(1, sizeof *out->frame);
    if (!out->frame)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    out->count = 1;
    const scene_files files = {&scene, 1};
    return scene_camera_from_log("", 0, &files, &out->frame[0].cam, err);
}

/* POV-Ray's error, in the user's files: the copies name the scene and its included files. */
static void probe_error(const char *scene, const char *dir, const char *top, const char *copy,
                        const char *log, const scene_copy *sc, l2p_error *err)
{
    povray_path_link *links = calloc((size_t)sc->count, sizeof *links);
    if (!links) {
        l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
        return;
    }
    links[0] = (povray_path_link){(char *)copy, (char *)scene};
    for (int k = 1; k < sc->count; k++)
        links[k] = (povray_path_link){sc->copy[k], sc->path[k]};
    const povray_log_names names = {scene, dir, {top, NULL}, links, sc->count};
    if (!povray_log_error(log, &names, err))
        l2p_fail(err, L2P_FAILED, scene, 0, "POV-Ray failed reading the scene's camera");
    free(links);
}

/* run_probe, started again while it fails for a passing cause, as a render's runs are. */
static int run_probe_again(const char *dir, const char *input, const char *log, int w, int h,
                           const probe_args *pa, l2p_error *err)
{
    int st;
    for (int retries = 0;; retries++) {
        st = run_probe(dir, input, log, w, h, pa, err);
        if (st >= 0 || !povray_retry_transient(log, retries))
            return st;
    }
}

/* After the copy failed: POV-Ray on the scene as it is. When that fails too, its error is the
   scene's, named in the user's own files; when it does not, the copy's camera statement, which
   prints each item, is what POV-Ray could not read (an item that a macro gives, say), and the
   camera is to be given on the command line. */
static void copy_or_scene_error(const char *scene, const char *dir, const char *work, int w,
                                int h, const probe_args *pa, l2p_error *err)
{
    char log[4200], abs[4200], cwd[4096];
    snprintf(log, sizeof log, "%s/scene-alone.log", work);
    if (scene[0] == '/' || !getcwd(cwd, sizeof cwd))
        snprintf(abs, sizeof abs, "%s", scene);
    else
        snprintf(abs, sizeof abs, "%s/%s", cwd, scene);
    l2p_error alone;
    const int st = run_probe_again(dir, abs, log, w, h, pa, &alone);
    const povray_log_names names = {scene, dir, {NULL, NULL}, NULL, 0};
    if (st < 0 && povray_log_error(log, &names, &alone))
        *err = alone;
    else if (st == L2P_OK) {
        char copy_error[sizeof err->text];
        snprintf(copy_error, sizeof copy_error, "%s", err->text);
        l2p_fail(err, L2P_BAD_INPUT, scene, 0, "lens2pov cannot read the scene's camera: POV-Ray "
                 "reads the scene, but not the copy that prints each item of its camera "
                 "(POV-Ray on the copy: %s); give the camera with --location, --look-at and "
                 "--angle instead (an item given by a macro can do this)", copy_error);
    }
    unlink(log);
}

static int run_copy(const char *scene, const char *dir, const char *work, int w, int h,
                    const probe_args *pa, const scene_copy *sc, scene_frames *out,
                    l2p_error *err)
{
    char copy[4200], top[4200], log[4200];
    snprintf(log, sizeof log, "%s/scene-camera.log", work);
    int st = write_probe_files(work, sc->text, copy, top, sizeof copy, err);
    if (!st) {
        st = run_probe_again(dir, top, log, w, h, pa, err);
        if (st < 0 && pa->user_count && refused_options(log, pa, err))
            st = L2P_BAD_INPUT;
        if (st < 0) {
            probe_error(scene, dir, top, copy, log, sc, err);
            if (err->status == L2P_BAD_INPUT)
                copy_or_scene_error(scene, dir, work, w, h, pa, err);
            st = err->status;
        }
    }
    size_t n = 0;
    char *out_log = st ? NULL : read_whole_file(log, &n);
    if (!st && !out_log)
        st = l2p_fail(err, L2P_FAILED, log, 0, "cannot read: %s", strerror(errno));
    const scene_files files = {(const char *const *)sc->path, sc->count};
    if (!st)
        st = scene_frames_from_log(out_log, n, &files, out, err);
    free(out_log);
    unlink(copy);
    unlink(top);
    unlink(log);
    return st;
}

static int probe(const char *scene, const char *dir, const char *work, int w, int h,
                 const probe_args *pa, scene_frames *out, l2p_error *err)
{
    size_t n = 0;
    char *text = read_whole_file(scene, &n);
    if (!text)
        return l2p_fail(err, L2P_BAD_INPUT, scene, 0, "cannot read: %s", strerror(errno));
    if (memchr(text, '\0', n)) {
        free(text);
        return l2p_fail(err, L2P_BAD_INPUT, scene, 0, "not a text file");
    }
    char **library = povargs_library_paths(dir, pa->user, pa->user_count);
    scene_copy sc;
    int st = library ? scene_copy_make(scene, text, n, work, library, &sc, err)
                     : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    povargs_free(library);
    if (st) {
        free(text);
        return st;
    }
    /* no included file has a camera, and every one was found */
    const bool own_text_only = sc.count == 1 && !sc.unresolved;
    if (own_text_only && pa->user_count == 0 && !strcmp(sc.text, text)) {
        st = one_default_frame(scene, out, err);   /* POV-Ray's default camera, one frame */
    } else {
        char *literal = own_text_only && !pa->user_count && !settings_may_differ(dir)
                            ? scene_camera_literal_log(text, n) : NULL;
        const scene_files files = {&scene, 1};
        if (literal)   /* what POV-Ray would print, without running it */
            st = scene_frames_from_log(literal, strlen(literal), &files, out, err);
        else
            st = run_copy(scene, dir, work, w, h, pa, &sc, out, err);
        free(literal);
    }
    const int computed = st ? 0 : scene_text_computed_include(text, n);
    for (int i = 0; computed && i < out->count; i++)
        if (!out->frame[i].cam.found)
            out->frame[i].cam.computed_include = computed;
    scene_copy_free(&sc);
    free(text);
    return st;
}

int scene_frames_read(const char *scene, int width, int height, char *const *args,
                      int arg_count, scene_frames *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    if (access(scene, R_OK) != 0)
        return l2p_fail(err, L2P_BAD_INPUT, scene, 0, "cannot read: %s", strerror(errno));
    char work[4096];
    snprintf(work, sizeof work, "%s/lens2pov-camera.XXXXXX", temp_root());
    if (!plain_path(work))
        snprintf(work, sizeof work, "/tmp/lens2pov-camera.XXXXXX");
    if (!mkdtemp(work))
        return l2p_fail(err, L2P_FAILED, work, 0, "cannot make a temporary folder: %s",
                        strerror(errno));
    cleanup_track(work);
    char *dir = folder_of(scene);
    const probe_args pa = {args, arg_count};
    const int st = dir ? probe(scene, dir, work, width, height, &pa, out, err)
                       : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    free(dir);
    rmdir(work);
    cleanup_untrack(work);
    if (st)
        scene_frames_free(out);
    return st;
}

int scene_camera_read(const char *scene, int width, int height, scene_camera *out,
                      l2p_error *err)
{
    scene_frames f;
    const int st = scene_frames_read(scene, width, height, NULL, 0, &f, err);
    if (!st)
        *out = f.frame[f.count - 1].cam;
    scene_frames_free(&f);
    return st;
}

void scene_frames_free(scene_frames *f)
{
    free(f->frame);
    memset(f, 0, sizeof *f);
}
