/* nftw is X/Open. */
#define _XOPEN_SOURCE 700

#include "support.h"
#include "image/image_io.h"

#include <criterion/criterion.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <math.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

const char *tmp_path(const char *dir, const char *name)
{
    static char buf[8][512];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 512, "%s/%s", dir, name);
    return p;
}

void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    cr_assert_not_null(f, "cannot write %s", path);
    fwrite(text, 1, strlen(text), f);
    fclose(f);
}

void write_bytes(const char *path, const char *data, size_t length)
{
    FILE *f = fopen(path, "wb");
    cr_assert_not_null(f, "cannot write %s: %s", path, strerror(errno));
    cr_assert_eq(fwrite(data, 1, length, f), length, "cannot write %s", path);
    cr_assert_eq(fclose(f), 0, "cannot write %s", path);
}

bool file_exists(const char *path)
{
    struct stat st;
    return lstat(path, &st) == 0;
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st;
    (void)flag;
    (void)ftw;
    return remove(path);
}

void remove_tree(const char *dir)
{
    cr_assert(strncmp(dir, "/tmp/", 5) == 0 && !strstr(dir, ".."), "not a test folder: %s", dir);
    cr_expect_eq(nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS), 0, "cannot remove %s: %s",
                 dir, strerror(errno));
}

/* Every test's folders go in one folder of the run, made before the first test (the tests'
   processes inherit its name) and removed after the last unless a test failed, so that a
   failure leaves its files to look at. Criterion ends a test's process without running
   atexit handlers, so the tests cannot clean up after themselves. */
static char run_dir[32];

ReportHook(PRE_ALL)(struct criterion_test_set *set)
{
    (void)set;
    snprintf(run_dir, sizeof run_dir, "/tmp/l2ptest.XXXXXX");
    if (mkdtemp(run_dir))
        setenv("LENS2POV_TEST_DIR", run_dir, 1);
}

ReportHook(POST_ALL)(struct criterion_global_stats *stats)
{
    if (run_dir[0] && stats->tests_failed == 0 && stats->tests_crashed == 0)
        nftw(run_dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    else if (run_dir[0])
        fprintf(stderr, "the tests' files are kept in %s\n", run_dir);
}

const char *test_tmpdir(void)
{
    static char dir[64];
    const char *root = getenv("LENS2POV_TEST_DIR");
    snprintf(dir, sizeof dir, "%s/t.XXXXXX", root ? root : "/tmp");
    cr_assert_not_null(mkdtemp(dir), "mkdtemp %s: %s", dir, strerror(errno));
    return dir;
}

int count_entries(const char *dir, const char *prefix, char *listing, size_t size)
{
    DIR *d = opendir(dir);
    cr_assert_not_null(d, "cannot list %s", dir);
    int n = 0;
    if (listing && size)
        listing[0] = '\0';
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        if (prefix && strncmp(e->d_name, prefix, strlen(prefix)))
            continue;
        n++;
        if (listing) {
            const size_t len = strlen(listing);
            snprintf(listing + len, size - len, "%s ", e->d_name);
        }
    }
    closedir(d);
    return n;
}

void test_camera(camera *c, const char *lens_name, const camera_options *o)
{
    char path[512];
    snprintf(path, sizeof path, LENS_DIR "%s.dat", lens_name);
    lens l;
    l2p_error err;
    cr_assert_eq(lens_read(path, &l, &err), 0, "%s", err.text);
    camera_options defaults;
    camera_options_default(&defaults);
    cr_assert_eq(camera_setup(c, &l, o ? o : &defaults, &err), 0, "%s: %s", lens_name, err.text);
}

char *read_text(const char *path, size_t *length)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    size_t got = fread(s, 1, (size_t)n, f);
    s[got] = '\0';
    fclose(f);
    if (length)
        *length = got;
    return s;
}

/* LeakSanitizer's stop-the-world tracer sometimes crashes at exit of a process that had
   threads (google/sanitizers#1353): the run itself finished, but its status is LSan's. Only
   that exact message, without a leak report, is taken for the sanitizer's failure, and the
   run is made again up to LSAN_RETRIES times. (The crashes that came on every retry were
   another fault, avoided by make test-sanitize's ASAN_OPTIONS: docs/testing.md.) */
