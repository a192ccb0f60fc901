#include "image/samplemap.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Records are packed byte by byte, so the file is the same on every machine; floats are
   written as their IEEE-754 bit patterns. */
_Static_assert(sizeof(float) == 4, "float must be IEEE-754 binary32");

enum { RECORD_BYTES = 16, BAND_BYTES = 4, BATCH_RECORDS = 1024 };

static long long record_bytes(const samplemap_header *h)
{
    return RECORD_BYTES + (h->wavelength_bands > 0 ? BAND_BYTES : 0);
}

static const char MAGIC[] = "lens2pov-samplemap 1";

/* ---- chunks ---- */

long long samplemap_chunk_count(const samplemap_header *h)
{
    if (h->chunk_faces <= 0)
        return 0;
    if (h->faces <= 0)
        return 1;   /* the emitter's dummy face: an empty table still renders one chunk */
    return (h->faces + h->chunk_faces - 1) / h->chunk_faces;
}

int samplemap_chunk_rows(const samplemap_header *h, long long chunk)
{
    if (chunk < 0 || chunk >= samplemap_chunk_count(h) || h->packed_width <= 0)
        return 0;
    long long faces = h->faces - chunk * h->chunk_faces;
    if (faces > h->chunk_faces)
        faces = h->chunk_faces;
    const long long rows = (faces + h->packed_width - 1) / h->packed_width;
    return rows > 0 ? (int)rows : 1;
}

/* ---- record packing ---- */

static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static uint32_t get_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put_f32(unsigned char *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, 4);
    put_u32(p, v);
}

static float get_f32(const unsigned char *p)
{
    const uint32_t v = get_u32(p);
    float f;
    memcpy(&f, &v, 4);
    return f;
}

static void pack_record(unsigned char *p, const samplemap_record *r)
{
    put_u32(p, r->film_pixel);
    put_f32(p + 4, r->offset_x);
    put_f32(p + 8, r->offset_y);
    put_f32(p + 12, r->weight);
}

static void unpack_record(const unsigned char *p, samplemap_record *r)
{
    r->film_pixel = get_u32(p);
    r->offset_x = get_f32(p + 4);
    r->offset_y = get_f32(p + 8);
    r->weight = get_f32(p + 12);
}

/* ---- writing ---- */

int samplemap_begin(FILE *fp)
{
    /* Spaces, not a header: a map whose writing was interrupted has no magic line. */
    char blank[SAMPLEMAP_HEADER_BYTES];
    memset(blank, ' ', sizeof blank);
    return fwrite(blank, 1, sizeof blank, fp) == sizeof blank ? L2P_OK : L2P_FAILED;
}

int samplemap_append(FILE *fp, const samplemap_record *records, const uint32_t *band,
                     size_t count)
{
    const size_t size = RECORD_BYTES + (band ? BAND_BYTES : 0);
    unsigned char buf[BATCH_RECORDS * (RECORD_BYTES + BAND_BYTES)];
    while (count > 0) {
        const size_t n = count < BATCH_RECORDS ? count : BATCH_RECORDS;
        for (size_t i = 0; i < n; i++) {
            pack_record(buf + i * size, &records[i]);
            if (band)
                put_u32(buf + i * size + RECORD_BYTES, band[i]);
        }
        if (fwrite(buf, size, n, fp) != n)
            return L2P_FAILED;
        records += n;
        band = band ? band + n : NULL;
        count -= n;
    }
    return L2P_OK;
}

/* A header string on one line: newlines (and carriage returns) become spaces. */
static void one_line(char *dst, size_t size, const char *src, size_t src_size)
{
    snprintf(dst, size, "%.*s", (int)strnlen(src, src_size), src);
    for (char *p = dst; *p; p++)
        if (*p == '\n' || *p == '\r')
            *p = ' ';
}

