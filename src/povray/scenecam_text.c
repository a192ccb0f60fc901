/* The scene copy for the camera probe: every camera statement becomes #debug lines that make
   POV-Ray print its items, evaluated where the statement stands. Only the statement's keyword
   structure is read here (scenecam_lex.c); every expression is handed to POV-Ray as written. */
#include "povray/scenecam.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "povray/scenecam_lex.h"

/* The expression s[a, b) with its comments blanked (a "//" would swallow what follows it on
   the line) and its line ends kept. */
static void put_expression(lex_buf *t, const char *s, size_t a, size_t b)
{
    for (size_t i = a; i < b;) {
        const size_t j = s[i] == '"' ? lex_skip_string(s, b, i) : lex_skip_comment(s, b, i);
        if (j == i) {
            lex_put(t, s + i, 1);
            i++;
            continue;
        }
        if (s[i] == '"')
            lex_put(t, s + i, j - i);
        else
            for (size_t k = i; k < j; k++)
                lex_put(t, s[k] == '\n' ? "\n" : " ", 1);
        i = j;
    }
}

static void put_vector(lex_buf *t, const char *what)
{
    lex_puts(t, " vstr(3, ");
    lex_puts(t, what);
    lex_puts(t, ", \" \", 0, 17)");
}

/* The #debug lines of one item: keyword s[a, b), expression s[b, e). Every message starts on
   a line of its own and ends with '|': POV-Ray wraps its console at 80 columns. */
static void put_item(lex_buf *t, const char *s, size_t a, size_t b, size_t e, enum lex_item kind)
{
    char name[32];
    snprintf(name, sizeof name, "%.*s", (int)(b - a), s + a);
    if (kind == ITEM_VECTOR || kind == ITEM_ANGLE) {
        /* <0,0,0> + (float) is <f,f,f>, as a float in a vector's place is; vstr alone would
           give <f,0,0>. */
        lex_puts(t, "#debug concat(\"\\nlens2pov-");
        lex_puts(t, name);
        lex_puts(t, kind == ITEM_VECTOR ? " \", vstr(3, <0,0,0> + (" : " \", str((");
        put_expression(t, s, b, e);
        lex_puts(t, kind == ITEM_VECTOR ? "), \" \", 0, 17), \"|\\n\") " : "), 0, 17), \"|\\n\") ");
    } else if (kind == ITEM_TRANSFORM) {
        /* The transform as a function; its images of the origin and the axes give the affine
           map exactly as POV-Ray composes it. */
        lex_puts(t, "#ifdef (Lens2pov_Transform) #undef Lens2pov_Transform #end "
                 "#declare Lens2pov_Transform = function { transform { ");
        lex_puts(t, name);
        put_expression(t, s, b, e);
        lex_puts(t, " } } ");
        /* One vector a message: POV-Ray drops or cuts longer #debug strings. */
        static const char *const points[4][2] = {{"t0", "(0, 0, 0)"}, {"t1", "(1, 0, 0)"},
                                                 {"t2", "(0, 1, 0)"}, {"t3", "(0, 0, 1)"}};
        for (int k = 0; k < 4; k++) {
            lex_puts(t, "#debug concat(\"\\nlens2pov-");
            lex_puts(t, points[k][0]);
            lex_puts(t, " \",");
            char call[64];
            snprintf(call, sizeof call, "Lens2pov_Transform%s", points[k][1]);
            put_vector(t, call);
            lex_puts(t, ", \"|\\n\") ");
        }
    } else if (kind == ITEM_TYPE) {
        lex_puts(t, "#debug \"\\nlens2pov-type ");
        lex_puts(t, name);
        lex_puts(t, "|\\n\" ");
    } else if (lex_is_word(s, a, b, "normal")) {   /* left out, with a warning */
        lex_puts(t, "#debug \"\\nlens2pov-normal|\\n\" ");
    }
}