enum { LSAN_RETRIES = 6 };
static bool lsan_crashed(const char *errtext)
{
    return errtext && strstr(errtext, "LeakSanitizer has encountered a fatal error") &&
           !strstr(errtext, "ERROR: LeakSanitizer: detected memory leaks");
}

static int spawn_once(char *const argv[], char **out, char **errout);

int run_lens2pov(char **out, char **errout, ...)
{
    char *args[64];
    int n = 0;
    va_list ap;
    va_start(ap, errout);
    for (char *a; (a = va_arg(ap, char *)) != NULL;) {
        cr_assert_lt(n, 63, "too many arguments");
        args[n++] = a;
    }
    va_end(ap);
    args[n] = NULL;
    return run_lens2pov_argv(out, errout, args);
}

void run_lens2pov_ok(const char *what, ...)
{
    char *args[64];
    int n = 0;
    va_list ap;
    va_start(ap, what);
    for (char *a; (a = va_arg(ap, char *)) != NULL;) {
        cr_assert_lt(n, 63, "too many arguments");
        args[n++] = a;
    }
    va_end(ap);
    args[n] = NULL;
    char *errtext = NULL;
    const int st = run_lens2pov_argv(NULL, &errtext, args);
    /* A copy on the stack: the failed assertion ends the test before a free. */
    char text[2048];
    snprintf(text, sizeof text, "%s", errtext ? errtext : "");
    free(errtext);
    cr_assert_eq(st, 0, "%s: exit %d: %s", what, st, text);
}

int run_lens2pov_argv(char **out, char **errout, char *const args[])
{
    const char *bin = getenv("LENS2POV");
    if (!bin)
        bin = LENS2POV_SOURCE_DIR "/build/lens2pov";
    char *argv[128];
    int n = 0;
    argv[n++] = (char *)bin;
    for (; args[n - 1]; n++) {
        cr_assert_lt(n, 127, "too many arguments");
        argv[n] = args[n - 1];
    }
    argv[n] = NULL;
    char *o, *e;
    int status = spawn_once(argv, &o, &e);
    for (int retry = 0; retry < LSAN_RETRIES && lsan_crashed(e); retry++) {
        cr_log_warn("LeakSanitizer's tracer crashed at exit; running again: %s", argv[1] ? argv[1] : "");
        free(o);
        free(e);
        status = spawn_once(argv, &o, &e);
    }
    if (out) *out = o; else free(o);
    if (errout) *errout = e; else free(e);
    return status;
}

static int spawn_once(char *const argv[], char **out, char **errout)
{
    const char *bin = argv[0];
    char dir[64];
    snprintf(dir, sizeof dir, "/tmp/l2prun.XXXXXX");
    cr_assert_not_null(mkdtemp(dir));
    char o_path[128], e_path[128];
    snprintf(o_path, sizeof o_path, "%s/out", dir);
    snprintf(e_path, sizeof e_path, "%s/err", dir);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, o_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&fa, 2, e_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid;
    /* A binary just linked can be busy for a moment (ETXTBSY), and a loaded machine can be out
       of processes (EAGAIN): both pass. */
    int e = posix_spawn(&pid, bin, &fa, NULL, argv, environ);
    for (int tries = 0; (e == ETXTBSY || e == EAGAIN) && tries < 20; tries++) {
        nanosleep(&(struct timespec){0, 50000000}, NULL);
        e = posix_spawn(&pid, bin, &fa, NULL, argv, environ);
    }
    cr_assert_eq(e, 0, "cannot run %s: %s", bin, strerror(e));
    posix_spawn_file_actions_destroy(&fa);
    int status = 0;
    waitpid(pid, &status, 0);
    *out = read_text(o_path, NULL);
    *errout = read_text(e_path, NULL);
    unlink(o_path);
    unlink(e_path);
    rmdir(dir);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

csv_ray *read_rays_csv(const char *path, size_t *count)
{
    FILE *f = fopen(path, "r");
    cr_assert_not_null(f, "cannot read %s", path);
    char line[1024];
    cr_assert_not_null(fgets(line, sizeof line, f));
    cr_assert_str_eq(line, "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,"
                           "dir_x,dir_y,dir_z,weight\n");
    size_t n = 0, cap = 1024;
    csv_ray *r = malloc(cap * sizeof *r);
    while (fgets(line, sizeof line, f)) {
        if (n == cap)
            r = realloc(r, (cap *= 2) * sizeof *r);
        csv_ray *x = &r[n++];
        int k = sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &x->raster_x,
                       &x->raster_y, &x->film_x, &x->film_y, &x->o.x, &x->o.y, &x->o.z, &x->d.x,
                       &x->d.y, &x->d.z, &x->weight);
        cr_assert_eq(k, 11, "bad csv row: %s", line);
    }
    fclose(f);
    *count = n;
    return r;
}