/* The header text without its padding; returns its length, or -1 when it does not fit. */
static int format_header(const samplemap_header *h, const char *magic, const char *more,
                         char *buf, size_t size)
{
    char lens[sizeof h->lens], pupil[sizeof h->pupil], trace[sizeof h->trace],
        weighting[sizeof h->weighting], bands[32] = "";
    one_line(lens, sizeof lens, h->lens, sizeof h->lens);
    one_line(pupil, sizeof pupil, h->pupil, sizeof h->pupil);
    one_line(trace, sizeof trace, h->trace, sizeof h->trace);
    one_line(weighting, sizeof weighting, h->weighting, sizeof h->weighting);
    if (h->wavelength_bands > 0)
        snprintf(bands, sizeof bands, "wavelength_bands %d\n", h->wavelength_bands);
    const int n = snprintf(buf, size,
        "%s\nfilm_width %d\nfilm_height %d\nspp %d\ncrop_x0 %d\ncrop_y0 %d\ncrop_x1 %d\n"
        "crop_y1 %d\npacked_width %d\nfaces %lld\nchunk_faces %lld\nlens %s\npupil %s\n"
        "trace %s\nweighting %s\nf_number %.17g\naperture_diameter_mm %.17g\n"
        "focus_distance_units %.17g\nfilm_distance_mm %.17g\nfilm_diagonal_mm %.17g\n"
        "unit_mm %.17g\n%s%send\n",
        magic, h->film_width, h->film_height, h->spp, h->crop_x0, h->crop_y0, h->crop_x1,
        h->crop_y1, h->packed_width, h->faces, h->chunk_faces, lens, pupil, trace, weighting,
        h->f_number, h->aperture_diameter_mm, h->focus_distance_units, h->film_distance_mm,
        h->film_diagonal_mm, h->unit_mm, bands, more);
    return n >= 0 && (size_t)n < size ? n : -1;
}

int samplemap_header_text(const samplemap_header *h, const char *magic, const char *more,
                          char text[SAMPLEMAP_HEADER_BYTES])
{
    char buf[SAMPLEMAP_HEADER_BYTES + 1];
    const int n = format_header(h, magic, more, buf, sizeof buf);
    if (n < 0)
        return -1;
    memcpy(text, buf, (size_t)n);
    memset(text + n, ' ', SAMPLEMAP_HEADER_BYTES - (size_t)n);
    return 0;
}

int samplemap_finish(FILE *fp, const samplemap_header *h)
{
    char text[SAMPLEMAP_HEADER_BYTES];
    if (samplemap_header_text(h, MAGIC, "", text) != 0 || h->faces < 0 || fflush(fp) != 0)
        return L2P_FAILED;
    /* The records written so far must be exactly the faces the header announces. */
    const off_t end = ftello(fp);
    if (end != (off_t)(SAMPLEMAP_HEADER_BYTES + record_bytes(h) * h->faces))
        return L2P_FAILED;
    if (fseeko(fp, 0, SEEK_SET) != 0 || fwrite(text, 1, SAMPLEMAP_HEADER_BYTES, fp) !=
                                            SAMPLEMAP_HEADER_BYTES)
        return L2P_FAILED;
    return fseeko(fp, 0, SEEK_END) == 0 && fflush(fp) == 0 ? L2P_OK : L2P_FAILED;
}

/* ---- reading the header ---- */

typedef enum field_type { FIELD_INT, FIELD_LLONG, FIELD_DOUBLE, FIELD_STRING } field_type;

typedef struct field {
    const char *key;
    field_type type;
    size_t offset, size;
    bool optional;
} field;

#define FIELD(name, type) {#name, type, offsetof(samplemap_header, name), \
                           sizeof(((samplemap_header *)0)->name), false}
