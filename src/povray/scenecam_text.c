/* The scene copy for the camera probe: every camera statement becomes #debug lines that make
   POV-Ray print its items, evaluated where the statement stands. Only the statement's keyword
   structure is read here; every expression is handed to POV-Ray as written. */
#include "povray/scenecam.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct text {
    char *s;
    size_t n, cap;
    bool failed;
} text;

static void put(text *t, const char *s, size_t n)
{
    if (t->failed)
        return;
    if (t->n + n + 1 > t->cap) {
        size_t cap = t->cap ? t->cap : 4096;
        while (t->n + n + 1 > cap)
            cap *= 2;
        char *grown = realloc(t->s, cap);
        if (!grown) {
            t->failed = true;
            return;
        }
        t->s = grown;
        t->cap = cap;
    }
    memcpy(t->s + t->n, s, n);
    t->n += n;
    t->s[t->n] = '\0';
}

static void puts_(text *t, const char *s) { put(t, s, strlen(s)); }

/* Past the comment starting at i (a line comment, or a block comment, which nests in
   POV-Ray), else i. */
static size_t skip_comment(const char *s, size_t n, size_t i)
{
    if (i + 1 < n && s[i] == '/' && s[i + 1] == '/') {
        while (i < n && s[i] != '\n')
            i++;
        return i;
    }
    if (i + 1 < n && s[i] == '/' && s[i + 1] == '*') {
        int depth = 0;
        while (i < n) {
            if (i + 1 < n && s[i] == '/' && s[i + 1] == '*') {
                depth++;
                i += 2;
            } else if (i + 1 < n && s[i] == '*' && s[i + 1] == '/') {
                i += 2;
                if (--depth == 0)
                    break;
            } else {
                i++;
            }
        }
        return i;
    }
    return i;
}

static size_t skip_string(const char *s, size_t n, size_t i)
{
    for (i++; i < n && s[i] != '"'; i++)
        if (s[i] == '\\' && i + 1 < n)
            i++;
    return i < n ? i + 1 : n;
}

/* The next significant character at or after i: past blanks and comments. */
static size_t skip_blank(const char *s, size_t n, size_t i)
{
    for (;;) {
        while (i < n && isspace((unsigned char)s[i]))
            i++;
        const size_t j = skip_comment(s, n, i);
        if (j == i)
            return i;
        i = j;
    }
}

static bool ident_char(char c) { return isalnum((unsigned char)c) || c == '_'; }

/* A token: identifier or number run, string, or one other character. */
static size_t token_end(const char *s, size_t n, size_t i)
{
    if (s[i] == '"')
        return skip_string(s, n, i);
    if (ident_char(s[i])) {
        while (i < n && ident_char(s[i]))
            i++;
        return i;
    }
    return i + 1;
}

static bool is_word(const char *s, size_t a, size_t b, const char *w)
{
    return strlen(w) == b - a && !memcmp(s + a, w, b - a);
}

/* Past the '}' matching the '{' at i. */
static size_t block_end(const char *s, size_t n, size_t i)
{
    int depth = 0;
    while (i < n) {
        i = skip_blank(s, n, i);
        if (i >= n)
            break;
        if (s[i] == '{')
            depth++;
        else if (s[i] == '}' && --depth == 0)
            return i + 1;
        i = token_end(s, n, i);
    }
    return n;
}

enum item_kind { ITEM_NONE, ITEM_TYPE, ITEM_VECTOR, ITEM_ANGLE, ITEM_TRANSFORM, ITEM_IGNORED };

static enum item_kind item_kind(const char *s, size_t a, size_t b)
{
    static const char *const types[] = {"perspective", "orthographic", "fisheye",
                                        "ultra_wide_angle", "omnimax", "panoramic", "spherical",
                                        "cylinder", "mesh_camera", "user_defined"};
    static const char *const vectors[] = {"location", "look_at", "direction", "up", "right", "sky"};
    static const char *const transforms[] = {"translate", "rotate", "scale", "matrix", "transform"};
    static const char *const ignored[] = {"focal_point", "aperture", "blur_samples", "confidence",
                                          "variance", "normal", "bokeh"};
    for (size_t k = 0; k < sizeof types / sizeof *types; k++)
        if (is_word(s, a, b, types[k]))
            return ITEM_TYPE;
    for (size_t k = 0; k < sizeof vectors / sizeof *vectors; k++)
        if (is_word(s, a, b, vectors[k]))
            return ITEM_VECTOR;
    for (size_t k = 0; k < sizeof transforms / sizeof *transforms; k++)
        if (is_word(s, a, b, transforms[k]))
            return ITEM_TRANSFORM;
    for (size_t k = 0; k < sizeof ignored / sizeof *ignored; k++)
        if (is_word(s, a, b, ignored[k]))
            return ITEM_IGNORED;
    return is_word(s, a, b, "angle") ? ITEM_ANGLE : ITEM_NONE;
}

