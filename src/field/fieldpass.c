#include "field/fieldpass.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "field/fieldpixels.h"

int field_weights_kept_bytes(double *bytes, l2p_error *err)
{
    static const char name[] = "LENS2POV_FIELD_WEIGHTS_MB";
    const char *text = getenv(name);
    char *end = NULL;
    const double mb = text ? strtod(text, &end) : FIELD_WEIGHTS_KEPT_MB;
    *bytes = FIELD_WEIGHTS_KEPT_MB * 1048576.0;
    if (text && (end == text || *end || !(mb >= 0.0) || !isfinite(mb)))
        return l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "%s in the environment is '%s', not a "
                        "number of MB, 0 or more", name, text);
    *bytes = mb * 1048576.0;
    return L2P_OK;
}

static long long count_runs(const float *weights, long long pixels)
{
    long long runs = 0;
    for (long long i = 0; i < pixels; i++)
        runs += weights[i] > 0 && (i == 0 || !(weights[i - 1] > 0));
    return runs;
}

/* The runs of passing pixels of weights into out, runs of them. */
static int runs_of(const float *weights, long long pixels, long long runs, field_pass *out,
                   l2p_error *err)
{
    if (runs == 0)
        return L2P_OK;
    if (!(out->runs = malloc(sizeof *out->runs * 2 * (size_t)runs)))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    long long *r = out->runs;
    for (long long i = 0; i < pixels; i++) {
        if (weights[i] > 0 && (i == 0 || !(weights[i - 1] > 0)))
            *r++ = i;
        if (weights[i] > 0 && (i + 1 == pixels || !(weights[i + 1] > 0)))
            *r++ = i + 1;
    }
    out->run_count = runs;
    return L2P_OK;
}

int field_pass_of(float **weights, long long pixels, film_sample s, double weight_scale,
                  bool keep, field_pass *out, l2p_error *err)
{
    *out = (field_pass){.sample = s, .weight_scale = weight_scale};
    /* runs of two long longs each that would take more than the floats: the floats */
    const long long runs = keep ? 0 : count_runs(*weights, pixels);
    if (!keep && 4 * runs <= pixels)
        return runs_of(*weights, pixels, runs, out, err);
    out->weights = *weights;
    *weights = NULL;
    return L2P_OK;
}

int field_pass_weights(const camera *c, const field_pass *p, float *weights, l2p_error *err)
{
    const long long pixels = (long long)(c->crop_x1 - c->crop_x0) * (c->crop_y1 - c->crop_y0);
    if (p->weights) {
        memcpy(weights, p->weights, sizeof *weights * (size_t)pixels);
        return L2P_OK;
    }
    memset(weights, 0, sizeof *weights * (size_t)pixels);
    if (p->run_count == 0)
        return L2P_OK;
    sample_batch *batch = malloc(sizeof *batch);
    if (!batch)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (long long r = 0; r < p->run_count; r++) {
        const long long end = p->runs[2 * r + 1];
        for (long long i = p->runs[2 * r]; i < end; i += CAMERA_BATCH) {
            const int n = (int)(end - i < CAMERA_BATCH ? end - i : CAMERA_BATCH);
            field_weigh_pixels(c, p->sample, p->weight_scale, (long)i, n, batch);
            for (int k = 0; k < n; k++)
                weights[i + k] = (float)batch->weight[k];
        }
    }
    free(batch);
    return L2P_OK;
}

void field_pass_free(field_pass *p)
{
    free(p->weights), free(p->runs);
    memset(p, 0, sizeof *p);
}