static const field FIELDS[] = {
    FIELD(film_width, FIELD_INT),       FIELD(film_height, FIELD_INT),
    FIELD(spp, FIELD_INT),              FIELD(crop_x0, FIELD_INT),
    FIELD(crop_y0, FIELD_INT),          FIELD(crop_x1, FIELD_INT),
    FIELD(crop_y1, FIELD_INT),          FIELD(packed_width, FIELD_INT),
    FIELD(faces, FIELD_LLONG),          FIELD(chunk_faces, FIELD_LLONG),
    FIELD(lens, FIELD_STRING),          FIELD(pupil, FIELD_STRING),
    FIELD(trace, FIELD_STRING),         FIELD(weighting, FIELD_STRING),
    FIELD(f_number, FIELD_DOUBLE),      FIELD(aperture_diameter_mm, FIELD_DOUBLE),
    FIELD(focus_distance_units, FIELD_DOUBLE), FIELD(film_distance_mm, FIELD_DOUBLE),
    FIELD(film_diagonal_mm, FIELD_DOUBLE),     FIELD(unit_mm, FIELD_DOUBLE),
    {"wavelength_bands", FIELD_INT, offsetof(samplemap_header, wavelength_bands), sizeof(int), true},
};
#undef FIELD
enum { FIELD_COUNT = sizeof FIELDS / sizeof FIELDS[0] };

static int find_field(const char *key)
{
    for (int i = 0; i < FIELD_COUNT; i++)
        if (strcmp(FIELDS[i].key, key) == 0)
            return i;
    return -1;
}

/* Stores one value into its field; false when it does not parse or fit. Doubles may be inf
   (focus at infinity) or nan: they are metadata, not used in any computation. */
static int store_field(const field *f, const char *value, samplemap_header *h)
{
    char *dst = (char *)h + f->offset, *end = NULL;
    errno = 0;
    if (f->type == FIELD_STRING) {
        if (strlen(value) >= f->size)
            return 0;
        memcpy(dst, value, strlen(value) + 1);
        return 1;
    }
    if (f->type == FIELD_DOUBLE) {
        const double v = strtod(value, &end);
        memcpy(dst, &v, sizeof v);
    } else {
        const long long v = strtoll(value, &end, 10);
        if (f->type == FIELD_INT && (v < INT_MIN || v > INT_MAX))
            return 0;
        const int small = (int)v;
        memcpy(dst, f->type == FIELD_INT ? (const void *)&small : (const void *)&v, f->size);
    }
    return end != value && *end == '\0' && errno != ERANGE;
}

/* One "key value" line (NUL-terminated, without its newline). */
static int parse_line(char *line, int number, samplemap_header *h, int *seen, const char *path,
                      l2p_error *err)
{
    char *space = strchr(line, ' ');
    const char *value = space ? space + 1 : "";
    if (space)
        *space = '\0';
    const int i = find_field(line);
    if (i < 0)
        return L2P_OK;   /* unknown keys are skipped: later versions may add some */
    if (seen[i])
        return l2p_fail(err, L2P_BAD_INPUT, path, number, "'%s' given twice", line);
    seen[i] = 1;
    if (!store_field(&FIELDS[i], value, h))
        return l2p_fail(err, L2P_BAD_INPUT, path, number, "bad value for %s: '%s'", line, value);
    return L2P_OK;
}

/* After the line "end", only the padding spaces. */
static int check_padding(const char *p, const char *end, const char *path, l2p_error *err)
{
    for (; p < end; p++)
        if (*p != ' ')
            return l2p_fail(err, L2P_BAD_INPUT, path, 0, "header padding is not spaces");
    return L2P_OK;
}

static int check_all_seen(const int *seen, const char *path, l2p_error *err)
{
    for (int i = 0; i < FIELD_COUNT; i++)
        if (!seen[i] && !FIELDS[i].optional)
            return l2p_fail(err, L2P_BAD_INPUT, path, 0, "header has no '%s'", FIELDS[i].key);
    return L2P_OK;
}

