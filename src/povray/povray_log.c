/* POV-Ray's log: why a run failed, in POV-Ray's own words, and how far it has got. */
#include "povray/povray_log.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <string.h>
#include <unistd.h>

enum {
    TOKENS_PER_FACE = 23,      /* of "Parsing NK tokens", for the parse's progress: 8 tokens
                                  (< x , y , z > ,) for a face's indices and for each of its
                                  vertices, of which neighbours on a shared edge have two */
    PROGRESS_TAIL = 256,       /* bytes of a log read for the latest status line */
    FRAME_TAIL = 65536,        /* bytes of an animation's log searched for its frame */
    ERROR_TAIL = 65536,        /* bytes of a failed log searched for POV-Ray's messages */
    MAX_MESSAGES = 64
};

/* The last `len` bytes of a file (at most), NUL-terminated; NULL if unreadable. */
static char *read_tail(const char *path, long len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    const long size = ftell(f);
    const long from = size > len ? size - len : 0;
    fseek(f, from, SEEK_SET);
    char *s = malloc((size_t)(size - from) + 1);
    const size_t got = s ? fread(s, 1, (size_t)(size - from), f) : 0;
    if (s)
        s[got] = '\0';
    fclose(f);
    return s;
}

void povray_log_last_line(const char *log_path, char *out, size_t n)
{
    if (n == 0)
        return;
    char *s = read_tail(log_path, PROGRESS_TAIL);
    size_t end = s ? strlen(s) : 0;
    while (end > 0 && strchr(" \t\r\n", s[end - 1]))
        end--;
    size_t start = end;
    while (start > 0 && s[start - 1] != '\n' && s[start - 1] != '\r')
        start--;
    while (start < end && (s[start] == ' ' || s[start] == '\t'))
        start++;
    const size_t len = end - start < n - 1 ? end - start : n - 1;
    if (len)
        memcpy(out, s + start, len);
    out[len] = '\0';
    free(s);
}

/* An animation announces each frame on a line "Rendering frame F of N" (twice for the first):
   the text after the last such line in s, or s. */
static char *current_frame(char *s, int *frame)
{
    static const char mark[] = "Rendering frame ";
    char *after = s;
    for (char *p = s; (p = strstr(p, mark)) != NULL; p += sizeof mark - 1) {
        if (p != s && p[-1] != '\n' && p[-1] != '\r')
            continue;
        int f;
        if (sscanf(p + sizeof mark - 1, "%d", &f) == 1 && frame)
            *frame = f;
        after = p + strcspn(p, "\r\n");
    }
    return after;
}

/* One message: POV-Ray wraps long messages onto lines that start with one space. */
typedef struct message {
    char file[1024];
    int line;
    int rank;                  /* 3 Parse Error, 2 Possible Parse Error, 1 other text, 0 noise */
    bool section;              /* a "==== [Parsing...] ====" line */
    char text[512];
} message;