/* The expression s[a, b) with its comments blanked (a "//" would swallow what follows it on
   the line) and its line ends kept. */
static void put_expression(text *t, const char *s, size_t a, size_t b)
{
    for (size_t i = a; i < b;) {
        const size_t j = s[i] == '"' ? skip_string(s, b, i) : skip_comment(s, b, i);
        if (j == i) {
            put(t, s + i, 1);
            i++;
            continue;
        }
        if (s[i] == '"')
            put(t, s + i, j - i);
        else
            for (size_t k = i; k < j; k++)
                put(t, s[k] == '\n' ? "\n" : " ", 1);
        i = j;
    }
}

static void put_vector(text *t, const char *what)
{
    puts_(t, " vstr(3, ");
    puts_(t, what);
    puts_(t, ", \" \", 0, 17)");
}

/* The #debug lines of one item: keyword s[a, b), expression s[b, e). Every message starts on
   a line of its own and ends with '|': POV-Ray wraps its console at 80 columns. */
static void put_item(text *t, const char *s, size_t a, size_t b, size_t e, enum item_kind kind)
{
    char name[32];
    snprintf(name, sizeof name, "%.*s", (int)(b - a), s + a);
    if (kind == ITEM_VECTOR || kind == ITEM_ANGLE) {
        /* <0,0,0> + (float) is <f,f,f>, as a float in a vector's place is; vstr alone would
           give <f,0,0>. */
        puts_(t, "#debug concat(\"\\nlens2pov-");
        puts_(t, name);
        puts_(t, kind == ITEM_VECTOR ? " \", vstr(3, <0,0,0> + (" : " \", str((");
        put_expression(t, s, b, e);
        puts_(t, kind == ITEM_VECTOR ? "), \" \", 0, 17), \"|\\n\") " : "), 0, 17), \"|\\n\") ");
    } else if (kind == ITEM_TRANSFORM) {
        /* The transform as a function; its images of the origin and the axes give the affine
           map exactly as POV-Ray composes it. */
        puts_(t, "#ifdef (Lens2pov_Transform) #undef Lens2pov_Transform #end "
                 "#declare Lens2pov_Transform = function { transform { ");
        puts_(t, name);
        put_expression(t, s, b, e);
        puts_(t, " } } ");
        /* One vector a message: POV-Ray drops or cuts longer #debug strings. */
        static const char *const points[4][2] = {{"t0", "(0, 0, 0)"}, {"t1", "(1, 0, 0)"},
                                                 {"t2", "(0, 1, 0)"}, {"t3", "(0, 0, 1)"}};
        for (int k = 0; k < 4; k++) {
            puts_(t, "#debug concat(\"\\nlens2pov-");
            puts_(t, points[k][0]);
            puts_(t, " \",");
            char call[64];
            snprintf(call, sizeof call, "Lens2pov_Transform%s", points[k][1]);
            put_vector(t, call);
            puts_(t, ", \"|\\n\") ");
        }
    } else if (kind == ITEM_TYPE) {
        puts_(t, "#debug \"\\nlens2pov-type ");
        puts_(t, name);
        puts_(t, "|\\n\" ");
    }
}

static int count_lines(const char *s, size_t a, size_t b)
{
    int lines = 0;
    for (size_t i = a; i < b; i++)
        lines += s[i] == '\n';
    return lines;
}

