/* The scene copy for the camera probe: every camera statement becomes #debug lines that make
   POV-Ray print its items, evaluated where the statement stands. Only the statement's keyword
   structure is read here; every expression is handed to POV-Ray as written. */
#include "povray/scenecam.h"

#include <ctype.h>
#include <math.h>
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

/* Where the item whose keyword ends at b ends: at the next keyword or directive at its brace
   level, or at close. */
static size_t item_end(const char *s, size_t close, size_t b)
{
    size_t e = b;
    int depth = 0;
    for (;;) {
        e = skip_blank(s, close, e);
        if (e >= close)
            return e;
        if (s[e] == '{')
            depth++;
        if (s[e] == '}')
            depth--;
        const size_t f = token_end(s, close, e);
        if (depth == 0 && (s[e] == '#' || item_kind(s, e, f) != ITEM_NONE))
            return e;
        e = f;
    }
}

static int count_lines(const char *s, size_t a, size_t b)
{
    int lines = 0;
    for (size_t i = a; i < b; i++)
        lines += s[i] == '\n';
    return lines;
}

/* Past the ')' matching the '(' at i, or i when there is none there. */
static size_t paren_end(const char *s, size_t close, size_t i)
{
    int depth = 0;
    for (size_t j = i; j < close; j = token_end(s, close, j)) {
        j = skip_blank(s, close, j);
        if (j >= close || (j == i && s[j] != '('))
            break;
        depth += (s[j] == '(') - (s[j] == ')');
        if (depth == 0)
            return j + 1;
    }
    return i;
}

/* Where a directive that may stand inside a camera block ends, '#' at s[a]: a conditional
   (#if (...), #else, #end, #switch, ...), copied as written, so that the #debug lines of the
   items it holds run as the items would, or a #debug or #warning of a string. a for any other
   directive. */
static size_t directive_end(const char *s, size_t close, size_t a)
{
    static const char *const plain[] = {"else", "end", "break"};
    /* Not #while: without #declare, which may not stand here, it would never end. */
    static const char *const with_test[] = {"if", "ifdef", "ifndef", "elseif", "switch", "case",
                                            "range"};
    const size_t w = skip_blank(s, close, a + 1), we = w < close ? token_end(s, close, w) : w;
    const size_t p = skip_blank(s, close, we);
    for (size_t k = 0; k < sizeof plain / sizeof *plain; k++)
        if (is_word(s, w, we, plain[k]))
            return we;
    for (size_t k = 0; k < sizeof with_test / sizeof *with_test; k++)
        if (is_word(s, w, we, with_test[k])) {
            const size_t q = paren_end(s, close, p);
            return q > p ? q : a;
        }
    if ((is_word(s, w, we, "debug") || is_word(s, w, we, "warning")) && p < close && s[p] == '"')
        return token_end(s, close, p);
    return a;
}

/* Whether the token s[a, b) can end an item: a type, or the last token of an expression (not
   an item's keyword, an operator or an opening bracket). */
static bool ends_item(const char *s, size_t a, size_t b)
{
    const enum item_kind kind = item_kind(s, a, b);
    return kind == ITEM_TYPE || (kind == ITEM_NONE && !strchr("+-*/,(<=&|?:!", s[a]));
}

/* Whether every directive in the camera block s(open, close) is one directive_end passes and
   stands between items: outside brackets and vectors, after a token that can end an item, and
   followed by an item's keyword, another directive or the block's end. A directive inside an
   item's expression would cut it, and a branch that starts with another word would leave its
   items unread. */
static bool directives_pass(const char *s, size_t open, size_t close)
{
    int parens = 0, angles = 0;
    size_t prev_a = 0, prev_b = 0;   /* the last token that is not a directive */
    for (size_t i = skip_blank(s, close, open + 1); i < close;) {
        if (s[i] != '#') {
            const size_t e = token_end(s, close, i);
            parens += (s[i] == '(') - (s[i] == ')');
            angles += parens == 0 ? (s[i] == '<') - (s[i] == '>') : 0;
            prev_a = i, prev_b = e;
            i = skip_blank(s, close, e);
            continue;
        }
        const size_t e = directive_end(s, close, i), next = skip_blank(s, close, e);
        if (e == i || parens || angles || (prev_b > prev_a && !ends_item(s, prev_a, prev_b)))
            return false;
        if (next < close && s[next] != '#' &&
            item_kind(s, next, token_end(s, close, next)) == ITEM_NONE)
            return false;
        i = next;
    }
    return true;
}

/* Newlines after what t holds from mark on, so that it has as many as s[a, b): POV-Ray's
   messages then give the lines of the scene. */
