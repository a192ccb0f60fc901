/* render --adaptive: a still's field render in two rounds (docs/adaptive.md). The first
   renders a quarter of the samples over the whole crop and measures each tile's error; the
   second renders the further sub-images each tile is given, over those tiles only. Every
   count is a multiple of the first round's, a power of two whose every block of sub-images
   holds the same share of each stratum (strata.c), so that each pixel's weights stay those
   of a uniform render of its tile's count. */
#include "field/field_files.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include "field/fieldtiles.h"
#include "image/develop.h"

/* The first round's count: the largest power of two at most a quarter of spp, at least 2. */
static int first_round(int spp)
{
    int n = 2;
    while (2 * n <= spp / 4)
        n *= 2;
    return n;
}

/* One round: its files built, rendered and developed, onto sums when given (an earlier
   round's, which this one then owns, also when it fails). */
typedef struct render_round {
    field_files files;
    field_developer dev;
    bool started;
} render_round;

static int run_round(const camera *c, const field_files_request *q, const povray_options *po,
                     int early, double *sums, render_round *r, l2p_error *err)
{
    int st = field_files_make(c, q, &r->files, err);
    if (st)
        free(sums);
    else if (!(st = field_develop_continue(&r->dev, &r->files.table, sums, err)))
        r->started = true;
    if (!st && early)
        st = field_develop_keep_early(&r->dev, early, err);
    if (!st)
        st = field_render_into(&r->files, q->jobs, po, &r->dev, err);
    return st;
}

static void round_free(render_round *r)
{
    if (r->started)
        field_develop_free(&r->dev);
    r->started = false;
    field_files_free(&r->files);
}

/* The picture from the sums of both rounds, each pixel's scaled in place to the picture's
   spp. */
static int write_picture(double *sums, const samplemap_header *h, const field_tiles *t,
                         const char *out, l2p_error *err)
{
    const long pixels = (long)t->width * t->height;
    const size_t stride = develop_sums_per_pixel(h);
    for (long i = 0; i < pixels; i++)
        for (size_t ch = 0; ch < stride; ch++)
            sums[stride * (size_t)i + ch] *= field_tiles_scale(t, i);
    samplemap map = {.header = *h};
    map.header.spp = t->spp;
    return develop_write_picture(&map, sums, out, err);
}

/* Both rounds as one map: render r of the second round numbered after the first's, its
   sub-image j after the first's; spp the picture's, each weight scaled to it (weights_of). */
typedef struct joined {
    field_map map;
    const render_round *one, *two;
    const field_tiles *tiles;
} joined;

static int joined_weights(const void *ctx, int k, float *weights, l2p_error *err)
{
    const joined *j = ctx;
    const int n1 = j->one->files.subimages;
    const field_map *from = k < n1 ? &j->one->files.table : &j->two->files.table;
    const int st = field_map_weights(from, k < n1 ? k : k - n1, weights, err);
    const field_piece *p = &j->map.piece[k];
    for (int i = 0; !st && i < p->w * p->h; i++) {
        const long in_crop = (long)(p->y0 + i / p->w) * j->tiles->width + p->x0 + i % p->w;
        weights[i] = (float)(weights[i] * field_tiles_scale(j->tiles, in_crop));
    }
    return st;
}

static int join(const render_round *one, const render_round *two, const field_tiles *t, joined *j,
                l2p_error *err)
{
    const field_map *a = &one->files.table, *b = two ? &two->files.table : NULL;
    const int n1 = a->subimages, n = n1 + (b ? b->subimages : 0);
    const int renders = a->renders + (b ? b->renders : 0);
    *j = (joined){.map = {.header = a->header, .subimages = n, .renders = renders,
                          .weights_of = joined_weights},
                  .one = one, .two = two, .tiles = t};
    field_map *m = &j->map;
    m->weights_ctx = j;
    m->header.spp = t->spp;
    m->width = malloc(sizeof *m->width * (size_t)renders);
    m->height = malloc(sizeof *m->height * (size_t)renders);
    m->at = malloc(sizeof *m->at * (size_t)n);
    m->band = calloc((size_t)n, sizeof *m->band);
    m->piece = malloc(sizeof *m->piece * (size_t)n);
    if (!m->width || !m->height || !m->at || !m->band || !m->piece)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    for (int r = 0; r < renders; r++) {
        const bool first = r < a->renders;
        m->width[r] = first ? a->width[r] : b->width[r - a->renders];
        m->height[r] = first ? a->height[r] : b->height[r - a->renders];
    }
    for (int k = 0; k < n; k++) {
        const bool first = k < n1;
        m->piece[k] = first ? (field_piece){k, 0, 0, t->width, t->height} : b->piece[k - n1];
        m->at[k] = first ? a->at[k] : b->at[k - n1];
        m->at[k].render += first ? 0 : a->renders;
    }
    return L2P_OK;
}

