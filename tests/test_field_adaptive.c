/* Adaptive field sampling (src/field/fieldtiles.c, field_adaptive.c): the counts each tile gets
   after the first round, the pieces of the second, and the strata that keep every tile's
   weights those of a uniform render of its count. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include "field/fieldpixels.h"
#include "field/fieldtiles.h"
#include "field/strata.h"
#include "support.h"

/* A crop of W x H (5 x 3 tiles, the last column and row partial) whose tile (tx, ty) has the
   two estimates differ by d(tx, ty) in every channel of every pixel: no two tiles alike, so
   that the mean count moves by one tile's step at a time. */
enum { W = 37, H = 19, ACROSS = 5, DOWN = 3, FIRST = 8 };

static double difference_of(int tx, int ty)
{
    const int shuffled = (7 * (tx + ACROSS * ty) + 3) % (ACROSS * DOWN);   /* 7 and 15 coprime */
    return 4e-4 * pow(1 + shuffled, 1.7);
}

static void estimates(double *sums, double *early, double (*d)(int, int))
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                const size_t i = 3 * ((size_t)y * W + x) + c;
                const double e = 0.3 + 0.01 * c;   /* the first half's estimate */
                early[i] = e * (FIRST / 2);
                sums[i] = (e + d(x / FIELD_TILE_PX, y / FIELD_TILE_PX)) * FIRST;
            }
}

static int tile_pixels(int tx, int ty)
{
    const int w = W - tx * FIELD_TILE_PX < FIELD_TILE_PX ? W - tx * FIELD_TILE_PX : FIELD_TILE_PX;
    const int h = H - ty * FIELD_TILE_PX < FIELD_TILE_PX ? H - ty * FIELD_TILE_PX : FIELD_TILE_PX;
    return w * h;
}

/* The counts are multiples of the first round's, from it to FIELD_TILE_MOST_ROUNDS times it;
   their mean over the pixels is the budget to within one tile's step; and one scale lambda
   gives every tile its count as lambda times its difference rounded to a multiple of the
   first round's, or the bound it is held at (Neyman). */
Test(field_adaptive, counts_follow_the_spread_and_spend_the_budget)
{
    static double sums[3 * W * H], early[3 * W * H];
    estimates(sums, early, difference_of);
    static const int BUDGETS[] = {16, 32, 64};
    const int top = FIELD_TILE_MOST_ROUNDS * FIRST;
    for (int b = 0; b < 3; b++) {
        field_tiles t;
        l2p_error err;
        cr_assert_eq(field_tiles_allocate(&t, W, H, sums, early, FIRST, BUDGETS[b], &err), L2P_OK);
        cr_assert(t.across == ACROSS && t.down == DOWN && t.spp == BUDGETS[b]);
        double mean = 0.0, lambda_lo = 0.0, lambda_hi = INFINITY;
        int most = 0;
        for (int ty = 0; ty < DOWN; ty++)
            for (int tx = 0; tx < ACROSS; tx++) {
                const int n = t.samples[ty * ACROSS + tx];
                const double d = difference_of(tx, ty);
                cr_expect(n % FIRST == 0 && n >= FIRST && n <= top, "tile %d,%d: %d", tx, ty, n);
                mean += (double)n * tile_pixels(tx, ty) / (W * H);
                most = n > most ? n : most;
                /* lambda d rounds to n unless n is a bound, which it may pass */
                if (n > FIRST)
                    lambda_lo = fmax(lambda_lo, (n - FIRST / 2.0) / d);
                if (n < top)
                    lambda_hi = fmin(lambda_hi, (n + FIRST / 2.0) / d);
            }
        cr_expect(t.most == most);
        cr_expect(fabs(mean - BUDGETS[b]) <= (double)FIRST * 64 / (W * H) + 1e-9,
                  "budget %d: mean %g", BUDGETS[b], mean);
        cr_expect(lambda_lo <= lambda_hi * (1 + 1e-12), "budget %d: no one scale gives the counts "
                  "(%g > %g)", BUDGETS[b], lambda_lo, lambda_hi);
        cr_expect(most > FIRST && t.samples[0] < most, "budget %d: the counts do not differ", BUDGETS[b]);
        field_tiles_free(&t);
    }
}

static double no_difference(int tx, int ty)
{
    (void)tx, (void)ty;
    return 0.0;
}

/* Where the two estimates agree everywhere, no tile is worth more: the first round is all. */
Test(field_adaptive, a_picture_without_spread_stays_at_the_first_round)
{
    static double sums[3 * W * H], early[3 * W * H];
    estimates(sums, early, no_difference);
    field_tiles t;
    l2p_error err;
    cr_assert_eq(field_tiles_allocate(&t, W, H, sums, early, FIRST, 64, &err), L2P_OK);
    for (int i = 0; i < ACROSS * DOWN; i++)
        cr_expect_eq(t.samples[i], FIRST);
    cr_expect_eq(t.most, FIRST);
    field_piece *p;
    cr_expect_eq(field_tiles_pieces(&t, FIRST, &p), 0);
    free(p);
    field_tiles_free(&t);
}