static void keep_lines(text *t, size_t mark, const char *s, size_t a, size_t b)
{
    for (int k = count_lines(s, a, b) - count_lines(t->s ? t->s : "", mark, t->n); k > 0; k--)
        puts_(t, "\n");
}

/* The nesting a conditional directive at s[a] opens (1), closes (-1) or leaves (0). */
static int nesting(const char *s, size_t close, size_t a)
{
    const size_t w = skip_blank(s, close, a + 1), we = w < close ? token_end(s, close, w) : w;
    if (is_word(s, w, we, "if") || is_word(s, w, we, "ifdef") || is_word(s, w, we, "ifndef") ||
        is_word(s, w, we, "switch"))
        return 1;
    return is_word(s, w, we, "end") ? -1 : 0;
}

/* One camera statement: "camera" at s[kw], its body s[open + 1, close), of file number file
   (0: the scene; an included file's number follows the line). */
static void put_camera(text *t, const char *s, size_t kw, size_t open, size_t close, int index,
                       int line, int file)
{
    const size_t start = t->n;
    char head[160], file_number[16] = "";
    if (file > 0)
        snprintf(file_number, sizeof file_number, " %d", file);
    snprintf(head, sizeof head,
             "#debug concat(\"\\nlens2pov-camera %d %d%s|\\n\", \"\\nlens2pov-version \", "
             "str(version, 0, 3), \"|\\n\") ", index, line, file_number);
    puts_(t, head);
    size_t i = skip_blank(s, close, open + 1);
    keep_lines(t, start, s, kw, i);
    bool perspective = true;
    if (!directives_pass(s, open, close)) {
        puts_(t, "#debug \"\\nlens2pov-directive|\\n\" ");
        i = close;
    }
    if (i < close && ident_char(s[i]) && !isdigit((unsigned char)s[i])) {
        const size_t e = token_end(s, close, i);
        if (item_kind(s, i, e) == ITEM_NONE) {   /* camera { Declared_Camera ... } */
            puts_(t, "#debug \"\\nlens2pov-declared|\\n\" ");
            i = close;
        }
    }
    bool items = true;   /* false past an unknown word, to the branch's end */
    int depth = 0;       /* of the conditionals around */
    while (i < close) {
        const size_t a = i, b = token_end(s, close, i), mark = t->n;
        const enum item_kind kind = item_kind(s, a, b);
        if (s[a] == '#') {   /* between items: directives_pass has passed it */
            i = skip_blank(s, close, directive_end(s, close, a));
            put_expression(t, s, a, i);
            puts_(t, " ");
            depth += nesting(s, close, a);
            items = true;
            continue;
        }
        const size_t e = item_end(s, close, b);
        if (!items || kind == ITEM_NONE) {
            if (items)
                puts_(t, "#debug \"\\nlens2pov-unknown|\\n\" ");
            items = false;
            i = skip_blank(s, close, b);
        } else if (kind == ITEM_TYPE && depth > 0) {
            puts_(t, "#debug \"\\nlens2pov-branch_type|\\n\" ");
            items = false;
            i = e;
        } else {
            if (kind == ITEM_TYPE)
                perspective = is_word(s, a, b, "perspective");
            if (perspective || kind == ITEM_TYPE)
                put_item(t, s, a, b, e, kind);
            i = e;
        }
        keep_lines(t, mark, s, a, i);
    }
    puts_(t, "#debug \"\\nlens2pov-end|\\n\"");
    keep_lines(t, start, s, kw, close + 1);   /* the statement's lines, to its '}' */
}

/* ---------------------------------------------------------------- walking the scene */

/* The scene's tokens in order, outside comments: the current one s[a, b) and its line, and
   the two before it (for "= camera", "default { camera" and "#include"). */
typedef struct walk {
    const char *s;
    size_t n, a, b;
    int line;
    size_t prev_a, prev_b, prev2_a, prev2_b;
} walk;

static walk walk_start(const char *s, size_t n) { return (walk){s, n, 0, 0, 1, 0, 0, 0, 0}; }

/* Moves to the next token; false at the end. */
static bool walk_next(walk *w)
{
    if (w->b > w->a) {
        w->line += count_lines(w->s, w->a, w->b);
        w->prev2_a = w->prev_a, w->prev2_b = w->prev_b;
        w->prev_a = w->a, w->prev_b = w->b;
    }
    const size_t j = skip_blank(w->s, w->n, w->b);
    w->line += count_lines(w->s, w->b, j);
    if (j >= w->n)
        return false;
    w->a = j;
    w->b = token_end(w->s, w->n, j);
    return true;
}

/* Whether the token is a camera statement's keyword (not a declared camera's, "= camera",
   nor one in "default { }"): *open gets its '{', *close what follows its '}'. */
