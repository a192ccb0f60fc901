/* Developing a field render from its map and its renders' pictures (fieldmap.h). */
#include "field/field_develop.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "base/cleanup.h"
#include "image/develop.h"
#include "image/image_io.h"
#include "optics/spectrum.h"

/* Adds sub-image k, rendered at (at.dx, at.dy) of a picture of iw pixels a row whose row 0 is
   not rendered (FS#261, docs/fields.md), into the crop's sums: each pixel of its piece (the
   whole crop unless the map says) its weight times its colour, and with dispersion its band's
   colour weights. */
static void add_subimage(const field_map *m, int k, const float *weights, const float *rgba,
                         int iw, double *sums)
{
    const samplemap_header *h = &m->header;
    const int crop_w = h->crop_x1 - h->crop_x0;
    const field_piece p = m->piece ? m->piece[k]
                                   : (field_piece){k, 0, 0, crop_w, h->crop_y1 - h->crop_y0};
    const size_t stride = develop_sums_per_pixel(h);
    double colour[3];
    if (h->wavelength_bands > 0)
        spectrum_band_weights((int)m->band[k], h->wavelength_bands, colour);
    const field_placement *at = &m->at[k];
    for (int y = 0; y < p.h; y++)
        for (int x = 0; x < p.w; x++) {
            const float wt = weights[(size_t)y * p.w + x];
            if (wt <= 0)
                continue;   /* blocked: no face, black */
            const float *px = rgba + 4 * ((size_t)(at->dy + y + 1) * iw + at->dx + x);
            develop_add(sums + stride * ((size_t)(p.y0 + y) * crop_w + p.x0 + x),
                        h->wavelength_bands > 0 ? colour : NULL, (double)wt, px);
        }
}

/* A render's picture, read on a thread of its own or the caller's. */
typedef struct picture {
    const char *path;
    int width, height;
    float *rgba;
    int status;
    l2p_error err;
} picture;

static void *read_picture(void *arg)
{
    picture *p = arg;
    p->status = image_read_rgba(p->path, &p->width, &p->height, &p->rgba, &p->err);
    return NULL;
}

/* Reads two pictures at once (decoding is most of developing), the second on a thread of its
   own. */
static void read_pair(picture p[2])
{
    pthread_t t;
    const bool threaded = p[1].path && cleanup_start_thread(&t, read_picture, &p[1]) == 0;
    read_picture(&p[0]);
    if (threaded)
        pthread_join(t, NULL);
    else if (p[1].path)
        read_picture(&p[1]);
}

/* Render r's picture and every sub-image in it, in the order of the sub-images. */
static int add_render(field_developer *d, int r, const picture *p, l2p_error *err)
{
    const field_map *m = d->map;
    if (p->status) {
        *err = p->err;
        return p->status;
    }
    int st = L2P_OK;
    if (p->width != m->width[r] + 1 || p->height != m->height[r] + 1)
        st = l2p_fail(err, L2P_BAD_INPUT, p->path, 0, "is %dx%d, not %dx%d: not render %d of this "
                      "field map", p->width, p->height, m->width[r] + 1, m->height[r] + 1, r);
    for (int k = 0; k < m->subimages && !st; k++)
        if (m->at[k].render == r && !(st = field_map_weights(m, k, d->weights, err))) {
            add_subimage(m, k, d->weights, p->rgba, p->width, d->sums);
            if (k < d->early_count)
                add_subimage(m, k, d->weights, p->rgba, p->width, d->early);
        }
    return st;
}

int field_develop_continue(field_developer *d, const field_map *m, double *sums, l2p_error *err)
{
    memset(d, 0, sizeof *d);
    d->map = m;
    const samplemap_header *h = &m->header;
    const size_t pixels = (size_t)(h->crop_x1 - h->crop_x0) * (size_t)(h->crop_y1 - h->crop_y0);
    d->sums = sums ? sums : calloc(develop_sums_per_pixel(h) * pixels, sizeof *d->sums);
    d->weights = malloc(sizeof *d->weights * pixels);
    d->picture = calloc((size_t)m->renders + 1, sizeof *d->picture);
    if (!d->sums || !d->weights || !d->picture) {
        field_develop_free(d);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    return L2P_OK;
}

int field_develop_start(field_developer *d, const field_map *m, l2p_error *err)
{
    return field_develop_continue(d, m, NULL, err);
}

double *field_develop_take_sums(field_developer *d)
{
    double *sums = d->sums;
    d->sums = NULL;
    return sums;
}

void field_develop_free(field_developer *d)
{
    for (int r = 0; d->picture && r < d->map->renders; r++)
        free(d->picture[r]);
    free(d->picture), free(d->sums), free(d->early), free(d->weights);
    memset(d, 0, sizeof *d);
}

/* Adds the renders from d->next on whose pictures are known, two at a time. */
static int add_known(field_developer *d, l2p_error *err)
{
    int st = L2P_OK;
    while (!st && d->next < d->map->renders && d->picture[d->next]) {
        const int r = d->next, two = r + 1 < d->map->renders && d->picture[r + 1];
        picture p[2] = {{.path = d->picture[r]}, {.path = two ? d->picture[r + 1] : NULL}};
        read_pair(p);
        for (int i = 0; i < 2 && p[i].path; i++) {
            if (!st)
                st = add_render(d, r + i, &p[i], err);
            if (!st && d->remove_pictures)
                unlink(p[i].path);
            free(p[i].rgba);
        }
        d->next += 1 + two;
    }
    return st;
}

int field_develop_keep_early(field_developer *d, int count, l2p_error *err)
{
    const samplemap_header *h = &d->map->header;
    const size_t pixels = (size_t)(h->crop_x1 - h->crop_x0) * (size_t)(h->crop_y1 - h->crop_y0);
    d->early = calloc(develop_sums_per_pixel(h) * pixels, sizeof *d->early);
    d->early_count = d->early ? count : 0;
    return d->early ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
}

int field_develop_add(field_developer *d, int r, const char *path, l2p_error *err)
{
    if (r < 0 || r >= d->map->renders || r < d->next || d->picture[r])
        return l2p_fail(err, L2P_FAILED, path, 0, "render %d given twice or out of range", r);
    if (!(d->picture[r] = strdup(path)))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    return add_known(d, err);
}

int field_develop_finish(field_developer *d, const char *out, l2p_error *err)
{
    if (d->next < d->map->renders)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "render %d was not developed", d->next);
    const samplemap map = {.header = d->map->header};
    return develop_write_picture(&map, d->sums, out, err);
}

int field_develop(const field_map *m, const char *const *renders, int count, const char *out,
                  l2p_error *err)
{
    if (count != m->renders)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "the field map has %d render%s but %d %s "
                        "given", m->renders, m->renders == 1 ? "" : "s", count,
                        count == 1 ? "was" : "were");
    int st = develop_check_distinct(renders, count, err);
    if (st)
        return st;
    field_developer d;
    st = field_develop_start(&d, m, err);
    if (st)
        return st;
    for (int r = 0; r < count && !st; r++)
        if (!(d.picture[r] = strdup(renders[r])))
            st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    if (!st)
        st = add_known(&d, err);
    if (!st)
        st = field_develop_finish(&d, out, err);
    field_develop_free(&d);
    return st;
}
