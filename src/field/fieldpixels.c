/* A sub-image's pixels seen with its shared sample: their raster positions, exact rays and
   weights (fieldpixels.h). */
#include "field/fieldpixels.h"

#include <math.h>
#include "field/sobol.h"

void field_pixel_raster(const camera *c, film_sample s, long i, double *rx, double *ry)
{
    const int w = c->crop_x1 - c->crop_x0;
    *rx = c->crop_x0 + i % w + s.offset_x;
    *ry = c->crop_y0 + i / w + s.offset_y;
}

void field_piece_crop(const camera *c, const field_piece *p, camera *out)
{
    out->crop_x0 = c->crop_x0 + p->x0, out->crop_y0 = c->crop_y0 + p->y0;
    out->crop_x1 = out->crop_x0 + p->w, out->crop_y1 = out->crop_y0 + p->h;
}

film_sample field_shared_sample(const camera *c, int k, uint32_t *band)
{
    film_sample s = sobol_shared_sample(c->samples.seed, (uint32_t)k);
    uint32_t b = 0;
    if (c->dispersion) {
        const wavelength_sample w = sample_pattern_wavelength(&c->samples,
                                                              sample_pattern_shared(&c->samples), k);
        s.wavelength_nm = w.nm;
        b = (uint32_t)w.band;
    }
    if (band)
        *band = b;
    return s;
}

/* The film samples of crop pixels first .. first + n - 1 seen with shared sample s. */
static void pixel_samples(const camera *c, film_sample s, long first, int n, sample_batch *batch)
{
    batch->n = n;
    for (int k = 0; k < n; k++) {
        double rx, ry;
        field_pixel_raster(c, s, first + k, &rx, &ry);
        batch->film_point[k] = film_camera_from_raster(&c->film, rx, ry);
        batch->u[k] = s.pupil_u;
        batch->v[k] = s.pupil_v;
        batch->wavelength_nm[k] = s.wavelength_nm;
    }
}

void field_weigh_pixels(const camera *c, film_sample s, double weight_scale, long first, int n,
                        sample_batch *batch)
{
    vec3 direction[CAMERA_BATCH];
    pixel_samples(c, s, first, n, batch);
    camera_film_rays(c, batch, direction);
    for (int k = 0; k < n; k++)
        batch->weight[k] *= weight_scale;
}

void field_trace_pixels(const camera *c, film_sample s, double weight_scale, long first, int n,
                        sample_batch *batch)
{
    pixel_samples(c, s, first, n, batch);
    camera_trace_batch(c, batch);
    for (int k = 0; k < n; k++) {
        const ray *r = &batch->out[k];
        /* as with pixel sampling, a film point beyond the lens's reach is no sample */
        batch->passed[k] = batch->passed[k] && pupil_reaches(&c->pupil, batch->film_point[k]) &&
                           v3_isfinite(r->o) && v3_isfinite(r->d) && isfinite(batch->weight[k]);
        batch->weight[k] *= weight_scale;
    }
}