static bool walk_camera(const walk *w, size_t *open, size_t *close)
{
    const char *s = w->s;
    const bool declared = w->prev_b > w->prev_a && s[w->prev_a] == '=';
    const bool in_default = w->prev_b > w->prev_a && s[w->prev_a] == '{' &&
                            is_word(s, w->prev2_a, w->prev2_b, "default");
    if (!is_word(s, w->a, w->b, "camera") || declared || in_default)
        return false;
    *open = skip_blank(s, w->n, w->b);
    if (*open >= w->n || s[*open] != '{')
        return false;
    *close = block_end(s, w->n, *open);
    return true;
}

/* Past a camera statement that ends before close, which counts as no token. */
static void walk_past(walk *w, size_t close)
{
    w->line += count_lines(w->s, w->a, close);
    w->a = w->b = close;
    w->prev_a = w->prev_b = 0;
}

/* The directive word of "# WORD", if the token is one. */
static bool walk_directive(const walk *w)
{
    return w->prev_b == w->prev_a + 1 && w->s[w->prev_a] == '#';
}

char *scene_camera_rewrite(const char *s, size_t n) { return scene_camera_rewrite_file(s, n, 0); }

char *scene_camera_rewrite_file(const char *s, size_t n, int file)
{
    text t = {0};
    size_t copied = 0, open, close;
    int index = 0;
    for (walk w = walk_start(s, n); walk_next(&w);)
        if (walk_camera(&w, &open, &close)) {
            put(&t, s + copied, w.a - copied);
            put_camera(&t, s, w.a, open, close > open ? close - 1 : open, index++, w.line, file);
            walk_past(&w, copied = close);
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
    /* '#' 'include' "NAME": the name without its quotes (no escapes in a file name). */
    for (walk w = walk_start(s, n); walk_next(&w);)
        if (s[w.a] == '"' && w.b - w.a >= 2 && s[w.b - 1] == '"' &&
            is_word(s, w.prev_a, w.prev_b, "include") && w.prev2_b == w.prev2_a + 1 &&
            s[w.prev2_a] == '#' && !visit(s + w.a + 1, w.b - w.a - 2, w.line, ctx))
            return;
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

/* ---------------------------------------------------------------- literal cameras */

/* A number as POV-Ray writes one: digits with an optional point and exponent, no sign (a sign
   is an operator), at s[*i] before e; *i moves past it. */
static bool literal_number(const char *s, size_t e, size_t *i, double *v)
{
    size_t k = *i, digits = 0;
    while (k < e && isdigit((unsigned char)s[k]))
        k++, digits++;
    if (k < e && s[k] == '.')
        for (k++; k < e && isdigit((unsigned char)s[k]); k++)
            digits++;
    if (!digits)
        return false;
    if (k < e && (s[k] == 'e' || s[k] == 'E')) {
        size_t x = k + 1;
        if (x < e && (s[x] == '+' || s[x] == '-'))
            x++;
        if (x >= e || !isdigit((unsigned char)s[x]))
            return false;
        while (x < e && isdigit((unsigned char)s[x]))
            x++;
        k = x;
    }
    char buf[64];
    if (k - *i >= sizeof buf)
        return false;
    memcpy(buf, s + *i, k - *i);
    buf[k - *i] = '\0';
    *v = strtod(buf, NULL);
    *i = k;
    return true;
}

/* A signed literal number, blanks allowed around the sign. */
static bool signed_number(const char *s, size_t e, size_t *i, double *v)
{
    size_t k = skip_blank(s, e, *i);
    const bool minus = k < e && s[k] == '-';
    if (k < e && (s[k] == '-' || s[k] == '+'))
        k = skip_blank(s, e, k + 1);
    if (!literal_number(s, e, &k, v))
        return false;
    *v = minus ? -*v : *v;
    *i = k;
    return true;
}

/* The value of an item's expression s[b, e) when it is a literal: a vector <a, b, c>, a
   number (a vector's three components, as POV-Ray promotes it) or a signed x, y or z; an
   angle only a number. */
static bool literal_value(const char *s, size_t b, size_t e, bool vector, double v[3])
{
    size_t i = skip_blank(s, e, b);
    if (vector && i < e && s[i] == '<') {
        for (int k = 0; k < 3; k++) {
            i++;   /* past '<' or ',' */
            if (!signed_number(s, e, &i, &v[k]))
                return false;
            i = skip_blank(s, e, i);
            if (i >= e || s[i] != (k < 2 ? ',' : '>'))
                return false;
        }
        return skip_blank(s, e, i + 1) == e;
    }
    const size_t sign = i;
    if (i < e && (s[i] == '-' || s[i] == '+'))
        i = skip_blank(s, e, i + 1);
    const size_t t = i < e ? token_end(s, e, i) : i;
    if (vector && t == i + 1 && (s[i] == 'x' || s[i] == 'y' || s[i] == 'z')) {
        v[0] = v[1] = v[2] = 0;
        v[s[i] - 'x'] = s[sign] == '-' ? -1 : 1;
        return skip_blank(s, e, t) == e;
    }
    i = sign;
    if (!signed_number(s, e, &i, &v[0]))
        return false;
    v[1] = v[2] = v[0];
    return skip_blank(s, e, i) == e;
}

/* The messages the probe's copy would print for one camera statement (put_camera) whose items
   are all literals of location, look_at, direction, up, right, sky, angle and perspective;
   false for any other. Numbers are printed as POV-Ray's str(v, 0, 17) prints them ("%.17f"),
   so that they are read back as from POV-Ray; beyond 1e9 that takes too many digits. */
static bool literal_camera(text *t, const char *s, size_t open, size_t close, int index,
                           int line, double version)
{
    char msg[256];
    snprintf(msg, sizeof msg, "\nlens2pov-camera %d %d|\n\nlens2pov-version %.3f|\n", index, line,
             version);
    puts_(t, msg);
    for (size_t i = skip_blank(s, close, open + 1); i < close;) {
        const size_t a = i, b = token_end(s, close, i);
        const enum item_kind kind = item_kind(s, a, b);
        if (s[a] == '#' || kind == ITEM_NONE || kind == ITEM_TRANSFORM ||
            (kind == ITEM_TYPE && !is_word(s, a, b, "perspective")))
            return false;
        const size_t e = item_end(s, close, b);
        double v[3];
        if (kind == ITEM_VECTOR || kind == ITEM_ANGLE) {
            if (!literal_value(s, b, e, kind == ITEM_VECTOR, v) ||
                !(fabs(v[0]) < 1e9 && fabs(v[1]) < 1e9 && fabs(v[2]) < 1e9))
                return false;
            if (kind == ITEM_VECTOR)   /* <0,0,0> + (EXPR): a zero's sign is lost */
                snprintf(msg, sizeof msg, "\nlens2pov-%.*s %.17f %.17f %.17f|\n", (int)(b - a),
                         s + a, 0.0 + v[0], 0.0 + v[1], 0.0 + v[2]);
            else
                snprintf(msg, sizeof msg, "\nlens2pov-angle %.17f|\n", v[0]);
            puts_(t, msg);
        } else if (kind == ITEM_TYPE) {
            puts_(t, "\nlens2pov-type perspective|\n");
        }
        i = e;
    }
    puts_(t, "\nlens2pov-end|\n");
    return true;
}

/* Directives that open a block up to its #end. */
static bool opens_block(const char *s, size_t a, size_t b)
{
    static const char *const words[] = {"if", "ifdef", "ifndef", "switch", "while", "for", "macro"};
    for (size_t k = 0; k < sizeof words / sizeof *words; k++)
        if (is_word(s, a, b, words[k]))
            return true;
    return false;
}

/* Follows the directive whose word is the walk's token: the depth of blocks, and a literal
   #version; false for a #version that is no literal or stands in a block. */
static bool follow_directive(const walk *w, int *depth, double *version)
{
    const char *s = w->s;
    if (opens_block(s, w->a, w->b))
        ++*depth;
    else if (is_word(s, w->a, w->b, "end"))
        return --*depth >= 0;
    else if (is_word(s, w->a, w->b, "version")) {
        size_t k = skip_blank(s, w->n, w->b);
        if (*depth || !literal_number(s, w->n, &k, version))
            return false;
        k = skip_blank(s, w->n, k);
        return k < w->n && s[k] == ';';
    }
    return true;
}

char *scene_camera_literal_log(const char *s, size_t n)
{
    text t = {0};
    puts_(&t, "\nlens2pov-frame 0 0 0|\n");
    size_t open, close;
    int index = 0, depth = 0;
    double version = 0;   /* none yet: POV-Ray's then comes from its settings */
    bool ok = true;
    for (walk w = walk_start(s, n); ok && walk_next(&w);) {
        if (walk_directive(&w))
            ok = follow_directive(&w, &depth, &version);
        if (ok && walk_camera(&w, &open, &close)) {
            ok = depth == 0 && version >= 3.5 && version <= 3.7 &&
                 literal_camera(&t, s, open, close > open ? close - 1 : open, index++, w.line,
                                version);
            walk_past(&w, close);
        }
    }
    if (!ok || t.failed || index == 0) {
        free(t.s);
        return NULL;
    }
    return t.s;
}
