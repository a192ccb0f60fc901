/* The --rays CSV of a field render. Each sub-image's pixels are traced again with its shared
   sample through field_trace_pixels, the function that built its mesh: the rows are the rays
   the mesh was checked against, without keeping spp sub-images of rays until the sub-images
   are packed into renders. */
#include "field/fieldrays.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "field/fieldpixels.h"
#include "field/fieldtiles.h"
#include "field/strata.h"

static void put_row(FILE *out, const camera *c, film_sample s, long i, const sample_batch *b, int k,
                    double weight, const field_placement *at)
{
    const int w = c->crop_x1 - c->crop_x0;
    const ray *r = &b->out[k];
    double rx, ry;
    field_pixel_raster(c, s, i, &rx, &ry);
    fprintf(out, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,",
            rx, ry, b->film_point[k].x, b->film_point[k].y, r->o.x, r->o.y, r->o.z, r->d.x, r->d.y,
            r->d.z, weight);
    if (c->dispersion)
        fprintf(out, "%.17g,", s.wavelength_nm);
    fprintf(out, "%d,%ld,%ld\n", at->render, at->dx + i % w, at->dy + i / w + 1);
}

/* The factor on pixel i of piece p's weight: field_tiles_scale of its crop pixel, 1 without
   tiles. */
static double tile_scale(const field_tiles *t, const field_piece *p, long i)
{
    return t ? field_tiles_scale(t, (p->y0 + i / p->w) * (long)t->width + p->x0 + i % p->w) : 1.0;
}

/* The rows of piece p, seen through camera c (narrowed to it). */
static void put_subimage(FILE *out, const camera *c, const field_strata *t,
                         const field_tiles *tiles, const field_piece *p,
                         const field_placement *at, sample_batch *b)
{
    film_sample s = field_shared_sample(c, p->k, NULL);
    const double scale = field_strata_place(t, &s);
    const long n = (long)p->w * p->h;
    for (long start = 0; start < n && !ferror(out); start += CAMERA_BATCH) {
        field_trace_pixels(c, s, scale, start, (int)(n - start < CAMERA_BATCH ? n - start : CAMERA_BATCH), b);
        for (int j = 0; j < b->n; j++)
            if (b->passed[j])
                put_row(out, c, s, start + j, b, j,
                        b->weight[j] * tile_scale(tiles, p, start + j), at);
    }
}

int field_rays_write(FILE *out, const char *path, const camera *c, int strata_samples,
                     const field_piece *pieces, const field_tiles *tiles,
                     const field_placement *at, int count, l2p_error *err)
{
    sample_batch *b = malloc(sizeof *b);
    camera *piece = malloc(sizeof *piece);
    if (!b || !piece) {
        free(b), free(piece);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    fputs(c->dispersion ? "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,dir_x,dir_y,"
                          "dir_z,weight,wavelength_nm,image,image_x,image_y\n"
                        : "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,dir_x,dir_y,"
                          "dir_z,weight,image,image_x,image_y\n", out);
    field_strata t;
    field_strata_count(c, strata_samples, &t);
    *piece = *c;
    const int crop_w = c->crop_x1 - c->crop_x0, crop_h = c->crop_y1 - c->crop_y0;
    for (int k = 0; k < count && !ferror(out); k++) {
        const field_piece p = pieces ? pieces[k] : (field_piece){k, 0, 0, crop_w, crop_h};
        field_piece_crop(c, &p, piece);
        put_subimage(out, piece, &t, tiles, &p, &at[k], b);
    }
    free(b), free(piece);
    return ferror(out) ? l2p_fail(err, L2P_FAILED, path, 0, "write failed: %s", strerror(errno))
                       : L2P_OK;
}