/* --rays: every rendered pixel of both rounds, weighted as the picture counts it. */
static int write_rays(const camera *c, const joined *j, outfile *csv, l2p_error *err)
{
    const int st = field_rays_write(csv->fp, csv->final_path, c, j->one->files.subimages,
                                    j->map.piece, j->tiles, j->map.at, j->map.subimages, err);
    return st ? st : outfile_finish(csv, err);
}

/* The kept work folder's map, PREFIX.map, a map of pieces that `develop` takes with the
   renders' pictures. It is dated `begun`, before the first round: `develop` warns of a
   picture older than its map, as one rendered from an earlier trace. */
static int write_map(const joined *j, const char *prefix, const struct timespec *begun,
                     l2p_error *err)
{
    char *path = malloc(strlen(prefix) + 8);
    if (!path)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    sprintf(path, "%s.map", prefix);
    outfile f = {0};
    int st = outfile_open(&f, path, err);
    if (!st)
        st = field_map_write_pieces(&f, &j->map, err);
    const struct timespec times[2] = {*begun, *begun};
    if (!st && futimens(fileno(f.fp), times) != 0)
        st = l2p_fail(err, L2P_FAILED, f.final_path, 0, "cannot set its time: %s", strerror(errno));
    if (!st && !(st = outfile_finish(&f, err)))
        st = outfile_commit(&f, err);
    outfile_discard(&f);
    free(path);
    return st;
}

int field_render_adaptive(const camera *c, const field_files_request *q, const povray_options *po,
                          const char *out, bool *too_fine, l2p_error *err)
{
    const int spp = c->samples.spp, first = first_round(spp);
    struct timespec begun;
    clock_gettime(CLOCK_REALTIME, &begun);
    /* The CSV and the kept map list both rounds, so the first round's files stay to the end,
       and the rounds share the memory kept for weights (fieldpass.h); else the first round's
       go once it is developed. */
    const bool listed = q->rays_csv || q->map_file;
    field_files_request q1 = *q;
    q1.pieces = NULL, q1.count = 0, q1.strata_samples = first;
    q1.map_file = false, q1.rays_csv = NULL;
    q1.weights_kept_bytes = listed ? q->weights_kept_bytes / 2 : q->weights_kept_bytes;
    render_round one = {0}, two = {0};
    field_tiles t = {0};
    field_piece *pieces = NULL;
    /* the first round's sub-images are the camera's first `first` */
    camera *c1 = malloc(sizeof *c1);
    int st = c1 ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    if (!st) {
        *c1 = *c;
        c1->samples.spp = first;
        st = run_round(c1, &q1, po, first / 2, NULL, &one, err);
        *too_fine = one.files.too_fine;
    }
    if (!st)
        st = field_tiles_allocate(&t, c->crop_x1 - c->crop_x0, c->crop_y1 - c->crop_y0,
                                  one.dev.sums, one.dev.early, first, spp, err);
    const long n2 = st ? 0 : field_tiles_pieces(&t, first, &pieces);
    if (n2 < 0)
        st = l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    /* The second round adds onto the first's sums; of the first, only its files, listed, stay. */
    const samplemap_header header = one.files.table.header;
    const int first_renders = one.files.renders;
    double *sums = one.started ? field_develop_take_sums(&one.dev) : NULL;
    if (one.started)
        field_develop_free(&one.dev), one.started = false;
    if (!listed)
        field_files_free(&one.files);
    const bool second = !st && n2 > 0;
    if (second) {
        field_files_request q2 = q1;
        q2.pieces = pieces, q2.count = (int)n2;
        q2.render_base = first_renders;
        povray_options po2 = *po;
        po2.file_name = "povray.r2";   /* the first round's logs stay */
        st = run_round(c, &q2, &po2, 0, sums, &two, err);
        sums = two.started ? two.dev.sums : NULL;
        *too_fine = two.files.too_fine;
    }
    if (!st)
        st = write_picture(sums, &header, &t, out, err);
    if (!second)
        free(sums);
    joined j = {0};
    if (!st && listed)
        st = join(&one, second ? &two : NULL, &t, &j, err);
    if (!st && q->rays_csv)
        st = write_rays(c, &j, q->rays_csv, err);
    if (!st && q->map_file)
        st = write_map(&j, q->prefix, &begun, err);
    field_map_free(&j.map);
    round_free(&one), round_free(&two);
    field_tiles_free(&t);
    free(pieces), free(c1);
    return st;
}
