/* The scene's text as the camera probe reads it (scenecam_text.c, scenecam_literal.c): only
   its keyword structure, every expression left to POV-Ray. */
#ifndef LENS2POV_SCENECAM_LEX_H
#define LENS2POV_SCENECAM_LEX_H

#include <stdbool.h>
#include <stddef.h>

/* A growing NUL-terminated text; failed once memory ran out (later puts do nothing). */
typedef struct lex_buf {
    char *s;
    size_t n, cap;
    bool failed;
} lex_buf;

void lex_put(lex_buf *t, const char *s, size_t n);
void lex_puts(lex_buf *t, const char *s);

/* Positions in s[0, n): past a comment at i (else i), past a string at i, the next character
   that is neither blank nor comment, the end of the token at i (an identifier or number run,
   a string, or one other character), past the '}' matching the '{' at i. */
size_t lex_skip_comment(const char *s, size_t n, size_t i);
size_t lex_skip_string(const char *s, size_t n, size_t i);
size_t lex_skip_blank(const char *s, size_t n, size_t i);
size_t lex_token_end(const char *s, size_t n, size_t i);
size_t lex_block_end(const char *s, size_t n, size_t i);
bool lex_ident_char(char c);
bool lex_is_word(const char *s, size_t a, size_t b, const char *w);
int lex_count_lines(const char *s, size_t a, size_t b);

/* A camera statement's items by their keywords. */
enum lex_item { ITEM_NONE, ITEM_TYPE, ITEM_VECTOR, ITEM_ANGLE, ITEM_TRANSFORM, ITEM_IGNORED };
enum lex_item lex_item_kind(const char *s, size_t a, size_t b);
/* Where the item whose keyword ends at b ends: at the next keyword or directive at its brace
   level, or at close. */
size_t lex_item_end(const char *s, size_t close, size_t b);

/* The scene's tokens in order, outside comments: the current one s[a, b) and its line, and
   the two before it (for "= camera", "default { camera" and "#include"). */
typedef struct lex_walk {
    const char *s;
    size_t n, a, b;
    int line;
    size_t prev_a, prev_b, prev2_a, prev2_b;
} lex_walk;

lex_walk lex_walk_start(const char *s, size_t n);
/* Moves to the next token; false at the end. */
bool lex_walk_next(lex_walk *w);
/* Whether the token is a camera statement's keyword (not a declared camera's, "= camera",
   nor one in "default { }"): *open gets its '{', *close what follows its '}'. */
bool lex_walk_camera(const lex_walk *w, size_t *open, size_t *close);
/* Past a camera statement that ends before close, which counts as no token. */
void lex_walk_past(lex_walk *w, size_t close);
/* Whether the token is the word of a directive ("# WORD"). */
bool lex_walk_directive(const lex_walk *w);

#endif