/* The second round's pieces: rectangles of whole tiles (cut at the crop's right and bottom
   edges), each seen with one sample k; every tile is in exactly one piece of each of its
   samples FIRST .. n - 1, and in none of a sample at or above its count; taller pieces come
   first, then wider. The scale on a pixel's weights is the budget over its tile's count. */
Test(field_adaptive, pieces_cover_each_tile_once_a_further_sample)
{
    int counts[ACROSS * DOWN];
    field_tiles t = {.width = W, .height = H, .across = ACROSS, .down = DOWN, .samples = counts,
                     .most = 5 * FIRST, .spp = 24};
    for (int i = 0; i < ACROSS * DOWN; i++)
        counts[i] = FIRST * (1 + (i * 7) % 5);
    field_piece *p;
    const long n = field_tiles_pieces(&t, FIRST, &p);
    cr_assert_gt(n, 0);
    static int seen[ACROSS * DOWN][5 * FIRST];
    long tile_samples = 0;
    for (long j = 0; j < n; j++) {
        const field_piece *q = &p[j];
        cr_assert(q->x0 % FIELD_TILE_PX == 0 && q->y0 % FIELD_TILE_PX == 0 && q->w > 0 && q->h > 0 &&
                  q->x0 + q->w <= W && q->y0 + q->h <= H, "piece %ld: %d,%d %dx%d", j, q->x0, q->y0,
                  q->w, q->h);
        cr_assert((q->w % FIELD_TILE_PX == 0 || q->x0 + q->w == W) &&
                  (q->h % FIELD_TILE_PX == 0 || q->y0 + q->h == H), "piece %ld cuts a tile", j);
        cr_assert(q->k >= FIRST && q->k < t.most);
        if (j > 0)
            cr_expect(p[j - 1].h > q->h || (p[j - 1].h == q->h && p[j - 1].w >= q->w),
                      "piece %ld is taller or wider than the one before", j);
        for (int y = q->y0; y < q->y0 + q->h; y += FIELD_TILE_PX)
            for (int x = q->x0; x < q->x0 + q->w; x += FIELD_TILE_PX) {
                const int tile = y / FIELD_TILE_PX * ACROSS + x / FIELD_TILE_PX;
                cr_assert(q->k < counts[tile], "piece %ld: sample %d in tile %d of %d", j, q->k, tile,
                          counts[tile]);
                seen[tile][q->k]++;
                tile_samples++;
            }
    }
    long expected = 0;
    for (int i = 0; i < ACROSS * DOWN; i++) {
        expected += counts[i] - FIRST;
        for (int k = FIRST; k < counts[i]; k++)
            cr_expect_eq(seen[i][k], 1, "tile %d, sample %d", i, k);
    }
    cr_expect_eq(tile_samples, expected);
    cr_expect_lt(n, expected, "no two tiles of a sample were joined");
    for (long i = 0; i < (long)W * H; i++) {
        const int tile = (int)(i / W / FIELD_TILE_PX * ACROSS + i % W / FIELD_TILE_PX);
        cr_expect(field_tiles_scale(&t, i) == 24.0 / counts[tile]);
    }
    free(p);
}

/* A tile's count is a multiple of the first round's; for its pixels to be weighted as a
   uniform render of that count, every block of FIRST shared samples (from 0 on) must hold the
   same share of the ring as the first, whatever the seed; then the strata's scale is the
   same for every count. Checked where the strata are on: the stop-image and rear pupils of
   the double-Gauss and the telephoto, at full aperture and f/8, seeds 1 to 8, 64 blocks. */
Test(field_adaptive, every_block_of_the_first_round_holds_its_strata)
{
    static const char *const LENSES[] = {"dgauss.50mm", "telephoto.250mm"};
    static const pupil_kind PUPILS[] = {PUPIL_STOP_IMAGE, PUPIL_REAR};
    static const double F_NUMBERS[] = {NAN, 8.0};
    int on = 0;
    for (int l = 0; l < 2; l++)
        for (int p = 0; p < 2; p++)
            for (int f = 0; f < 2; f++)
                for (uint64_t seed = 1; seed <= 8; seed++) {
                    camera_options o;
                    camera_options_default(&o);
                    o.width = 32, o.height = 24, o.spp = 64, o.seed = seed;
                    o.pupil = PUPILS[p], o.f_number = F_NUMBERS[f];
                    o.focus_distance_units = 3.0;
                    o.dispersion = DISPERSION_OFF;
                    camera c;
                    test_camera(&c, LENSES[l], &o);
                    field_strata t;
                    field_strata_count(&c, 16, &t);
                    if (t.on) {
                        on++;
                        for (int b = 0; b < 64; b++) {
                            int ring = 0;
                            for (int k = 16 * b; k < 16 * (b + 1); k++)
                                ring += field_strata_in_ring(&t, field_shared_sample(&c, k, NULL));
                            cr_expect_eq(ring, t.ring_count, "%s, seed %d, block %d: %d in the ring, "
                                         "not %d", LENSES[l], (int)seed, b, ring, t.ring_count);
                        }
                    }
                    camera_free(&c);
                }
    cr_assert(on >= 32, "the strata were on in %d cases only", on);
}