/* Past the ')' matching the '(' at i, or i when there is none there. */
static size_t paren_end(const char *s, size_t close, size_t i)
{
    int depth = 0;
    for (size_t j = i; j < close; j = lex_token_end(s, close, j)) {
        j = lex_skip_blank(s, close, j);
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
   items it holds run as the items would, a #debug or #warning of a string, or a '#' alone at
   the block's end. a for any other directive. */
static size_t directive_end(const char *s, size_t close, size_t a)
{
    static const char *const plain[] = {"else", "end", "break"};
    /* Not #while: without #declare, which may not stand here, it would never end. */
    static const char *const with_test[] = {"if", "ifdef", "ifndef", "elseif", "switch", "case",
                                            "range"};
    const size_t w = lex_skip_blank(s, close, a + 1), we = w < close ? lex_token_end(s, close, w) : w;
    const size_t p = lex_skip_blank(s, close, we);
    if (w >= close)
        return a + 1;   /* a '#' alone before the block's '}': POV-Ray passes over it */
    for (size_t k = 0; k < sizeof plain / sizeof *plain; k++)
        if (lex_is_word(s, w, we, plain[k]))
            return we;
    for (size_t k = 0; k < sizeof with_test / sizeof *with_test; k++)
        if (lex_is_word(s, w, we, with_test[k])) {
            const size_t q = paren_end(s, close, p);
            return q > p ? q : a;
        }
    if ((lex_is_word(s, w, we, "debug") || lex_is_word(s, w, we, "warning")) && p < close && s[p] == '"')
        return lex_token_end(s, close, p);
    return a;
}

/* Whether the token s[a, b) can end an item: a type, or the last token of an expression (not
   an item's keyword, an operator or an opening bracket). */
static bool ends_item(const char *s, size_t a, size_t b)
{
    const enum lex_item kind = lex_item_kind(s, a, b);
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
    for (size_t i = lex_skip_blank(s, close, open + 1); i < close;) {
        if (s[i] != '#') {
            const size_t e = lex_token_end(s, close, i);
            parens += (s[i] == '(') - (s[i] == ')');
            angles += parens == 0 ? (s[i] == '<') - (s[i] == '>') : 0;
            prev_a = i, prev_b = e;
            i = lex_skip_blank(s, close, e);
            continue;
        }
        const size_t e = directive_end(s, close, i), next = lex_skip_blank(s, close, e);
        if (e == i || parens || angles || (prev_b > prev_a && !ends_item(s, prev_a, prev_b)))
            return false;
        if (next < close && s[next] != '#' &&
            lex_item_kind(s, next, lex_token_end(s, close, next)) == ITEM_NONE)
            return false;
        i = next;
    }
    return true;
}

/* Newlines after what t holds from mark on, so that it has as many as s[a, b): POV-Ray's
   messages then give the lines of the scene. */
static void keep_lines(lex_buf *t, size_t mark, const char *s, size_t a, size_t b)
{
    for (int k = lex_count_lines(s, a, b) - lex_count_lines(t->s ? t->s : "", mark, t->n); k > 0; k--)
        lex_puts(t, "\n");
}

/* The nesting a conditional directive at s[a] opens (1), closes (-1) or leaves (0). */
static int nesting(const char *s, size_t close, size_t a)
{
    const size_t w = lex_skip_blank(s, close, a + 1), we = w < close ? lex_token_end(s, close, w) : w;
    if (lex_is_word(s, w, we, "if") || lex_is_word(s, w, we, "ifdef") || lex_is_word(s, w, we, "ifndef") ||
        lex_is_word(s, w, we, "switch"))
        return 1;
    return lex_is_word(s, w, we, "end") ? -1 : 0;
}

/* One camera statement: "camera" at s[kw], its body s[open + 1, close), of file number file
   (0: the scene; an included file's number follows the line). */
static void put_camera(lex_buf *t, const char *s, size_t kw, size_t open, size_t close, int index,
                       int line, int file)
{
    const size_t start = t->n;
    char head[160], file_number[16] = "";
    if (file > 0)
        snprintf(file_number, sizeof file_number, " %d", file);
    snprintf(head, sizeof head,
             "#debug concat(\"\\nlens2pov-camera %d %d%s|\\n\", \"\\nlens2pov-version \", "
             "str(version, 0, 3), \"|\\n\") ", index, line, file_number);
    lex_puts(t, head);
    size_t i = lex_skip_blank(s, close, open + 1);
    keep_lines(t, start, s, kw, i);
    bool perspective = true;
    if (!directives_pass(s, open, close)) {
        lex_puts(t, "#debug \"\\nlens2pov-directive|\\n\" ");
        i = close;
    }
    if (i < close && lex_ident_char(s[i]) && !isdigit((unsigned char)s[i])) {
        const size_t e = lex_token_end(s, close, i);
        if (lex_item_kind(s, i, e) == ITEM_NONE) {   /* camera { Declared_Camera ... } */
            lex_puts(t, "#debug \"\\nlens2pov-declared|\\n\" ");
            i = close;
        }
    }
    bool items = true;   /* false past an unknown word, to the branch's end */
    int depth = 0;       /* of the conditionals around */
    while (i < close) {
        const size_t a = i, b = lex_token_end(s, close, i), mark = t->n;
        const enum lex_item kind = lex_item_kind(s, a, b);
        if (s[a] == '#') {   /* between items: directives_pass has passed it */
            const size_t e = directive_end(s, close, a);
            i = lex_skip_blank(s, close, e);
            if (e > a + 1)   /* not a lone '#' */
                put_expression(t, s, a, i);
            lex_puts(t, " ");
            depth += nesting(s, close, a);
            items = true;
            continue;
        }
        const size_t e = lex_item_end(s, close, b);
        if (!items || kind == ITEM_NONE) {
            if (items)
                lex_puts(t, "#debug \"\\nlens2pov-unknown|\\n\" ");
            items = false;
            i = lex_skip_blank(s, close, b);
        } else if (kind == ITEM_TYPE && depth > 0) {
            lex_puts(t, "#debug \"\\nlens2pov-branch_type|\\n\" ");
            items = false;
            i = e;
        } else {
            if (kind == ITEM_TYPE)
                perspective = lex_is_word(s, a, b, "perspective");
            if (perspective || kind == ITEM_TYPE)
                put_item(t, s, a, b, e, kind);
            i = e;
        }
        keep_lines(t, mark, s, a, i);
    }
    lex_puts(t, "#debug \"\\nlens2pov-end|\\n\"");
    keep_lines(t, start, s, kw, close + 1);   /* the statement's lines, to its '}' */
}

char *scene_camera_rewrite(const char *s, size_t n) { return scene_camera_rewrite_file(s, n, 0); }

char *scene_camera_rewrite_file(const char *s, size_t n, int file)
{
    lex_buf t = {0};
    size_t copied = 0, open, close;
    int index = 0;
    for (lex_walk w = lex_walk_start(s, n); lex_walk_next(&w);)
        if (lex_walk_camera(&w, &open, &close)) {
            lex_put(&t, s + copied, w.a - copied);
            copied = w.a;
            if (s[close - 1] != '}') {
                /* Unclosed: kept as it is, after a mark that makes the copy differ from the
                   scene, so that POV-Ray is run and says where the scene is wrong. */
                lex_puts(&t, "#debug \"\" ");
                break;
            }
            put_camera(&t, s, w.a, open, close - 1, index++, w.line, file);
            lex_walk_past(&w, copied = close);
        }
    lex_put(&t, s + copied, n - copied);
    if (!t.s && !t.failed)
        lex_puts(&t, "");
    if (t.failed) {
        free(t.s);
        return NULL;
    }
    return t.s;
}

void scene_text_includes(const char *s, size_t n, scene_include_visit visit, void *ctx)
{
    /* '#' 'include' "NAME": the name without its quotes (no escapes in a file name). */
    for (lex_walk w = lex_walk_start(s, n); lex_walk_next(&w);)
        if (s[w.a] == '"' && w.b - w.a >= 2 && s[w.b - 1] == '"' &&
            lex_is_word(s, w.prev_a, w.prev_b, "include") && w.prev2_b == w.prev2_a + 1 &&
            s[w.prev2_a] == '#' && !visit(s + w.a + 1, w.b - w.a - 2, w.line, ctx))
            return;
}

int scene_text_computed_include(const char *s, size_t n)
{
    for (lex_walk w = lex_walk_start(s, n); lex_walk_next(&w);)
        if (s[w.a] != '"' && lex_is_word(s, w.prev_a, w.prev_b, "include") &&
            w.prev2_b == w.prev2_a + 1 && s[w.prev2_a] == '#')
            return w.line;
    return 0;
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
    *line = changed ? lex_count_lines(s, 0, k) + 1 : 0;
    free(copy);
    return changed;
}
