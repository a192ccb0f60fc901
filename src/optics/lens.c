/* Reading and validating a lens prescription (pbrt's format, see lens.h); lens_shape.c holds
   what is asked of a lens once read.

   Users bring their own files, so the reader is strict: every row is four decimal numbers, or
   five with the Abbe number of the glass behind the surface, and every glass row of a file gives
   one or none does; everything else is an error that names the file and the line. */
#include "optics/lens.h"

#include <errno.h>
#include <fcntl.h>
#include <locale.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Longer than any decimal a lens file needs (17 significant digits, sign, point, exponent),
   short enough for a buffer on the stack. */
enum { NUMBER_MAX_CHARS = 63 };

/* How many characters of an offending token a message quotes. */
enum { QUOTE_MAX_CHARS = 32 };

/* One row as read: the numbers, and their text as written, which messages quote so that the
   user sees the number they typed rather than a reformatting of it. */
typedef struct row {
    double value[5];
    const char *text[5];
    int text_length[5];
    int count;               /* 4, or 5 with an Abbe number */
} row;

/* Where the parser is, for messages; and the first glass row, which says whether the file
   gives Abbe numbers (0 before any glass row). */
typedef struct where {
    const char *path;
    int line;
    l2p_error *err;
    int first_glass_line;
    int first_glass_has_abbe;
} where;

/* The separators between numbers. '\r' is one so that CRLF files read like LF files. */
static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Tokens are quoted in messages, so a byte that would garble the terminal is reported by its
   code instead of printed. */
static int check_printable(const where *w, const char *token, size_t length)
{
    for (size_t i = 0; i < length; i++) {
        const unsigned char c = (unsigned char)token[i];
        if (c < 0x21 || c > 0x7e)
            return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                            "unexpected byte 0x%02x (is this a lens file?)", c);
    }
    return L2P_OK;
}

/* One decimal number, the whole token. strtod alone would also take "inf", "nan" and hex
   ("0x1p3"), which are not numbers a lens file holds; the character set check refuses them. */
static int parse_number(const where *w, const char *token, size_t length, double *out)
{
    const int quoted = length > QUOTE_MAX_CHARS ? QUOTE_MAX_CHARS : (int)length;
    const char *ellipsis = length > QUOTE_MAX_CHARS ? "..." : "";
    if (length > NUMBER_MAX_CHARS)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line, "a number of %zu characters, "
                        "more than the %d any decimal needs: '%.*s%s'", length,
                        NUMBER_MAX_CHARS, quoted, token, ellipsis);
    char text[NUMBER_MAX_CHARS + 1];
    memcpy(text, token, length);
    text[length] = '\0';

    errno = 0;
    char *rest = NULL;
    const double x = strtod(text, &rest);
    const int range_error = errno == ERANGE;
    const int whole = rest != text && *rest == '\0';
    if (whole && !isfinite(x) && !range_error)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line, "not a finite number: '%s'",
                        text);
    if (!whole || strspn(text, "0123456789+-.eE") != length)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line, "not a number: '%.*s%s'",
                        quoted, text, ellipsis);
    /* Overflow (1e999) and underflow (1e-999) both: neither is a length in millimetres, and
       an underflowed radius would make an infinite curvature. */
    if (range_error)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line, "number out of range: '%s'",
                        text);
    *out = x;
    return L2P_OK;
}

/* Splits one line (without its '\n') into a row. *found is 0 for a blank or comment-only
   line, 1 for a row of four or five numbers; anything else is an error. */
static int parse_line(const where *w, const char *p, const char *eol, row *r, int *found)
{
    *found = 0;
    /* A NUL is never text: say so rather than let it end the line early. */
    if (memchr(p, '\0', (size_t)(eol - p)))
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "NUL byte (is this a lens file?)");
    const char *data_end = memchr(p, '#', (size_t)(eol - p));
    if (!data_end)
        data_end = eol;
    /* a CR inside a line (not the CR of CRLF) ends rows in old Mac files, which read as one line */
    const char *cr = memchr(p, '\r', (size_t)(data_end - p)), *after = cr;
    while (after && after < data_end && is_blank(*after))
        after++;
    if (cr && after < data_end)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "a carriage return (CR) inside the line: rows end with CR alone, as in old "
                        "Mac files; convert the line endings to LF");
    int n = 0;
    for (;;) {
        while (p < data_end && is_blank(*p))
            p++;
        if (p == data_end)
            break;
        const char *token = p;
        while (p < data_end && !is_blank(*p))
            p++;
        const size_t length = (size_t)(p - token);
        int st = check_printable(w, token, length);
        if (st)
            return st;
        if (n == 5)
            return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                            "unexpected '%.*s%s' after the 5 numbers",
                            length > QUOTE_MAX_CHARS ? QUOTE_MAX_CHARS : (int)length, token,
                            length > QUOTE_MAX_CHARS ? "..." : "");
        st = parse_number(w, token, length, &r->value[n]);
        if (st)
            return st;
        r->text[n] = token;
        r->text_length[n] = (int)length;   /* at most NUMBER_MAX_CHARS */
        n++;
    }
    if (n != 0 && n != 4 && n != 5)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "expected 4 numbers (radius, thickness, index of refraction, "
                        "aperture diameter) or 5 (and the Abbe number), got %d", n);
    r->count = n;
    *found = n != 0;
    return L2P_OK;
}

