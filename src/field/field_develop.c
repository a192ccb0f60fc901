/* Developing a field render from its map and its renders' pictures (fieldmap.h). */
#include "field/field_develop.h"

#include <stdbool.h>
#include <stdlib.h>
#include "base/cleanup.h"
#include "image/develop.h"
#include "image/image_io.h"
#include "optics/spectrum.h"

/* Adds sub-image k, rendered at (at.dx, at.dy) of a picture of iw pixels a row whose row 0 is
   not rendered (FS#261, docs/fields.md), into the crop's sums: each pixel its weight times its
   colour, and with dispersion its band's colour weights. */
static void add_subimage(const field_map *m, int k, const float *weights, const float *rgba,
                         int iw, double *sums)
{
    const samplemap_header *h = &m->header;
    const int w = h->crop_x1 - h->crop_x0, ht = h->crop_y1 - h->crop_y0;
    const size_t stride = develop_sums_per_pixel(h);
    double colour[3];
    if (h->wavelength_bands > 0)
        spectrum_band_weights((int)m->band[k], h->wavelength_bands, colour);
    const field_placement *at = &m->at[k];
    for (int y = 0; y < ht; y++)
        for (int x = 0; x < w; x++) {
            const float wt = weights[(size_t)y * w + x];
            if (wt <= 0)
                continue;   /* blocked: no face, black */
            const float *px = rgba + 4 * ((size_t)(at->dy + y + 1) * iw + at->dx + x);
            develop_add(sums + stride * ((size_t)y * w + x),
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
static int add_render(const field_map *m, int r, const picture *p, float *weights, double *sums,
                      l2p_error *err)
{
    if (p->status) {
        *err = p->err;
        return p->status;
    }
    int st = L2P_OK;
    if (p->width != m->width[r] + 1 || p->height != m->height[r] + 1)
        st = l2p_fail(err, L2P_BAD_INPUT, p->path, 0, "is %dx%d, not %dx%d: not render %d of this "
                      "field map", p->width, p->height, m->width[r] + 1, m->height[r] + 1, r);
    for (int k = 0; k < m->header.spp && !st; k++)
        if (m->at[k].render == r && !(st = field_map_weights(m, k, weights, err)))
            add_subimage(m, k, weights, p->rgba, p->width, sums);
    return st;
}

int field_develop(const field_map *m, const char *const *renders, int count, const char *out,
                  l2p_error *err)
{
    if (count != m->renders)
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "the field map has %d render%s but %d %s "
                        "given", m->renders, m->renders == 1 ? "" : "s", count,
                        count == 1 ? "was" : "were");
    const samplemap_header *h = &m->header;
    const size_t pixels = (size_t)(h->crop_x1 - h->crop_x0) * (size_t)(h->crop_y1 - h->crop_y0);
    double *sums = calloc(develop_sums_per_pixel(h) * pixels, sizeof *sums);
    float *weights = malloc(sizeof *weights * pixels);
    int st = sums && weights ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; r < count && !st; r += 2) {
        picture p[2] = {{.path = renders[r]}, {.path = r + 1 < count ? renders[r + 1] : NULL}};
        read_pair(p);
        for (int i = 0; i < 2 && p[i].path; i++) {
            if (!st)
                st = add_render(m, r + i, &p[i], weights, sums, err);
            free(p[i].rgba);
        }
    }
    if (!st) {
        const samplemap map = {.header = *h};
        st = develop_write_picture(&map, sums, out, err);
    }
    free(sums), free(weights);
    return st;
}