/* One row of a field render's CSV: the pixel-sampling columns, then image, image_x, image_y. */
field_csv_ray *read_field_rays_csv(const char *path, size_t *count)
{
    FILE *f = fopen(path, "r");
    cr_assert_not_null(f, "cannot read %s", path);
    char line[1024];
    cr_assert_not_null(fgets(line, sizeof line, f));
    cr_assert_str_eq(line, "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,"
                           "dir_x,dir_y,dir_z,weight,image,image_x,image_y\n");
    size_t n = 0, cap = 1024;
    field_csv_ray *r = malloc(cap * sizeof *r);
    while (fgets(line, sizeof line, f)) {
        if (n == cap)
            r = realloc(r, (cap *= 2) * sizeof *r);
        field_csv_ray *x = &r[n++];
        int k = sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d,%d,%d", &x->ray.raster_x,
                       &x->ray.raster_y, &x->ray.film_x, &x->ray.film_y, &x->ray.o.x, &x->ray.o.y,
                       &x->ray.o.z, &x->ray.d.x, &x->ray.d.y, &x->ray.d.z, &x->ray.weight, &x->image,
                       &x->image_x, &x->image_y);
        cr_assert_eq(k, 14, "bad csv row: %s", line);
    }
    fclose(f);
    *count = n;
    return r;
}

/* The numbers after `key {`: a count, then count groups of n numbers in <...>. */
static double *read_block(const char *text, const char *key, int n, int *count)
{
    const char *p = strstr(text, key);
    cr_assert_not_null(p, "no %s", key);
    p = strchr(p, '{') + 1;
    *count = (int)strtol(p, (char **)&p, 10);
    double *v = malloc(sizeof *v * (size_t)(*count * n + 1));
    for (int i = 0; i < *count * n; i++) {
        while (*p && !(*p == '-' || *p == '.' || (*p >= '0' && *p <= '9')))
            p++;
        v[i] = strtod(p, (char **)&p);
    }
    return v;
}

void read_field_include(const char *text, povuv_mesh *pm)
{
    int nv, nn, nu, nf;
    double *pos = read_block(text, "vertex_vectors", 3, &nv), *nrm = read_block(text, "normal_vectors", 3, &nn);
    double *uv = read_block(text, "uv_vectors", 2, &nu), *tri = read_block(text, "face_indices", 3, &nf);
    cr_assert(nv == nn && nv == nu);
    povuv_face *faces = malloc(sizeof *faces * (size_t)(nf + 1));
    for (int k = 0; k < nf; k++) {
        double p[3][3], n[3][3], t[3][2];
        for (int j = 0; j < 3; j++) {
            int i = (int)tri[3 * k + j];
            cr_assert(i >= 0 && i < nv);
            memcpy(p[j], pos + 3 * i, sizeof p[j]), memcpy(n[j], nrm + 3 * i, sizeof n[j]);
            memcpy(t[j], uv + 2 * i, sizeof t[j]);
        }
        povuv_face_init(&faces[k], p, n, t);
    }
    cr_assert_eq(povuv_mesh_init(pm, faces, nf), 0);
    free(pos), free(nrm), free(uv), free(tri);
}

/* Parses just what the emitter writes: "vertex_vectors { N," then "<x,y,z>," per vertex,
   "face_indices { M," then "<a,b,c>," per face, then "scale S translate <x, y, z>". */
