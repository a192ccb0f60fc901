#include "field/fieldmap.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char MAGIC[] = "lens2pov-fieldmap 1", MAGIC_PIECES[] = "lens2pov-fieldmap 2";

static long long crop_pixels(const samplemap_header *h)
{
    return (long long)(h->crop_x1 - h->crop_x0) * (h->crop_y1 - h->crop_y0);
}

/* Byte offsets of the layout (fieldmap.h). */
static long long weights_at(const samplemap_header *h, int k)
{
    return SAMPLEMAP_HEADER_BYTES + 4 * crop_pixels(h) * k;
}

static long long tables_at(const samplemap_header *h)
{
    return weights_at(h, h->spp);
}

static long long file_bytes(const samplemap_header *h, int renders)
{
    return tables_at(h) + 8LL * renders + 16LL * h->spp;
}

/* Little-endian, whatever the machine: the file is the same everywhere. */
static void put_u32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t get_u32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static int write_at(const outfile *f, const void *data, size_t n, long long at, l2p_error *err)
{
    const unsigned char *p = data;
    while (n > 0) {
        const ssize_t done = pwrite(fileno(f->fp), p, n, (off_t)at);
        if (done < 0 && errno == EINTR)
            continue;
        if (done <= 0)
            return l2p_fail(err, L2P_FAILED, f->final_path, 0, "cannot write: %s", strerror(errno));
        p += done, n -= (size_t)done, at += done;
    }
    return L2P_OK;
}

static int read_at(int fd, void *data, size_t n, long long at, const char *path, l2p_error *err)
{
    unsigned char *p = data;
    while (n > 0) {
        const ssize_t done = pread(fd, p, n, (off_t)at);
        if (done < 0 && errno == EINTR)
            continue;
        if (done < 0)
            return l2p_fail(err, L2P_FAILED, path, 0, "cannot read: %s", strerror(errno));
        if (done == 0)
            return l2p_fail(err, L2P_BAD_INPUT, path, 0, "the file ends early: truncated");
        p += done, n -= (size_t)done, at += done;
    }
    return L2P_OK;
}

static int open_file(const char *path)
{
    return open(path, O_RDONLY | O_CLOEXEC);
}

/* ---- writing ---- */

static int put_header(const outfile *f, const samplemap_header *h, int renders, l2p_error *err)
{
    char more[32], text[SAMPLEMAP_HEADER_BYTES];
    snprintf(more, sizeof more, "renders %d\n", renders);
    if (samplemap_header_text(h, MAGIC, more, text) != 0)
        return l2p_fail(err, L2P_FAILED, f->final_path, 0, "the header does not fit");
    return write_at(f, text, sizeof text, 0, err);
}

int field_map_begin(const outfile *f, const samplemap_header *h, l2p_error *err)
{
    /* Spaces where the header goes: an interrupted map has no first line. */
    char blank[SAMPLEMAP_HEADER_BYTES];
    memset(blank, ' ', sizeof blank);
    int st = write_at(f, blank, sizeof blank, 0, err);
    if (!st && ftruncate(fileno(f->fp), (off_t)tables_at(h)) != 0)
        st = l2p_fail(err, L2P_FAILED, f->final_path, 0, "cannot write: %s", strerror(errno));
    return st;
}

int field_map_put_weights(const outfile *f, const samplemap_header *h, int k, const float *weights,
                          l2p_error *err)
{
    const size_t n = (size_t)crop_pixels(h);
    unsigned char *bytes = malloc(4 * n);
    if (!bytes)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (size_t i = 0; i < n; i++) {
        uint32_t bits;
        memcpy(&bits, &weights[i], 4);
        put_u32(bytes + 4 * i, bits);
    }
    const int st = write_at(f, bytes, 4 * n, weights_at(h, k), err);
    free(bytes);
    return st;
}

/* The tables of m at byte `at` of f: each render's width and height, then each sub-image's
   record, render, dx, dy, band, and in a map of pieces (m->piece) x0, y0, w, h. */