int samplemap_header_parse(char *text, const char *magic, samplemap_header *h, const char *path,
                           l2p_error *err)
{
    const char *text_end = text + SAMPLEMAP_HEADER_BYTES;
    if (memchr(text, '\0', SAMPLEMAP_HEADER_BYTES))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "not a lens2pov sample map (binary header)");
    int seen[FIELD_COUNT] = {0}, number = 0;
    for (char *line = text; line < text_end; number++) {
        char *nl = strchr(line, '\n');
        if (!nl)
            return l2p_fail(err, L2P_BAD_INPUT, path, 0, "header has no line 'end'");
        *nl = '\0';
        if (number == 0 && strcmp(line, magic) != 0)
            return l2p_fail(err, L2P_BAD_INPUT, path, 1,
                            "not a lens2pov %s (first line is not '%s')",
                            strcmp(magic, MAGIC) ? "field map" : "sample map", magic);
        if (number > 0 && strcmp(line, "end") == 0) {
            int st = check_padding(nl + 1, text_end, path, err);
            return st ? st : check_all_seen(seen, path, err);
        }
        int st = number > 0 ? parse_line(line, number + 1, h, seen, path, err) : L2P_OK;
        if (st)
            return st;
        line = nl + 1;
    }
    return l2p_fail(err, L2P_BAD_INPUT, path, 0, "header has no line 'end'");
}

/* ---- validating ---- */

static int check_film(const samplemap_header *h, const char *path, l2p_error *err)
{
    if (h->film_width < 1 || h->film_height < 1 ||
        (unsigned long long)h->film_width * (unsigned long long)h->film_height > 1ull << 32)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "bad film size %dx%d", h->film_width,
                        h->film_height);
    if (h->spp < 1)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "bad spp %d", h->spp);
    if (h->crop_x0 < 0 || h->crop_x0 >= h->crop_x1 || h->crop_x1 > h->film_width ||
        h->crop_y0 < 0 || h->crop_y0 >= h->crop_y1 || h->crop_y1 > h->film_height)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0,
                        "crop %d,%d,%d,%d is not inside the %dx%d film", h->crop_x0,
                        h->crop_y0, h->crop_x1, h->crop_y1, h->film_width, h->film_height);
    return L2P_OK;
}

/* The layout must give chunk images POV-Ray can render: int sizes, whole rows. */
static int check_layout(const samplemap_header *h, long long file_bytes, const char *path,
                        l2p_error *err)
{
    if (h->packed_width < 1)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "bad packed_width %d", h->packed_width);
    if (h->chunk_faces < 1 || h->chunk_faces % h->packed_width != 0 || h->chunk_faces > INT_MAX)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0,
                        "chunk_faces %lld is not a positive multiple of packed_width %d",
                        h->chunk_faces, h->packed_width);
    if (h->wavelength_bands < 0 || (h->wavelength_bands > 0 && h->wavelength_bands != h->spp))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "wavelength_bands %d is neither 0 nor spp %d",
                        h->wavelength_bands, h->spp);
    const long long bytes = file_bytes - SAMPLEMAP_HEADER_BYTES, size = record_bytes(h);
    if (h->faces < 0 || h->faces > bytes / size || bytes != size * h->faces)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0,
                        "header says %lld faces but the file holds %lld bytes of records "
                        "(%lld bytes a face): truncated or corrupt", h->faces, bytes, size);
    return L2P_OK;
}

static int check_record(const samplemap_header *h, const samplemap_record *r, long long face,
                        const char *path, l2p_error *err)
{
    const long long x = r->film_pixel % (uint32_t)h->film_width;
    const long long y = r->film_pixel / (uint32_t)h->film_width;
    if (x < h->crop_x0 || x >= h->crop_x1 || y < h->crop_y0 || y >= h->crop_y1)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0,
                        "face %lld: film pixel %lld,%lld is outside the crop %d,%d,%d,%d", face,
                        x, y, h->crop_x0, h->crop_y0, h->crop_x1, h->crop_y1);
    /* float32 rounding can turn an offset just below 1 into 1. */
    if (!(r->offset_x >= 0.0f && r->offset_x <= 1.0f && r->offset_y >= 0.0f &&
          r->offset_y <= 1.0f))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "face %lld: offset %g,%g outside [0, 1]",
                        face, (double)r->offset_x, (double)r->offset_y);
    if (!isfinite(r->weight) || r->weight < 0.0f)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "face %lld: bad weight %g", face,
                        (double)r->weight);
    return L2P_OK;
}

