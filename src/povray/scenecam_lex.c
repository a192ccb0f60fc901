/* The scene's text as the camera probe reads it: tokens outside comments and strings, a camera
   statement's items by their keywords, the scene's statements in order, and a growing text
   for what the probe writes (scenecam_lex.h). */
#include "povray/scenecam_lex.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

void lex_put(lex_buf *t, const char *s, size_t n)
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

void lex_puts(lex_buf *t, const char *s) { lex_put(t, s, strlen(s)); }

/* Past the comment starting at i (a line comment, or a block comment, which nests in
   POV-Ray), else i. */
size_t lex_skip_comment(const char *s, size_t n, size_t i)
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

size_t lex_skip_string(const char *s, size_t n, size_t i)
{
    for (i++; i < n && s[i] != '"'; i++)
        if (s[i] == '\\' && i + 1 < n)
            i++;
    return i < n ? i + 1 : n;
}

/* The next significant character at or after i: past blanks and comments. */
size_t lex_skip_blank(const char *s, size_t n, size_t i)
{
    for (;;) {
        while (i < n && isspace((unsigned char)s[i]))
            i++;
        const size_t j = lex_skip_comment(s, n, i);
        if (j == i)
            return i;
        i = j;
    }
}

bool lex_ident_char(char c) { return isalnum((unsigned char)c) || c == '_'; }

size_t lex_token_end(const char *s, size_t n, size_t i)
{
    if (s[i] == '"')
        return lex_skip_string(s, n, i);
    if (lex_ident_char(s[i])) {
        while (i < n && lex_ident_char(s[i]))
            i++;
        return i;
    }
    return i + 1;
}

bool lex_is_word(const char *s, size_t a, size_t b, const char *w)
{
    return strlen(w) == b - a && !memcmp(s + a, w, b - a);
}

size_t lex_block_end(const char *s, size_t n, size_t i)
{
    int depth = 0;
    while (i < n) {
        i = lex_skip_blank(s, n, i);
        if (i >= n)
            break;
        if (s[i] == '{')
            depth++;
        else if (s[i] == '}' && --depth == 0)
            return i + 1;
        i = lex_token_end(s, n, i);
    }
    return n;
}

enum lex_item lex_item_kind(const char *s, size_t a, size_t b)
{
    static const struct {
        const char *word;
        enum lex_item kind;
    } items[] = {
        {"perspective", ITEM_TYPE}, {"orthographic", ITEM_TYPE}, {"fisheye", ITEM_TYPE},
        {"ultra_wide_angle", ITEM_TYPE}, {"omnimax", ITEM_TYPE}, {"panoramic", ITEM_TYPE},
        {"spherical", ITEM_TYPE}, {"cylinder", ITEM_TYPE}, {"mesh_camera", ITEM_TYPE},
        {"user_defined", ITEM_TYPE},
        {"location", ITEM_VECTOR}, {"look_at", ITEM_VECTOR}, {"direction", ITEM_VECTOR},
        {"up", ITEM_VECTOR}, {"right", ITEM_VECTOR}, {"sky", ITEM_VECTOR},
        {"focal_point", ITEM_VECTOR},
        {"translate", ITEM_TRANSFORM}, {"rotate", ITEM_TRANSFORM}, {"scale", ITEM_TRANSFORM},
        {"matrix", ITEM_TRANSFORM}, {"transform", ITEM_TRANSFORM},
        {"aperture", ITEM_IGNORED}, {"blur_samples", ITEM_IGNORED}, {"confidence", ITEM_IGNORED},
        {"variance", ITEM_IGNORED}, {"normal", ITEM_IGNORED}, {"bokeh", ITEM_IGNORED},
        {"angle", ITEM_ANGLE},
    };
    for (size_t k = 0; k < sizeof items / sizeof *items; k++)
        if (lex_is_word(s, a, b, items[k].word))
            return items[k].kind;
    return ITEM_NONE;
}

size_t lex_item_end(const char *s, size_t close, size_t b)
{
    size_t e = b;
    int depth = 0;
    for (;;) {
        e = lex_skip_blank(s, close, e);
        if (e >= close)
            return e;
        if (s[e] == '{')
            depth++;
        if (s[e] == '}')
            depth--;
        const size_t f = lex_token_end(s, close, e);
        if (depth == 0 && (s[e] == '#' || lex_item_kind(s, e, f) != ITEM_NONE))
            return e;
        e = f;
    }
}

int lex_count_lines(const char *s, size_t a, size_t b)
{
    int lines = 0;
    for (size_t i = a; i < b; i++)
        lines += s[i] == '\n';
    return lines;
}

lex_walk lex_walk_start(const char *s, size_t n) { return (lex_walk){s, n, 0, 0, 1, 0, 0, 0, 0}; }

bool lex_walk_next(lex_walk *w)
{
    if (w->b > w->a) {
        w->line += lex_count_lines(w->s, w->a, w->b);
        w->prev2_a = w->prev_a, w->prev2_b = w->prev_b;
        w->prev_a = w->a, w->prev_b = w->b;
    }
    const size_t j = lex_skip_blank(w->s, w->n, w->b);
    w->line += lex_count_lines(w->s, w->b, j);
    if (j >= w->n)
        return false;
    w->a = j;
    w->b = lex_token_end(w->s, w->n, j);
    return true;
}

bool lex_walk_camera(const lex_walk *w, size_t *open, size_t *close)
{
    const char *s = w->s;
    const bool declared = w->prev_b > w->prev_a && s[w->prev_a] == '=';
    const bool in_default = w->prev_b > w->prev_a && s[w->prev_a] == '{' &&
                            lex_is_word(s, w->prev2_a, w->prev2_b, "default");
    if (!lex_is_word(s, w->a, w->b, "camera") || declared || in_default)
        return false;
    *open = lex_skip_blank(s, w->n, w->b);
    if (*open >= w->n || s[*open] != '{')
        return false;
    *close = lex_block_end(s, w->n, *open);
    return true;
}

void lex_walk_past(lex_walk *w, size_t close)
{
    w->line += lex_count_lines(w->s, w->a, close);
    w->a = w->b = close;
    w->prev_a = w->prev_b = 0;
}

bool lex_walk_directive(const lex_walk *w)
{
    return w->prev_b == w->prev_a + 1 && w->s[w->prev_a] == '#';
}