static int put_tables(const outfile *f, const field_map *m, long long at, l2p_error *err)
{
    const size_t record = m->piece ? 32 : 16;
    const size_t n = 8 * (size_t)m->renders + record * (size_t)m->subimages;
    unsigned char *t = malloc(n);
    if (!t)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; r < m->renders; r++) {
        put_u32(t + 8 * r, (uint32_t)m->width[r]);
        put_u32(t + 8 * r + 4, (uint32_t)m->height[r]);
    }
    unsigned char *p = t + 8 * (size_t)m->renders;
    for (int k = 0; k < m->subimages; k++, p += record) {
        const field_placement *place = &m->at[k];
        const field_piece *q = m->piece ? &m->piece[k] : NULL;
        const uint32_t v[8] = {(uint32_t)place->render, (uint32_t)place->dx, (uint32_t)place->dy,
                               m->band ? m->band[k] : 0, q ? (uint32_t)q->x0 : 0,
                               q ? (uint32_t)q->y0 : 0, q ? (uint32_t)q->w : 0,
                               q ? (uint32_t)q->h : 0};
        for (size_t i = 0; i < record / 4; i++)
            put_u32(p + 4 * i, v[i]);
    }
    const int st = write_at(f, t, n, at, err);
    free(t);
    return st;
}

int field_map_finish(const outfile *f, const field_map *m, l2p_error *err)
{
    const int st = put_tables(f, m, tables_at(&m->header), err);
    return st ? st : put_header(f, &m->header, m->renders, err);
}

/* A map of pieces (version 2, fieldmap.h): the header with "subimages S"; the tables, each
   sub-image's record eight numbers; then the weights, sub-image by sub-image, each its piece's
   pixels. */
static long long pieces_pixels(const field_map *m)
{
    long long n = 0;
    for (int k = 0; k < m->subimages; k++)
        n += (long long)m->piece[k].w * m->piece[k].h;
    return n;
}

static long long pieces_weights_at(const field_map *m)
{
    return SAMPLEMAP_HEADER_BYTES + 8LL * m->renders + 32LL * m->subimages;
}

int field_map_write_pieces(const outfile *f, const field_map *m, l2p_error *err)
{
    const size_t most = (size_t)crop_pixels(&m->header);
    float *w = malloc(sizeof *w * most);
    unsigned char *bytes = malloc(4 * most);
    int st = w && bytes ? put_tables(f, m, SAMPLEMAP_HEADER_BYTES, err)
                        : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    long long at = pieces_weights_at(m);
    for (int k = 0; k < m->subimages && !st; k++) {
        const size_t n = (size_t)m->piece[k].w * m->piece[k].h;
        if (!(st = field_map_weights(m, k, w, err))) {
            for (size_t i = 0; i < n; i++) {
                uint32_t bits;
                memcpy(&bits, &w[i], 4);
                put_u32(bytes + 4 * i, bits);
            }
            st = write_at(f, bytes, 4 * n, at, err);
        }
        at += 4 * (long long)n;
    }
    char more[64], text[SAMPLEMAP_HEADER_BYTES];
    snprintf(more, sizeof more, "renders %d\nsubimages %d\n", m->renders, m->subimages);
    if (!st && samplemap_header_text(&m->header, MAGIC_PIECES, more, text) != 0)
        st = l2p_fail(err, L2P_FAILED, f->final_path, 0, "the header does not fit");
    if (!st)
        st = write_at(f, text, sizeof text, 0, err);
    free(w), free(bytes);
    return st;
}

/* ---- reading ---- */

int field_map_is_one(const char *path)
{
    /* by the first word, whatever the version: reading it then says which version it takes */
    static const char word[] = "lens2pov-fieldmap ";
    char first[sizeof word - 1];
    FILE *f = fopen(path, "rb");
    const int one = f && fread(first, 1, sizeof first, f) == sizeof first && !memcmp(first, word, sizeof first);
    if (f)
        fclose(f);
    return one;
}

/* The number on the header's line "NAME N", or -1 when there is none. */
static long header_number(const char *text, const char *name)
{
    char key[32];
    snprintf(key, sizeof key, "\n%s ", name);
    const char *line = strstr(text, key);
    char *end = NULL;
    const long n = line ? strtol(line + strlen(key), &end, 10) : -1;
    return line && *end == '\n' ? n : -1;
}

/* The header, R from its line "renders R", and for a map of pieces S from "subimages S" (the
   sample map's parser skips both). */