pov_ray *read_include_as_povray(const char *path, size_t *count)
{
    char *text = read_text(path, NULL);
    cr_assert_not_null(text, "cannot read %s", path);
    char *p = strstr(text, "vertex_vectors {");
    cr_assert_not_null(p);
    long nv = strtol(p + 16, &p, 10);
    float (*v)[3] = malloc(sizeof *v * (size_t)(nv > 0 ? nv : 1));
    for (long i = 0; i < nv; i++) {
        p = strchr(p, '<') + 1;
        for (int k = 0; k < 3; k++) {
            v[i][k] = (float)strtod(p, &p);   /* POV-Ray parses a double, stores a float */
            p++;
        }
    }
    p = strstr(p, "face_indices {");
    cr_assert_not_null(p);
    long nf = strtol(p + 14, &p, 10);
    pov_ray *r = malloc(sizeof *r * (size_t)(nf > 0 ? nf : 1));
    long (*f)[3] = malloc(sizeof *f * (size_t)(nf > 0 ? nf : 1));
    for (long i = 0; i < nf; i++) {
        p = strchr(p, '<') + 1;
        for (int k = 0; k < 3; k++) {
            f[i][k] = strtol(p, &p, 10);
            p++;
        }
    }
    /* The mesh's transform, applied in double: scale (uniform) then translate. */
    p = strstr(p, "Lens2pov_Rays scale ");
    cr_assert_not_null(p);
    const double scale = strtod(p + 20, &p);
    p = strstr(p, "translate <");
    cr_assert_not_null(p);
    p += 11;
    double t[3];
    for (int k = 0; k < 3; k++) {
        t[k] = strtod(p, &p);
        p++;
    }
    for (long i = 0; i < nf; i++) {
        vec3 q[3];
        for (int k = 0; k < 3; k++) {
            const float *x = v[f[i][k]];
            q[k] = v3(x[0], x[1], x[2]);
        }
        const vec3 c = v3_scale(v3_add(v3_add(q[0], q[1]), q[2]), scale / 3.0);
        r[i].o = v3_add(c, v3(t[0], t[1], t[2]));
        r[i].d = v3_normalize(v3_cross(v3_sub(q[2], q[0]), v3_sub(q[1], q[0])));
    }
    free(v);
    free(f);
    free(text);
    *count = (size_t)nf;
    return r;
}

marker_centroid image_marker(const char *path, int c)
{
    int w, h;
    float *p;
    l2p_error err;
    cr_assert_eq(image_read_rgba(path, &w, &h, &p, &err), 0, "%s: %s", path, err.text);
    double sx = 0, sy = 0, s = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *q = p + 4 * ((size_t)y * (size_t)w + (size_t)x);
            const double v = q[c], others = q[0] + q[1] + q[2] - q[c];
            if (v > 0.05 && v > 2 * others) {
                sx += v * (x + 0.5);
                sy += v * (y + 0.5);
                s += v;
            }
        }
    free(p);
    return (marker_centroid){s > 0 ? sx / s : NAN, s > 0 ? sy / s : NAN, s > 0};
}

int system_povray(const char *command)
{
    int status = -1;
    for (int tries = 0; tries < 6 && status != 0; tries++) {
        if (tries)
            usleep(100000u << (tries - 1));
        status = system(command);
    }
    return status;
}

double json_number(const char *json, const char *key)
{
    char quoted[128];
    snprintf(quoted, sizeof quoted, "\"%s\":", key);
    const char *p = strstr(json, quoted);
    cr_assert_not_null(p, "info --json has no %s:\n%s", key, json);
    char *end;
    const double v = strtod(p + strlen(quoted), &end);
    cr_assert(end != p + strlen(quoted), "%s is not a number", key);
    return v;
}

void expect_attribute(const char *path, const char *key, const char *want)
{
    char value[256];
    cr_assert_eq(image_get_attribute(path, key, value, sizeof value), L2P_OK, "%s: no %s", path, key);
    cr_assert_str_eq(value, want, "%s: %s", path, key);
}