static bool starts_with(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* Progress, banners, warnings and endings carry no reason for a failure. */
static bool is_noise(const char *s)
{
    static const char *const prefixes[] = {"====", "Rendered ", "Parsing ", "Render failed",
                                           "Render cancelled", "POV-Ray finished",
                                           "Fatal error in parser:",
                                           "povray: cannot open the user configuration file"};
    for (size_t i = 0; i < sizeof prefixes / sizeof prefixes[0]; i++)
        if (starts_with(s, prefixes[i]))
            return true;
    return !*s || strstr(s, "Warning:") || strstr(s, "assumed_gamma not specified");
}

/* Splits "File 'F' line N: Kind: text" into its parts and ranks it. */
static void classify(message *m, const char *s)
{
    memset(m, 0, sizeof *m);
    const char *rest = s, *q;
    int line;
    if (starts_with(s, "File '") && (q = strstr(s + 6, "' line ")) &&
        sscanf(q, "' line %d", &line) == 1 && strchr(q, ':')) {
        snprintf(m->file, sizeof m->file, "%.*s", (int)(q - (s + 6)), s + 6);
        m->line = line;
        rest = strchr(q, ':') + 1;
        while (*rest == ' ')
            rest++;
    }
    if (starts_with(rest, "Parse Error:"))
        m->rank = 3, rest += strlen("Parse Error:");
    else if (starts_with(rest, "Possible Parse Error:"))
        m->rank = 2, rest += strlen("Possible Parse Error:");
    else
        m->rank = is_noise(s) ? 0 : 1;
    while (*rest == ' ')
        rest++;
    m->section = starts_with(s, "====");
    snprintf(m->text, sizeof m->text, "%.*s", (int)sizeof m->text - 1, rest);
    const size_t n = strlen(m->text);
    if (n && m->text[n - 1] == '.')
        m->text[n - 1] = '\0';
}

/* Splits the log into messages (joining continuation lines); returns how many. */
static int split_messages(char *log, message *out, int max)
{
    int count = 0;
    char joined[1536] = "";
    char *save = NULL;
    for (char *ln = strtok_r(log, "\r\n", &save);; ln = strtok_r(NULL, "\r\n", &save)) {
        if (ln && ln[0] == ' ' && ln[1] != ' ' && joined[0]) {
            const size_t n = strlen(joined);
            snprintf(joined + n, sizeof joined - n, "%s", ln);
            continue;
        }
        if (joined[0]) {
            if (count == max) {
                memmove(out, out + 1, (size_t)(max - 1) * sizeof *out);
                count--;
            }
            classify(&out[count++], joined);
        }
        if (!ln)
            return count;
        snprintf(joined, sizeof joined, "%s", ln);
    }
}

/* A path in POV-Ray's words, with our symlinks turned back into the user's paths. POV-Ray
   names a file as the scene wrote it: a relative name was found in its working folder, the
   scene's folder, when it is there. */
static void unlink_name(const povray_log_names *names, const char *file, char *out, size_t size)
{
    if (file[0] != '/') {
        char in_scene_dir[4096];
        snprintf(in_scene_dir, sizeof in_scene_dir, "%s/%s", names->scene_dir, file);
        snprintf(out, size, "%s", access(in_scene_dir, F_OK) == 0 ? in_scene_dir : file);
        return;
    }
    for (int i = 0; i < names->link_count; i++) {
        const size_t n = strlen(names->links[i].link);
        if (strncmp(file, names->links[i].link, n) == 0 && (file[n] == '\0' || file[n] == '/')) {
            snprintf(out, size, "%s%s", names->links[i].target, file + n);
            return;
        }
    }
    snprintf(out, size, "%s", file);
}

/* The message that says why: the last Parse Error, else the last Possible Parse Error or
   other text (only text after POV-Ray's first section line: before it is the banner); -1 if
   none. "Fatal error in parser" is only the consequence of an earlier message. */
static int telling_message(const message *m, int n)
{
    int first_section = -1, best = -1;
    for (int i = 0; i < n && first_section < 0; i++)
        if (m[i].section)
            first_section = i;
    for (int i = 0; i < n; i++) {
        const bool counts = m[i].rank >= 2 || (m[i].rank == 1 && i > first_section);
        if (counts && (best < 0 || m[best].rank < 3 || m[i].rank == 3))
            best = i;
    }
    return best;
}

/* Whether file is lens2pov's wrapper or camera include (compared by real path: POV-Ray may
   name them through a symlink). */
static bool is_own_file(const povray_log_names *names, const char *file)
{
    char *real = realpath(file, NULL);
    bool own = false;
    for (int i = 0; i < 2 && real; i++) {
        char *mine = names->own[i] ? realpath(names->own[i], NULL) : NULL;
        own |= mine && strcmp(mine, real) == 0;
        free(mine);
    }
    free(real);
    return own;
}

/* Reports m[best] as FILE:LINE: text, joined with the other errors at the same place. */
static int report_messages(const povray_log_names *names, const message *m, int n,
                           l2p_error *err)
{
    const int best = telling_message(m, n);
    if (best < 0)
        return 0;
    char text[900] = "";
    for (int i = 0; i < n; i++) {
        const bool same = i == best || (m[best].rank >= 2 && m[i].rank >= 2 &&
                                         m[i].line == m[best].line &&
                                         strcmp(m[i].file, m[best].file) == 0);
        if (!same || (i > 0 && m[i - 1].rank >= 2 && strcmp(m[i].text, m[i - 1].text) == 0))
            continue;
        const size_t len = strlen(text);
        snprintf(text + len, sizeof text - len, "%s%s", len ? "; " : "", m[i].text);
    }
    if (!m[best].file[0])
        return l2p_fail(err, L2P_FAILED, NULL, 0, "povray: %s", text);
    char file[4096];
    unlink_name(names, m[best].file, file, sizeof file);
    /* a parse error, or a possible one that stopped the render (a missing image file), is
       the scene's: bad input, as a bad lens file is */
    const int status = m[best].rank >= 2 ? L2P_BAD_INPUT : L2P_FAILED;
    if (is_own_file(names, file))
        return l2p_fail(err, status, names->scene, 0,
                        "the scene ends inside an unclosed block or #if (POV-Ray, reading on: %s)",
                        text);
    return l2p_fail(err, status, file, m[best].line, "%s", text);
}

int povray_log_error(const char *log_path, const povray_log_names *names, l2p_error *err)
{
    char *log = read_tail(log_path, ERROR_TAIL);
    message *m = calloc(MAX_MESSAGES, sizeof *m);
    const int n = log && m ? split_messages(current_frame(log, NULL), m, MAX_MESSAGES) : 0;
    const int st = report_messages(names, m, n, err);
    free(m);
    free(log);
    return st;
}

/* The latest "Parsing NK tokens" or "Rendered N of M pixels" in the log's tail. The parse
   share is estimated from the chunk's face count. */
void povray_log_progress(const char *log_path, long long faces, double *parse, double *render)
{
    char *whole = read_tail(log_path, PROGRESS_TAIL);
    if (!whole)
        return;
    char *tail = current_frame(whole, NULL);
    long long a, b;
    for (char *p = tail; (p = strstr(p, "Rendered ")) != NULL; p++)
        if (sscanf(p, "Rendered %lld of %lld", &a, &b) == 2 && b > 0) {
            *parse = 1;
            *render = (double)a / (double)b;
        }
    for (char *p = tail; *render == 0 && (p = strstr(p, "Parsing ")) != NULL; p++)
        if (sscanf(p, "Parsing %lldK tokens", &a) == 1 && faces > 0)
            *parse = (double)a * 1000.0 / ((double)faces * TOKENS_PER_FACE);
    if (*parse > 1)
        *parse = 1;
    free(whole);
}

int povray_log_frame(const char *log_path, int frame)
{
    char *tail = read_tail(log_path, FRAME_TAIL);
    if (tail)
        current_frame(tail, &frame);
    free(tail);
    return frame;
}


/* POV-Ray 3.7 gives up on a render whose worker threads do not report in within its time
   limit, which a loaded machine can exceed; the same run succeeds when started again. */
bool povray_log_transient(const char *log_path)
{
    char *tail = read_tail(log_path, ERROR_TAIL);
    const bool transient = tail && strstr(tail, "Timed out waiting for worker thread startup");
    free(tail);
    return transient;
}

/* The pauses grow because the cause is load, and such failures come in runs: 0.1 s doubling
   to 6.4 s, 12.7 s in all. */
enum { TRANSIENT_RETRIES = 7, TRANSIENT_PAUSE_MS = 100 };

bool povray_retry_transient(const char *log_path, int retries_made)
{
    if (retries_made >= TRANSIENT_RETRIES || !povray_log_transient(log_path))
        return false;
    fprintf(stderr, "lens2pov: warning: POV-Ray timed out starting its threads (a loaded "
                    "machine); starting it again\n");
    const long ms = (long)TRANSIENT_PAUSE_MS << retries_made;
    const struct timespec pause = {ms / 1000, ms % 1000 * 1000000L};
    nanosleep(&pause, NULL);
    return true;
}