static int read_header(int fd, const char *path, field_map *m, l2p_error *err)
{
    char text[SAMPLEMAP_HEADER_BYTES + 1];
    int st = read_at(fd, text, SAMPLEMAP_HEADER_BYTES, 0, path, err);
    if (st)
        return st;
    text[SAMPLEMAP_HEADER_BYTES] = '\0';
    const bool pieces = !strncmp(text, MAGIC_PIECES, sizeof MAGIC_PIECES - 1) &&
                        text[sizeof MAGIC_PIECES - 1] == '\n';
    const long renders = header_number(text, "renders");
    const long subimages = pieces ? header_number(text, "subimages") : 0;
    /* the parse changes text */
    st = samplemap_header_parse(text, pieces ? MAGIC_PIECES : MAGIC, &m->header, path, err);
    if (st)
        return st;
    m->subimages = pieces ? (int)(subimages > INT_MAX ? -1 : subimages) : m->header.spp;
    if (m->subimages < 1)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "header has no line 'subimages S' with S of "
                        "1 or more");
    if (renders < 1 || renders > m->subimages)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "header has no line 'renders R' with R from "
                        "1 to %s", pieces ? "subimages" : "spp");
    m->renders = (int)renders;
    const samplemap_header *h = &m->header;
    if (h->film_width < 1 || h->film_height < 1 || h->spp < 1 || h->crop_x0 < 0 ||
        h->crop_x0 >= h->crop_x1 || h->crop_x1 > h->film_width || h->crop_y0 < 0 ||
        h->crop_y0 >= h->crop_y1 || h->crop_y1 > h->film_height ||
        (h->wavelength_bands != 0 && (pieces || h->wavelength_bands != h->spp)))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "bad film, crop, spp or wavelength_bands");
    if (pieces && !(m->piece = malloc(sizeof *m->piece * (size_t)m->subimages)))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    return L2P_OK;
}

/* Sub-image k's record: where it lies in its render and, in a map of pieces, what of the crop
   it shows, which must lie in the crop and in its render. */
static int read_record(const unsigned char *p, int k, field_map *m, const char *path,
                       l2p_error *err)
{
    const samplemap_header *h = &m->header;
    const uint32_t r = get_u32(p), dx = get_u32(p + 4), dy = get_u32(p + 8);
    const uint32_t cw = (uint32_t)(h->crop_x1 - h->crop_x0);
    const uint32_t ch = (uint32_t)(h->crop_y1 - h->crop_y0);
    const uint32_t x0 = m->piece ? get_u32(p + 16) : 0, y0 = m->piece ? get_u32(p + 20) : 0;
    const uint32_t w = m->piece ? get_u32(p + 24) : cw, ht = m->piece ? get_u32(p + 28) : ch;
    m->band[k] = get_u32(p + 12);
    if (w < 1 || ht < 1 || x0 >= cw || y0 >= ch || w > cw - x0 || ht > ch - y0)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "sub-image %d does not lie in the crop", k);
    if (r >= (uint32_t)m->renders || (uint32_t)m->width[r] < w || (uint32_t)m->height[r] < ht ||
        dx > (uint32_t)m->width[r] - w || dy > (uint32_t)m->height[r] - ht)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "sub-image %d does not lie in a render", k);
    if (m->band[k] >= (uint32_t)(h->wavelength_bands ? h->wavelength_bands : 1))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "sub-image %d: band %lu out of range", k,
                        (unsigned long)m->band[k]);
    m->at[k] = (field_placement){(int)r, (int)dx, (int)dy};
    if (m->piece)
        m->piece[k] = (field_piece){k, (int)x0, (int)y0, (int)w, (int)ht};
    return L2P_OK;
}

