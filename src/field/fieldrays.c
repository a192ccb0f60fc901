/* The --rays CSV of a field render. Each sub-image's pixels are traced again with its shared
   sample through field_trace_pixels, the function that built its mesh: the rows are the rays
   the mesh was checked against, without keeping spp sub-images of rays until the sub-images
   are packed into renders. */
#include "field/fieldrays.h"

#include <stdlib.h>
#include "field/fieldpixels.h"
#include "field/strata.h"

static void put_row(FILE *out, const camera *c, film_sample s, long i, const sample_batch *b, int k,
                    const field_placement *at)
{
    const int w = c->crop_x1 - c->crop_x0;
    const ray *r = &b->out[k];
    double rx, ry;
    field_pixel_raster(c, s, i, &rx, &ry);
    fprintf(out, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,",
            rx, ry, b->film_point[k].x, b->film_point[k].y, r->o.x, r->o.y, r->o.z, r->d.x, r->d.y,
            r->d.z, b->weight[k]);
    if (c->dispersion)
        fprintf(out, "%.17g,", s.wavelength_nm);
    fprintf(out, "%d,%ld,%ld\n", at->render, at->dx + i % w, at->dy + i / w + 1);
}

/* Sub-image k's rows. */
static void put_subimage(FILE *out, const camera *c, const field_strata *t, uint32_t k,
                         const field_placement *at, sample_batch *b)
{
    film_sample s = field_shared_sample(c, (int)k, NULL);
    const double scale = field_strata_place(t, &s);
    const long n = (long)(c->crop_x1 - c->crop_x0) * (c->crop_y1 - c->crop_y0);
    for (long start = 0; start < n && !ferror(out); start += CAMERA_BATCH) {
        field_trace_pixels(c, s, scale, start, (int)(n - start < CAMERA_BATCH ? n - start : CAMERA_BATCH), b);
        for (int j = 0; j < b->n; j++)
            if (b->passed[j])
                put_row(out, c, s, start + j, b, j, at);
    }
}

int field_rays_write(FILE *out, const char *path, const camera *c, const field_placement *at,
                     int spp, l2p_error *err)
{
    sample_batch *b = malloc(sizeof *b);
    if (!b)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    fputs(c->dispersion ? "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,dir_x,dir_y,"
                          "dir_z,weight,wavelength_nm,image,image_x,image_y\n"
                        : "raster_x,raster_y,film_x,film_y,origin_x,origin_y,origin_z,dir_x,dir_y,"
                          "dir_z,weight,image,image_x,image_y\n", out);
    field_strata t;
    field_strata_count(c, &t);
    for (int k = 0; k < spp && !ferror(out); k++)
        put_subimage(out, c, &t, (uint32_t)k, &at[k], b);
    free(b);
    return ferror(out) ? l2p_fail(err, L2P_FAILED, path, 0, "write failed") : L2P_OK;
}