static int check_band(const samplemap_header *h, uint32_t band, long long face, const char *path,
                      l2p_error *err)
{
    if (band >= (uint32_t)h->wavelength_bands)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "face %lld: wavelength band %lu is not "
                        "below %d", face, (unsigned long)band, h->wavelength_bands);
    return L2P_OK;
}

/* ---- reading ---- */

static int read_records(FILE *fp, samplemap *m, const char *path, l2p_error *err)
{
    unsigned char buf[BATCH_RECORDS * (RECORD_BYTES + BAND_BYTES)];
    const long long faces = m->header.faces;
    const size_t size = (size_t)record_bytes(&m->header);
    for (long long done = 0; done < faces;) {
        const size_t n = (size_t)(faces - done < BATCH_RECORDS ? faces - done : BATCH_RECORDS);
        if (fread(buf, size, n, fp) != n)
            return l2p_fail(err, ferror(fp) ? L2P_FAILED : L2P_BAD_INPUT, path, 0,
                            "cannot read the records: %s",
                            ferror(fp) ? strerror(errno) : "file ends early");
        for (size_t i = 0; i < n; i++) {
            const long long face = done + (long long)i;
            unpack_record(buf + i * size, &m->records[face]);
            int st = check_record(&m->header, &m->records[face], face, path, err);
            if (!st && m->band)
                st = check_band(&m->header, m->band[face] = get_u32(buf + i * size + RECORD_BYTES),
                                face, path, err);
            if (st)
                return st;
        }
        done += (long long)n;
    }
    return L2P_OK;
}

static int read_header(FILE *fp, samplemap_header *h, const char *path, l2p_error *err)
{
    struct stat st;
    if (fstat(fileno(fp), &st) != 0)
        return l2p_fail(err, L2P_FAILED, path, 0, "cannot read: %s", strerror(errno));
    char text[SAMPLEMAP_HEADER_BYTES + 1];
    if (fread(text, 1, SAMPLEMAP_HEADER_BYTES, fp) != SAMPLEMAP_HEADER_BYTES)
        return l2p_fail(err, ferror(fp) ? L2P_FAILED : L2P_BAD_INPUT, path, 0,
                        "not a lens2pov sample map (shorter than its %d-byte header)",
                        SAMPLEMAP_HEADER_BYTES);
    text[SAMPLEMAP_HEADER_BYTES] = '\0';
    memset(h, 0, sizeof *h);
    int s = samplemap_header_parse(text, MAGIC, h, path, err);
    if (!s)
        s = check_film(h, path, err);
    return s ? s : check_layout(h, (long long)st.st_size, path, err);
}

int samplemap_read(const char *path, samplemap *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "cannot read: %s", strerror(errno));
    int st = read_header(fp, &out->header, path, err);
    if (!st) {
        /* One extra record so that an empty table still gets a pointer of its own. */
        const size_t n = (size_t)(out->header.faces + 1);
        out->records = malloc(sizeof *out->records * n);
        if (out->header.wavelength_bands > 0)
            out->band = malloc(sizeof *out->band * n);
        st = out->records && (out->band || out->header.wavelength_bands == 0)
                 ? read_records(fp, out, path, err)
                 : l2p_fail(err, L2P_FAILED, path, 0, "out of memory");
    }
    fclose(fp);
    if (st)
        samplemap_free(out);
    return st;
}

void samplemap_free(samplemap *m)
{
    free(m->records);
    free(m->band);
    m->records = NULL;
    m->band = NULL;
}