/* The physical sense of one row, on its own. */
static int check_row(const where *w, const row *r)
{
    const double radius = r->value[0], thickness = r->value[1], ior = r->value[2];
    const double aperture = r->value[3];
#define QUOTE(k) r->text_length[k], r->text[k]
    if (!(aperture > 0.0))
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "aperture diameter must be positive, got %.*s", QUOTE(3));
    if (!(thickness >= 0.0))
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "thickness must not be negative, got %.*s", QUOTE(1));
    if (radius == 0.0) {
        if (ior != 0.0 && !(ior >= 1.0))
            return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                            "index of refraction must be 0 (air) or at least 1, got %.*s",
                            QUOTE(2));
        return L2P_OK;
    }
    if (!(ior >= 1.0))
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "index of refraction must be at least 1, got %.*s%s", QUOTE(2),
                        ior == 0.0 ? " (0 means air only on the aperture stop, radius 0)" : "");
    /* A sphere of radius R has no zone wider than 2|R|. */
    if (fabs(radius) < 0.5 * aperture)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "radius %.*s is too small for aperture diameter %.*s "
                        "(|radius| must be at least half the aperture)", QUOTE(0), QUOTE(3));
#undef QUOTE
    return L2P_OK;
}

/* Air behind the surface: index 1, or the stop row's 0. */
static int row_is_air(const row *r)
{
    return r->value[2] == 1.0 || (r->value[0] == 0.0 && r->value[2] == 0.0);
}

/* The Abbe number of one row, on its own: 0 on air (like the index column's 0 on the stop),
   at least LENS_ABBE_LEAST behind glass. Not finite was refused with the number. Below about
   0.66 the Cauchy fit (docs/lenses.md) puts the index below 1 within 380-780 nm; no optical
   material comes near 5. */
#define LENS_ABBE_LEAST 5.0

static int check_abbe(const where *w, const row *r)
{
    if (r->count < 5)
        return L2P_OK;
    const double abbe = r->value[4];
    if (row_is_air(r) && abbe != 0.0)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "Abbe number must be 0 on an air row (index %.*s), got %.*s",
                        r->text_length[2], r->text[2], r->text_length[4], r->text[4]);
    if (!row_is_air(r) && !(abbe > 0.0))
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "Abbe number of the glass behind the surface must be positive, got %.*s",
                        r->text_length[4], r->text[4]);
    if (!row_is_air(r) && abbe < LENS_ABBE_LEAST)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "Abbe number %.*s disperses more than any optical material (glasses lie "
                        "between about 17 and 95; at least %g here): a typo?",
                        r->text_length[4], r->text[4], LENS_ABBE_LEAST);
    return L2P_OK;
}

/* Every glass row gives an Abbe number or none does: a file that gives some only would trace
   those glasses with dispersion and the others without. Air rows may give 0 or nothing. */
static int check_abbe_column(where *w, const row *r)
{
    if (row_is_air(r))
        return L2P_OK;
    const int has = r->count == 5;
    if (w->first_glass_line == 0) {
        w->first_glass_line = w->line;
        w->first_glass_has_abbe = has;
        return L2P_OK;
    }
    if (has == w->first_glass_has_abbe)
        return L2P_OK;
    return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                    has ? "Abbe number on this glass row, but none on the glass row of line %d "
                          "(give every glass row one, or none)"
                        : "no Abbe number on this glass row, but the glass row of line %d has "
                          "one (give every glass row one, or none)",
                    w->first_glass_line);
}

static int out_of_memory(l2p_error *err)
{
    return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
}

/* Appends a checked row. The file says 0 for air on the stop row; the struct holds the index
   itself, so the tracer never sees the 0. A stop row that names an index keeps it. */
