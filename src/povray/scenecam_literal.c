/* A camera written as literals, read without POV-Ray: the messages the probe's copy would
   print for it (docs/povray.md, "The scene's camera"). */
#include "povray/scenecam.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "povray/scenecam_lex.h"

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
    size_t k = lex_skip_blank(s, e, *i);
    const bool minus = k < e && s[k] == '-';
    if (k < e && (s[k] == '-' || s[k] == '+'))
        k = lex_skip_blank(s, e, k + 1);
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
    size_t i = lex_skip_blank(s, e, b);
    if (vector && i < e && s[i] == '<') {
        for (int k = 0; k < 3; k++) {
            i++;   /* past '<' or ',' */
            if (!signed_number(s, e, &i, &v[k]))
                return false;
            i = lex_skip_blank(s, e, i);
            if (i >= e || s[i] != (k < 2 ? ',' : '>'))
                return false;
        }
        return lex_skip_blank(s, e, i + 1) == e;
    }
    const size_t sign = i;
    if (i < e && (s[i] == '-' || s[i] == '+'))
        i = lex_skip_blank(s, e, i + 1);
    const size_t t = i < e ? lex_token_end(s, e, i) : i;
    if (vector && t == i + 1 && (s[i] == 'x' || s[i] == 'y' || s[i] == 'z')) {
        v[0] = v[1] = v[2] = 0;
        v[s[i] - 'x'] = s[sign] == '-' ? -1 : 1;
        return lex_skip_blank(s, e, t) == e;
    }
    i = sign;
    if (!signed_number(s, e, &i, &v[0]))
        return false;
    v[1] = v[2] = v[0];
    return lex_skip_blank(s, e, i) == e;
}

/* The messages the probe's copy would print for one camera statement (put_camera) whose items
   are all literals of location, look_at, direction, up, right, sky, angle and perspective;
   false for any other. Numbers are printed as POV-Ray's str(v, 0, 17) prints them ("%.17f"),
   so that they are read back as from POV-Ray; beyond 1e9 that takes too many digits. */
static bool literal_camera(lex_buf *t, const char *s, size_t open, size_t close, int index,
                           int line, double version)
{
    char msg[256];
    snprintf(msg, sizeof msg, "\nlens2pov-camera %d %d|\n\nlens2pov-version %.3f|\n", index, line,
             version);
    lex_puts(t, msg);
    for (size_t i = lex_skip_blank(s, close, open + 1); i < close;) {
        const size_t a = i, b = lex_token_end(s, close, i);
        const enum lex_item kind = lex_item_kind(s, a, b);
        if (s[a] == '#' || kind == ITEM_NONE || kind == ITEM_TRANSFORM ||
            (kind == ITEM_TYPE && !lex_is_word(s, a, b, "perspective")))
            return false;
        const size_t e = lex_item_end(s, close, b);
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
            lex_puts(t, msg);
        } else if (kind == ITEM_TYPE) {
            lex_puts(t, "\nlens2pov-type perspective|\n");
        } else if (lex_is_word(s, a, b, "normal")) {
            lex_puts(t, "\nlens2pov-normal|\n");
        }
        i = e;
    }
    lex_puts(t, "\nlens2pov-end|\n");
    return true;
}

/* Directives that open a block up to its #end. */
static bool opens_block(const char *s, size_t a, size_t b)
{
    static const char *const words[] = {"if", "ifdef", "ifndef", "switch", "while", "for", "macro"};
    for (size_t k = 0; k < sizeof words / sizeof *words; k++)
        if (lex_is_word(s, a, b, words[k]))
            return true;
    return false;
}

/* Follows the directive whose word is the walk's token: the depth of blocks, and a literal
   #version; false for a #version that is no literal or stands in a block. */
static bool follow_directive(const lex_walk *w, int *depth, double *version)
{
    const char *s = w->s;
    if (opens_block(s, w->a, w->b))
        ++*depth;
    else if (lex_is_word(s, w->a, w->b, "end"))
        return --*depth >= 0;
    else if (lex_is_word(s, w->a, w->b, "version")) {
        size_t k = lex_skip_blank(s, w->n, w->b);
        if (*depth || !literal_number(s, w->n, &k, version))
            return false;
        k = lex_skip_blank(s, w->n, k);
        return k < w->n && s[k] == ';';
    }
    return true;
}

char *scene_camera_literal_log(const char *s, size_t n)
{
    lex_buf t = {0};
    lex_puts(&t, "\nlens2pov-frame 0 0 0|\n");
    size_t open, close;
    int index = 0, depth = 0;
    double version = 0;   /* none yet: POV-Ray's then comes from its settings */
    bool ok = true;
    for (lex_walk w = lex_walk_start(s, n); ok && lex_walk_next(&w);) {
        if (lex_walk_directive(&w))
            ok = follow_directive(&w, &depth, &version);
        if (ok && lex_walk_camera(&w, &open, &close)) {
            /* An unclosed camera is left to the probe, whose POV-Ray says where. */
            ok = depth == 0 && version >= 3.5 && version <= 3.7 && s[close - 1] == '}' &&
                 literal_camera(&t, s, open, close - 1, index++, w.line, version);
            lex_walk_past(&w, close);
        }
    }
    if (!ok || t.failed || index == 0) {
        free(t.s);
        return NULL;
    }
    return t.s;
}
