#include "field/fieldmap.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char MAGIC[] = "lens2pov-fieldmap 1";

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

int field_map_finish(const outfile *f, const field_map *m, l2p_error *err)
{
    const samplemap_header *h = &m->header;
    const size_t n = 8 * (size_t)m->renders + 16 * (size_t)h->spp;
    unsigned char *t = malloc(n);
    if (!t)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; r < m->renders; r++) {
        put_u32(t + 8 * r, (uint32_t)m->width[r]);
        put_u32(t + 8 * r + 4, (uint32_t)m->height[r]);
    }
    unsigned char *p = t + 8 * (size_t)m->renders;
    for (int k = 0; k < h->spp; k++, p += 16) {
        put_u32(p, (uint32_t)m->at[k].render);
        put_u32(p + 4, (uint32_t)m->at[k].dx);
        put_u32(p + 8, (uint32_t)m->at[k].dy);
        put_u32(p + 12, m->band ? m->band[k] : 0);
    }
    int st = write_at(f, t, n, tables_at(h), err);
    free(t);
    return st ? st : put_header(f, h, m->renders, err);
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

/* The header, and R from its line "renders R" (the sample map's parser skips the line). */
static int read_header(int fd, const char *path, field_map *m, l2p_error *err)
{
    char text[SAMPLEMAP_HEADER_BYTES + 1];
    int st = read_at(fd, text, SAMPLEMAP_HEADER_BYTES, 0, path, err);
    if (st)
        return st;
    text[SAMPLEMAP_HEADER_BYTES] = '\0';
    const char *line = strstr(text, "\nrenders ");
    char *end = NULL;
    long renders = line ? strtol(line + 9, &end, 10) : -1;
    if (line && *end != '\n')
        renders = -1;
    st = samplemap_header_parse(text, MAGIC, &m->header, path, err);   /* text changes */
    if (st)
        return st;
    if (renders < 1 || renders > m->header.spp)
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "header has no line 'renders R' with R from "
                        "1 to spp");
    m->renders = (int)renders;
    const samplemap_header *h = &m->header;
    if (h->film_width < 1 || h->film_height < 1 || h->spp < 1 || h->crop_x0 < 0 ||
        h->crop_x0 >= h->crop_x1 || h->crop_x1 > h->film_width || h->crop_y0 < 0 ||
        h->crop_y0 >= h->crop_y1 || h->crop_y1 > h->film_height ||
        (h->wavelength_bands != 0 && h->wavelength_bands != h->spp))
        return l2p_fail(err, L2P_BAD_INPUT, path, 0, "bad film, crop, spp or wavelength_bands");
    return L2P_OK;
}

/* Each render's size and each sub-image's place: the crop must lie inside its render. */
static int read_tables(int fd, const char *path, field_map *m, l2p_error *err)
{
    const samplemap_header *h = &m->header;
    const size_t n = 8 * (size_t)m->renders + 16 * (size_t)h->spp;
    unsigned char *t = malloc(n);
    m->width = malloc(sizeof *m->width * (size_t)m->renders);
    m->height = malloc(sizeof *m->height * (size_t)m->renders);
    m->at = malloc(sizeof *m->at * (size_t)h->spp);
    m->band = malloc(sizeof *m->band * (size_t)h->spp);
    int st = t && m->width && m->height && m->at && m->band
                 ? read_at(fd, t, n, tables_at(h), path, err)
                 : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; !st && r < m->renders; r++) {
        m->width[r] = (int)get_u32(t + 8 * r);
        m->height[r] = (int)get_u32(t + 8 * r + 4);
        if (m->width[r] < 1 || m->height[r] < 1)
            st = l2p_fail(err, L2P_BAD_INPUT, path, 0, "render %d has no pixels", r);
    }
    const int w = h->crop_x1 - h->crop_x0, ht = h->crop_y1 - h->crop_y0;
    for (int k = 0; !st && k < h->spp; k++) {
        const unsigned char *p = t + 8 * (size_t)m->renders + 16 * (size_t)k;
        const uint32_t r = get_u32(p), dx = get_u32(p + 4), dy = get_u32(p + 8);
        m->band[k] = get_u32(p + 12);
        if (r >= (uint32_t)m->renders || dx > (uint32_t)(m->width[r] - w) ||
            dy > (uint32_t)(m->height[r] - ht) || m->width[r] < w || m->height[r] < ht)
            st = l2p_fail(err, L2P_BAD_INPUT, path, 0, "sub-image %d does not lie in a render", k);
        else if (m->band[k] >= (uint32_t)(h->wavelength_bands ? h->wavelength_bands : 1))
            st = l2p_fail(err, L2P_BAD_INPUT, path, 0, "sub-image %d: band %lu out of range", k,
                          (unsigned long)m->band[k]);
        else
            m->at[k] = (field_placement){(int)r, (int)dx, (int)dy};
    }
    free(t);
    return st;
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
    if (!st && (long long)sb.st_size != file_bytes(&out->header, out->renders))
        st = l2p_fail(err, L2P_BAD_INPUT, path, 0, "the file holds %lld bytes, its header says "
                      "%lld: truncated or corrupt", (long long)sb.st_size,
                      file_bytes(&out->header, out->renders));
    if (!st)
        st = read_tables(fd, path, out, err);
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
    const size_t n = (size_t)crop_pixels(&m->header);
    unsigned char *bytes = malloc(4 * n);
    const int fd = open_file(m->path);
    int st = !bytes ? l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory")
             : fd < 0 ? l2p_fail(err, L2P_FAILED, m->path, 0, "cannot read: %s", strerror(errno))
                      : read_at(fd, bytes, 4 * n, weights_at(&m->header, k), m->path, err);
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
    free(m->width), free(m->height), free(m->at), free(m->band), free(m->path);
    memset(m, 0, sizeof *m);
}