static int append_surface(const where *w, lens *l, int *capacity, const row *r)
{
    if (l->count == LENS_MAX_SURFACES)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "more than %d surfaces (is this a lens file?)", LENS_MAX_SURFACES);
    if (l->count == *capacity) {
        const int grown = *capacity ? 2 * *capacity : 16;
        lens_surface *s = realloc(l->surface, (size_t)grown * sizeof *s);
        if (!s)
            return out_of_memory(w->err);
        l->surface = s;
        *capacity = grown;
    }
    const double radius = r->value[0];
    l->surface[l->count++] = (lens_surface){
        .radius_mm = radius,
        .curvature_per_mm = radius == 0.0 ? 0.0 : 1.0 / radius,
        .thickness_mm = r->value[1],
        .ior = radius == 0.0 && r->value[2] == 0.0 ? 1.0 : r->value[2],
        .aperture_diameter_mm = r->value[3],
        .abbe = r->count == 5 ? r->value[4] : 0.0,
        .vertex_z_mm = 0.0,
        .line = w->line,
    };
    return L2P_OK;
}

/* Notes the stop; a second one is an error at its own line. */
static int note_stop(const where *w, lens *l)
{
    if (l->stop >= 0)
        return l2p_fail(w->err, L2P_BAD_INPUT, w->path, w->line,
                        "second aperture stop (radius 0; the first is on line %d)",
                        l->surface[l->stop].line);
    l->stop = l->count;
    return L2P_OK;
}

/* Reads every line into l->surface; *last_line is the number of the last line (1 for an
   empty file). Line numbers count '\n's, so they match what an editor shows for LF and CRLF
   files alike. */
static int parse_rows(const char *text, size_t length, const char *path, lens *l,
                      int *last_line, l2p_error *err)
{
    const char *p = text, *end = text + length;
    /* Editors on Windows may start a UTF-8 file with a byte order mark. */
    if (length >= 3 && memcmp(p, "\xEF\xBB\xBF", 3) == 0)
        p += 3;
    where w = {path, 0, err, 0, 0};
    int capacity = 0;
    while (p < end) {
        w.line++;
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol)
            eol = end;   /* no final newline */
        row r;
        int found = 0;
        int st = parse_line(&w, p, eol, &r, &found);
        if (!st && found)
            st = check_row(&w, &r);
        if (!st && found)
            st = check_abbe(&w, &r);
        if (!st && found)
            st = check_abbe_column(&w, &r);
        if (!st && found && r.value[0] == 0.0)
            st = note_stop(&w, l);
        if (!st && found)
            st = append_surface(&w, l, &capacity, &r);
        if (st)
            return st;
        p = eol < end ? eol + 1 : end;
    }
    *last_line = w.line > 0 ? w.line : 1;
    return L2P_OK;
}

/* Whether the text has a CR that no LF follows: rows ended by CR alone. */
static bool has_bare_cr(const char *text, size_t length)
{
    for (size_t i = 0; i < length; i++)
        if (text[i] == '\r' && (i + 1 == length || text[i + 1] != '\n'))
            return true;
    return false;
}

/* What the rows must make together: at least one surface, one stop, one refracting surface.
   What is missing is found missing at the end of the file, so that is the line named. A file
   of rows ended by CR alone whose first line is a comment reads as that one comment. */
static int check_lens(const lens *l, int last_line, bool bare_cr, l2p_error *err)
{
    if (l->count == 0 && bare_cr)
        return l2p_fail(err, L2P_BAD_INPUT, l->path, last_line,
                        "no surfaces, and carriage returns (CR) with no line feed after them: "
                        "rows end with CR alone, as in old Mac files; convert the line endings "
                        "to LF");
    if (l->count == 0)
        return l2p_fail(err, L2P_BAD_INPUT, l->path, last_line,
                        "no surfaces by the end of the file (a row is 4 numbers)");
    if (l->stop < 0)
        return l2p_fail(err, L2P_BAD_INPUT, l->path, last_line,
                        "no aperture stop (a row with radius 0) by the end of the file");
    if (l->count == 1)
        return l2p_fail(err, L2P_BAD_INPUT, l->path, l->surface[0].line,
                        "no refracting surface, only the aperture stop");
    return L2P_OK;
}

/* "lenses/dgauss.50mm.dat" -> "dgauss.50mm". */
static char *lens_name_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    size_t n = strlen(base);
    if (n > 4 && strcmp(base + n - 4, ".dat") == 0)
        n -= 4;
    char *name = malloc(n + 1);
    if (name) {
        memcpy(name, base, n);
        name[n] = '\0';
    }
    return name;
}

/* The parse with strtod in the "C" locale whatever the process's locale is (a library may
   have called setlocale): lens files always write a decimal point. uselocale is per thread. */
static int parse_in_c_locale(const char *text, size_t length, lens *l, int *last_line,
                             l2p_error *err)
{
    locale_t c_locale = newlocale(LC_ALL_MASK, "C", (locale_t)0);
    locale_t previous = c_locale ? uselocale(c_locale) : (locale_t)0;
    int st = parse_rows(text, length, l->path, l, last_line, err);
    if (c_locale) {
        uselocale(previous);
        freelocale(c_locale);
    }
    return st;
}