/* Each render's size and each sub-image's record. */
static int read_tables(int fd, const char *path, field_map *m, l2p_error *err)
{
    const size_t record = m->piece ? 32 : 16;
    const size_t n = 8 * (size_t)m->renders + record * (size_t)m->subimages;
    unsigned char *t = malloc(n);
    m->width = malloc(sizeof *m->width * (size_t)m->renders);
    m->height = malloc(sizeof *m->height * (size_t)m->renders);
    m->at = malloc(sizeof *m->at * (size_t)m->subimages);
    m->band = malloc(sizeof *m->band * (size_t)m->subimages);
    int st = t && m->width && m->height && m->at && m->band
                 ? read_at(fd, t, n, m->piece ? SAMPLEMAP_HEADER_BYTES : tables_at(&m->header),
                           path, err)
                 : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; !st && r < m->renders; r++) {
        m->width[r] = (int)get_u32(t + 8 * r);
        m->height[r] = (int)get_u32(t + 8 * r + 4);
        if (m->width[r] < 1 || m->height[r] < 1)
            st = l2p_fail(err, L2P_BAD_INPUT, path, 0, "render %d has no pixels", r);
    }
    for (int k = 0; !st && k < m->subimages; k++)
        st = read_record(t + 8 * (size_t)m->renders + record * (size_t)k, k, m, path, err);
    free(t);
    return st;
}

/* Where each sub-image's weights begin in a map of pieces. */
static int piece_offsets(field_map *m, l2p_error *err)
{
    if (!(m->offset = malloc(sizeof *m->offset * (size_t)m->subimages)))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    long long at = pieces_weights_at(m);
    for (int k = 0; k < m->subimages; k++) {
        m->offset[k] = at;
        at += 4LL * m->piece[k].w * m->piece[k].h;
    }
    return L2P_OK;
}

int field_map_read(const char *path, field_map *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    const int fd = open_file(path);
    if (fd < 0)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "cannot read: %s", strerror(errno));
    struct stat sb;
    int st = fstat(fd, &sb) == 0 ? L2P_OK : l2p_fail(err, L2P_FAILED, path, 0, "cannot read");
    if (!st)
        st = read_header(fd, path, out, err);
    /* a map of pieces has its tables first: its size follows from them */
    if (!st && out->piece && (long long)sb.st_size < pieces_weights_at(out))
        st = l2p_fail(err, L2P_BAD_INPUT, path, 0, "the file ends early: truncated");
    if (!st && out->piece)
        st = read_tables(fd, path, out, err);
    const long long bytes = st ? 0 : out->piece ? pieces_weights_at(out) + 4 * pieces_pixels(out)
                                                : file_bytes(&out->header, out->renders);
    if (!st && (long long)sb.st_size != bytes)
        st = l2p_fail(err, L2P_BAD_INPUT, path, 0, "the file holds %lld bytes, its header says "
                      "%lld: truncated or corrupt", (long long)sb.st_size, bytes);
    if (!st && !out->piece)
        st = read_tables(fd, path, out, err);
    if (!st && out->piece)
        st = piece_offsets(out, err);
    close(fd);
    if (!st && !(out->path = strdup(path)))
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    if (st)
        field_map_free(out);
    return st;
}

int field_map_weights(const field_map *m, int k, float *weights, l2p_error *err)
{
    if (m->weights_of)
        return m->weights_of(m->weights_ctx, k, weights, err);
    const size_t n = m->piece ? (size_t)m->piece[k].w * m->piece[k].h
                              : (size_t)crop_pixels(&m->header);
    unsigned char *bytes = malloc(4 * n);
    const int fd = open_file(m->path);
    int st = !bytes ? l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory")
             : fd < 0 ? l2p_fail(err, L2P_FAILED, m->path, 0, "cannot read: %s", strerror(errno))
                      : read_at(fd, bytes, 4 * n, m->piece ? m->offset[k] : weights_at(&m->header, k),
                                m->path, err);
    for (size_t i = 0; !st && i < n; i++) {
        const uint32_t bits = get_u32(bytes + 4 * i);
        memcpy(&weights[i], &bits, 4);
        if (!isfinite(weights[i]) || weights[i] < 0)
            st = l2p_fail(err, L2P_BAD_INPUT, m->path, 0, "sub-image %d: bad weight %g", k,
                          (double)weights[i]);
    }
    if (fd >= 0)
        close(fd);
    free(bytes);
    return st;
}

void field_map_free(field_map *m)
{
    free(m->width), free(m->height), free(m->at), free(m->band), free(m->piece), free(m->offset);
    free(m->path);
    memset(m, 0, sizeof *m);
}
