#include "povray/povargs.h"

#include <ctype.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* Switches (+X or -X, case-insensitive) lens2pov sets for the ray table: the image's size
   (W, H: but WT, threads, and WL, warnings, are harmless), antialiasing (A...), output type
   and file (F..., O...), crops (SR, SC, ER, EC) and the input (I). */
static const char *refused_switch(const char *a)
{
    const char c0 = (char)toupper((unsigned char)a[1]), c1 = (char)toupper((unsigned char)a[2]);
    if (c0 == 'W')
        return c1 == 'T' || c1 == 'L' ? NULL : "the image's width";
    if (c0 == 'H')
        return "the image's height";
    if (c0 == 'A')
        return "antialiasing";
    if (c0 == 'F')
        return "the output file's type";
    if (c0 == 'O')
        return "the output file";
    if (c0 == 'I')
        return "the input file";
    if ((c0 == 'S' || c0 == 'E') && (c1 == 'R' || c1 == 'C'))
        return "a crop";
    return NULL;
}

/* The INI keys (before '=') for the same settings. */
static const char *refused_key(const char *a, size_t n)
{
    static const struct { const char *key; const char *what; } keys[] = {
        {"Width", "the image's width"}, {"Height", "the image's height"},
        {"Antialias", "antialiasing"}, {"Antialias_Threshold", "antialiasing"},
        {"Antialias_Depth", "antialiasing"}, {"Antialias_Gamma", "antialiasing"},
        {"Sampling_Method", "antialiasing"}, {"Jitter", "antialiasing"},
        {"Jitter_Amount", "antialiasing"}, {"Output_File_Type", "the output file's type"},
        {"Output_File_Name", "the output file"}, {"Output_To_File", "the output file"},
        {"Output_Alpha", "the output file's alpha"}, {"Input_File_Name", "the input file"},
        {"Start_Row", "a crop"}, {"End_Row", "a crop"}, {"Start_Column", "a crop"},
        {"End_Column", "a crop"},
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (strlen(keys[i].key) == n && !strncasecmp(a, keys[i].key, n))
            return keys[i].what;
    return NULL;
}

int povargs_check(char *const *args, int count, l2p_error *err)
{
    for (int i = 0; i < count; i++) {
        const char *a = args[i], *eq = strchr(a, '=');
        const char *what = (a[0] == '+' || a[0] == '-') && a[1] ? refused_switch(a)
                           : eq ? refused_key(a, (size_t)(eq - a)) : NULL;
        if (what)
            return l2p_fail(err, L2P_BAD_INPUT, NULL, 0,
                            "-- %s: lens2pov sets %s for its ray table (give the film's with "
                            "--width, --height, --spp, --crop and -o)", a, what);
    }
    return L2P_OK;
}

/* head + path, the path made absolute when it is relative and exists here. */
static bool ends_with_pictures(const char *a)
{
    static const char *const keys[] = {"Declare", "Initial_Frame", "Final_Frame",
                                       "Initial_Clock", "Final_Clock", "Subset_Start_Frame",
                                       "Subset_End_Frame", "Cyclic_Animation", "Quality",
                                       "Work_Threads", "Library_Path"};
    const char *eq = strchr(a, '=');
    if ((a[0] == '+' || a[0] == '-') && a[1]) {
        const char c0 = (char)toupper((unsigned char)a[1]), c1 = (char)toupper((unsigned char)a[2]);
        return c0 == 'K' || c0 == 'Q' || c0 == 'L' || (c0 == 'W' && c1 == 'T') ||
               ((c0 == 'S' || c0 == 'E') && c1 == 'F');
    }
    for (size_t i = 0; eq && i < sizeof keys / sizeof keys[0]; i++)
        if (strlen(keys[i]) == (size_t)(eq - a) && !strncasecmp(a, keys[i], (size_t)(eq - a)))
            return true;
    return false;
}

bool povargs_end_with_pictures(char *const *args, int count)
{
    for (int i = 0; i < count; i++)
        if (!ends_with_pictures(args[i]))
            return false;
    return true;
}

/* The length of a file name given alone without the section POV-Ray reads of it, as in
   "FILE.ini[Section]". */
static size_t without_section(const char *a)
{
    const size_t n = strlen(a);
    const char *open = strrchr(a, '[');
    return open && open > a && n > 0 && a[n - 1] == ']' ? (size_t)(open - a) : n;
}

static char *resolved(const char *head, size_t head_len, const char *path)
{
    char cwd[4096], file[4096];
    snprintf(file, sizeof file, "%.*s", (int)without_section(path), path);
    const bool relative = path[0] && path[0] != '/' && access(file, F_OK) == 0 &&
                          getcwd(cwd, sizeof cwd);
    const size_t n = head_len + strlen(path) + (relative ? strlen(cwd) + 2 : 1);
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%.*s%s%s%s", (int)head_len, head, relative ? cwd : "",
                 relative ? "/" : "", path);
    return s;
}

static char *resolve_one(const char *a)
{
    if ((a[0] == '+' || a[0] == '-') && (a[1] == 'L' || a[1] == 'l'))
        return resolved(a, 2, a + 2);
    const char *eq = strchr(a, '=');
    if (eq && (size_t)(eq - a) == strlen("Library_Path") && !strncasecmp(a, "Library_Path", 12))
        return resolved(a, (size_t)(eq - a) + 1, eq + 1);
    if (!eq && a[0] != '+' && a[0] != '-')
        return resolved("", 0, a);
    return strdup(a);
}