int lens_parse(const char *text, size_t length, const char *name, lens *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    if (!text) {   /* no text is an empty file; and keeps pointer arithmetic off NULL */
        text = "";
        length = 0;
    }
    lens l = {.stop = -1};
    l.path = strdup(name ? name : "(lens)");
    l.name = l.path ? lens_name_of(l.path) : NULL;
    int st = l.name ? L2P_OK : out_of_memory(err);
    int last_line = 1;
    if (!st)
        st = parse_in_c_locale(text, length, &l, &last_line, err);
    if (!st)
        st = check_lens(&l, last_line, has_bare_cr(text, length), err);
    if (st) {
        lens_free(&l);
        return st;
    }
    l.stop_diameter_mm = l.surface[l.stop].aperture_diameter_mm;
    l.film_distance_mm = 0.0;
    lens_set_film_distance(&l, 0.0);
    *out = l;
    return L2P_OK;
}

static int too_large(const char *path, l2p_error *err)
{
    return l2p_fail(err, L2P_BAD_INPUT, path, 0, "larger than %d MiB: not a lens file",
                    LENS_MAX_FILE_BYTES >> 20);
}

/* Opens for reading, refusing a directory (open succeeds on one; Linux then fails the read
   with EISDIR, but not every system does) and a regular file over the size limit before
   reading any of it. */
static int open_lens_file(const char *path, int *fd_out, l2p_error *err)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "%s", strerror(errno));
    struct stat info;
    const int failure = fstat(fd, &info) != 0 ? errno : S_ISDIR(info.st_mode) ? EISDIR : 0;
    const int large = !failure && S_ISREG(info.st_mode) && info.st_size > LENS_MAX_FILE_BYTES;
    if (failure || large) {
        close(fd);
        return large ? too_large(path, err)
                     : l2p_fail(err, L2P_BAD_INPUT, path, 0, "%s", strerror(failure));
    }
    *fd_out = fd;
    return L2P_OK;
}

/* Everything fd holds, up to one byte past LENS_MAX_FILE_BYTES (enough to know it is too big).
   Reads until end of file rather than trusting a size, so pipes and /dev/stdin work too. */
static int read_all(int fd, char **text, size_t *length, int *error_number)
{
    const size_t limit = (size_t)LENS_MAX_FILE_BYTES + 1;
    size_t size = 0, capacity = 0;
    char *buffer = NULL;
    while (size < limit) {
        if (size == capacity) {
            capacity = capacity ? (2 * capacity < limit ? 2 * capacity : limit) : 4096;
            char *grown = realloc(buffer, capacity);
            if (!grown) {
                free(buffer);
                *error_number = ENOMEM;
                return -1;
            }
            buffer = grown;
        }
        const ssize_t n = read(fd, buffer + size, capacity - size);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            *error_number = errno;
            free(buffer);
            return -1;
        }
        if (n == 0)
            break;
        size += (size_t)n;
    }
    *text = buffer;
    *length = size;
    return 0;
}

/* The whole file into memory; a lens file is a few hundred bytes, and the limit stops a wrong
   path from filling memory. */
static int read_whole_file(const char *path, char **text, size_t *length, l2p_error *err)
{
    int fd = -1;
    int st = open_lens_file(path, &fd, err);
    if (st)
        return st;
    int error_number = 0;
    const int failed = read_all(fd, text, length, &error_number);
    close(fd);
    if (failed)
        return error_number == ENOMEM ? out_of_memory(err)
                                      : l2p_fail(err, L2P_BAD_INPUT, path, 0, "%s",
                                                 strerror(error_number));
    if (*length > (size_t)LENS_MAX_FILE_BYTES) {
        free(*text);
        *text = NULL;
        return too_large(path, err);
    }
    return L2P_OK;
}

int lens_read(const char *path, lens *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    char *text = NULL;
    size_t length = 0;
    int st = read_whole_file(path, &text, &length, err);
    if (st)
        return st;
    st = lens_parse(text, length, path, out, err);
    free(text);
    return st;
}

void lens_free(lens *l)
{
    if (!l)
        return;
    free(l->path);
    free(l->name);
    free(l->surface);
    memset(l, 0, sizeof *l);
}

int lens_copy(lens *dst, const lens *src)
{
    lens copy = *src;
    copy.path = src->path ? strdup(src->path) : NULL;
    copy.name = src->name ? strdup(src->name) : NULL;
    const size_t bytes = (size_t)src->count * sizeof *src->surface;
    copy.surface = src->count > 0 ? malloc(bytes) : NULL;
    if ((src->path && !copy.path) || (src->name && !copy.name) ||
        (src->count > 0 && !copy.surface)) {
        lens_free(&copy);
        memset(dst, 0, sizeof *dst);
        return L2P_FAILED;
    }
    if (src->count > 0)
        memcpy(copy.surface, src->surface, bytes);
    *dst = copy;
    return L2P_OK;
}