/* One camera statement: "camera" at s[kw], its body s[open + 1, close). */
static void put_camera(text *t, const char *s, size_t kw, size_t open, size_t close, int index,
                       int line)
{
    const size_t start = t->n;
    char head[160];
    snprintf(head, sizeof head,
             "#debug concat(\"\\nlens2pov-camera %d %d|\\n\", \"\\nlens2pov-version \", "
             "str(version, 0, 3), \"|\\n\") ", index, line);
    puts_(t, head);
    size_t i = skip_blank(s, close, open + 1);
    bool perspective = true;
    if (i < close && ident_char(s[i]) && !isdigit((unsigned char)s[i])) {
        const size_t e = token_end(s, close, i);
        if (item_kind(s, i, e) == ITEM_NONE) {   /* camera { Declared_Camera ... } */
            puts_(t, "#debug \"\\nlens2pov-declared|\\n\" ");
            i = close;
        }
    }
    while (i < close) {
        const size_t a = i, b = token_end(s, close, i);
        const enum item_kind kind = item_kind(s, a, b);
        if (s[a] == '#') {
            puts_(t, "#debug \"\\nlens2pov-directive|\\n\" ");
            break;
        }
        /* The item runs to the next keyword at this brace level. */
        size_t e = b;
        int depth = 0;
        for (;;) {
            e = skip_blank(s, close, e);
            if (e >= close)
                break;
            if (s[e] == '{')
                depth++;
            if (s[e] == '}')
                depth--;
            const size_t f = token_end(s, close, e);
            if (depth == 0 && (s[e] == '#' || item_kind(s, e, f) != ITEM_NONE))
                break;
            e = f;
        }
        if (kind == ITEM_NONE) {
            puts_(t, "#debug \"\\nlens2pov-unknown|\\n\" ");
            break;
        }
        if (kind == ITEM_TYPE)
            perspective = is_word(s, a, b, "perspective");
        if (perspective || kind == ITEM_TYPE)
            put_item(t, s, a, b, e, kind);
        i = e;
    }
    puts_(t, "#debug \"\\nlens2pov-end|\\n\"");
    /* The statement's lines, less those the expressions kept. */
    int missing = count_lines(s, kw, close + 1) - count_lines(t->s ? t->s : "", start, t->n);
    for (; missing > 0; missing--)
        puts_(t, "\n");
}

char *scene_camera_rewrite(const char *s, size_t n)
{
    text t = {0};
    size_t copied = 0, i = 0;
    int line = 1, index = 0;
    size_t prev_a = 0, prev_b = 0;      /* the last token, for "= camera" and "default {" */
    size_t prev2_a = 0, prev2_b = 0;
    while (i < n) {
        const size_t j = skip_blank(s, n, i);
        line += count_lines(s, i, j);
        if ((i = j) >= n)
            break;
        const size_t e = token_end(s, n, i);
        const bool declared = prev_b > prev_a && s[prev_a] == '=';
        const bool in_default = prev_b > prev_a && s[prev_a] == '{' &&
                                is_word(s, prev2_a, prev2_b, "default");
        if (is_word(s, i, e, "camera") && !declared && !in_default) {
            const size_t open = skip_blank(s, n, e);
            if (open < n && s[open] == '{') {
                const size_t close = block_end(s, n, open);
                put(&t, s + copied, i - copied);
                put_camera(&t, s, i, open, close > open ? close - 1 : open, index++, line);
                line += count_lines(s, i, close);
                copied = i = close;
                prev_a = prev_b = 0;
                continue;
            }
        }
        line += count_lines(s, i, e);
        prev2_a = prev_a, prev2_b = prev_b;
        prev_a = i, prev_b = e;
        i = e;
    }
    put(&t, s + copied, n - copied);
    if (!t.s && !t.failed)
        puts_(&t, "");
    if (t.failed) {
        free(t.s);
        return NULL;
    }
    return t.s;
}

void scene_text_includes(const char *s, size_t n, scene_include_visit visit, void *ctx)
{
    size_t i = 0, prev_a = 0, prev_b = 0, prev2_a = 0, prev2_b = 0;
    int line = 1;
    while (i < n) {
        const size_t j = skip_blank(s, n, i);
        line += count_lines(s, i, j);
        if ((i = j) >= n)
            break;
        const size_t e = token_end(s, n, i);
        /* '#' 'include' "NAME": the name without its quotes (no escapes in a file name). */
        if (s[i] == '"' && e - i >= 2 && s[e - 1] == '"' && is_word(s, prev_a, prev_b, "include") &&
            prev2_b == prev2_a + 1 && s[prev2_a] == '#' &&
            !visit(s + i + 1, e - i - 2, line, ctx))
            return;
        line += count_lines(s, i, e);
        prev2_a = prev_a, prev2_b = prev_b;
        prev_a = i, prev_b = e;
        i = e;
    }
}

bool scene_text_has_camera(const char *s, size_t n, int *line)
{
    char *copy = scene_camera_rewrite(s, n);
    if (!copy)
        return false;
    const size_t m = strlen(copy);
    size_t k = 0;
    while (k < n && k < m && copy[k] == s[k])
        k++;
    const bool changed = k < n || m != n;
    *line = changed ? count_lines(s, 0, k) + 1 : 0;
    free(copy);
    return changed;
}