char **povargs_resolve(char *const *args, int count)
{
    char **out = calloc((size_t)count + 1, sizeof *out);
    for (int i = 0; out && i < count; i++)
        if (!(out[i] = resolve_one(args[i]))) {
            povargs_free(out);
            return NULL;
        }
    return out;
}

void povargs_free(char **args)
{
    for (int i = 0; args && args[i]; i++)
        free(args[i]);
    free(args);
}

int povargs_frame_digits(int final_frame)
{
    int digits = 1;
    for (int i = final_frame; i >= 10; i /= 10)
        digits++;
    return digits;
}

char *povargs_frame_name(const char *path, int frame, int digits)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        dot = path + strlen(path);
    const size_t n = strlen(path) + 32;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%.*s%0*d%s", (int)(dot - path), path, digits, frame, dot);
    return s;
}

/* ---------------------------------------------------------------- the library path */

typedef struct paths {
    char **dir;
    int count, cap;
    bool failed;
} paths;

/* dir (len bytes, quotes trimmed) onto the list, relative to folder when relative. */
static void add_path(paths *p, const char *folder, const char *dir, size_t len)
{
    while (len > 0 && isspace((unsigned char)dir[len - 1]))
        len--;
    if (len >= 2 && dir[0] == '"' && dir[len - 1] == '"')
        dir++, len -= 2;
    if (len == 0 || p->failed)
        return;
    if (p->count + 1 >= p->cap) {
        char **grown = realloc(p->dir, (size_t)(p->cap = 2 * p->cap + 8) * sizeof *grown);
        if (!grown) {
            p->failed = true;
            return;
        }
        p->dir = grown;
    }
    const size_t n = len + strlen(folder) + 2;
    char *s = malloc(n);
    if (!s) {
        p->failed = true;
        return;
    }
    if (dir[0] == '/')
        snprintf(s, n, "%.*s", (int)len, dir);
    else
        snprintf(s, n, "%s/%.*s", folder, (int)len, dir);
    p->dir[p->count++] = s;
    p->dir[p->count] = NULL;
}

/* A setting that names a library folder: +L/-L DIR or Library_Path = DIR. */
static void take_setting(paths *p, const char *folder, const char *a, size_t len)
{
    while (len > 0 && isspace((unsigned char)*a))
        a++, len--;
    if (len > 2 && (a[0] == '+' || a[0] == '-') && (a[1] == 'L' || a[1] == 'l')) {
        add_path(p, folder, a + 2, len - 2);
        return;
    }
    static const char key[] = "Library_Path";
    const size_t k = sizeof key - 1;
    if (len <= k || strncasecmp(a, key, k))
        return;
    size_t i = k;
    while (i < len && isspace((unsigned char)a[i]))
        i++;
    if (i >= len || a[i] != '=')
        return;
    for (i++; i < len && isspace((unsigned char)a[i]); i++)
        continue;
    add_path(p, folder, a + i, len - i);
}

/* The settings of an ini file, outside its ';' comments. A missing file has none. */
static void take_ini(paths *p, const char *folder, const char *path)
{
    FILE *f = path ? fopen(path, "r") : NULL;
    char line[4096];
    while (f && fgets(line, sizeof line, f))
        take_setting(p, folder, line, strcspn(line, ";\r\n"));
    if (f)
        fclose(f);
}

static bool is_ini(const char *a)
{
    const size_t n = without_section(a);
    return a[0] != '+' && a[0] != '-' && !strchr(a, '=') && n > 4 &&
           !strncasecmp(a + n - 4, ".ini", 4);
}

void povargs_default_inis(const char *folder, char buf[POVARGS_INIS][POVARGS_INI_PATH],
                          const char *ini[POVARGS_INIS])
{
    const char *home = getenv("HOME"), *povini = getenv("POVINI");
    snprintf(buf[1], POVARGS_INI_PATH, "%s/povray.ini", folder);
    snprintf(buf[2], POVARGS_INI_PATH, "%s/POVRAY.INI", folder);
    snprintf(buf[3], POVARGS_INI_PATH, "%s/.povray/3.7/povray.ini", home ? home : "");
    ini[0] = povini && *povini ? povini : NULL;
    ini[1] = buf[1];
    ini[2] = buf[2];
    ini[3] = home && *home ? buf[3] : NULL;
    ini[4] = "/etc/povray/3.7/povray.ini";
}

char **povargs_library_paths(const char *folder, char *const *args, int count)
{
    paths p = {NULL, 0, 0, false};
    char buf[POVARGS_INIS][POVARGS_INI_PATH];
    const char *inis[POVARGS_INIS];
    povargs_default_inis(folder, buf, inis);
    for (int i = 0; i < POVARGS_INIS; i++)
        take_ini(&p, folder, inis[i]);
    for (int i = 0; i < count; i++) {
        if (!is_ini(args[i])) {
            take_setting(&p, folder, args[i], strlen(args[i]));
            continue;
        }
        char ini[POVARGS_INI_PATH];
        snprintf(ini, sizeof ini, "%s%s%.*s", args[i][0] == '/' ? "" : folder,
                 args[i][0] == '/' ? "" : "/", (int)without_section(args[i]), args[i]);
        take_ini(&p, folder, ini);
    }
    if (!p.failed && !p.dir)
        p.dir = calloc(1, sizeof *p.dir);
    if (p.failed) {
        povargs_free(p.dir);
        return NULL;
    }
    return p.dir;
}
