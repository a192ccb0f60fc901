/* Adaptive field sampling's tiles: which sub-images render a pixel, and how many a tile gets. */
#include "field/fieldtiles.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

int field_tiles_samples_at(const field_tiles *t, long i)
{
    const long x = i % t->width, y = i / t->width;
    return t->samples[y / FIELD_TILE_PX * t->across + x / FIELD_TILE_PX];
}

double field_tiles_scale(const field_tiles *t, long i)
{
    return (double)t->spp / field_tiles_samples_at(t, i);
}

/* The pixels of tile (tx, ty): those of the crop's right and bottom edges may be fewer. */
static int tile_pixels(const field_tiles *t, int tx, int ty)
{
    const int w = t->width - tx * FIELD_TILE_PX, h = t->height - ty * FIELD_TILE_PX;
    return (w < FIELD_TILE_PX ? w : FIELD_TILE_PX) * (h < FIELD_TILE_PX ? h : FIELD_TILE_PX);
}

/* Each tile's RMS difference of the two estimates over its pixels and channels. */
static void spread(const field_tiles *t, const double *sums, const double *early, int first,
                   double *out)
{
    for (int i = 0; i < t->across * t->down; i++)
        out[i] = 0.0;
    for (int y = 0; y < t->height; y++)
        for (int x = 0; x < t->width; x++)
            for (int c = 0; c < 3; c++) {
                const size_t p = 3 * ((size_t)y * t->width + x) + c;
                const double d = sums[p] / first - early[p] / (first / 2);
                out[y / FIELD_TILE_PX * t->across + x / FIELD_TILE_PX] += d * d;
            }
    for (int ty = 0; ty < t->down; ty++)
        for (int tx = 0; tx < t->across; tx++) {
            const int i = ty * t->across + tx;
            out[i] = sqrt(out[i] / (3.0 * tile_pixels(t, tx, ty)));
        }
}

/* The counts for scale: scale times a tile's spread, rounded to a multiple of first within
   [first, most]; returns the mean count over the pixels. */
static double counts_for(field_tiles *t, const double *s, double scale, int first, int most)
{
    double pixels = 0.0;
    for (int ty = 0; ty < t->down; ty++)
        for (int tx = 0; tx < t->across; tx++) {
            const int i = ty * t->across + tx;
            const double n = s[i] > 0.0 ? round(scale * s[i] / first) * first : first;
            t->samples[i] = n < first ? first : n > most ? most : (int)n;
            pixels += (double)t->samples[i] * tile_pixels(t, tx, ty);
        }
    return pixels / ((double)t->width * t->height);
}

int field_tiles_allocate(field_tiles *t, int w, int h, const double *sums, const double *early,
                         int first, int budget, l2p_error *err)
{
    *t = (field_tiles){.width = w, .height = h, .across = (w + FIELD_TILE_PX - 1) / FIELD_TILE_PX,
                       .down = (h + FIELD_TILE_PX - 1) / FIELD_TILE_PX, .spp = budget};
    const int tiles = t->across * t->down, most = FIELD_TILE_MOST_ROUNDS * first;
    double *s = malloc(sizeof *s * (size_t)tiles);
    t->samples = malloc(sizeof *t->samples * (size_t)tiles);
    if (!s || !t->samples) {
        free(s);
        field_tiles_free(t);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    spread(t, sums, early, first, s);
    double least = INFINITY;
    for (int i = 0; i < tiles; i++)
        least = s[i] > 0.0 ? fmin(least, s[i]) : least;
    /* the scale that spends the budget, bisected between all tiles at first and all that
       spread at most (the mean count grows with it); a picture without spread gets first
       everywhere */
    double lo = 0.0, hi = isfinite(least) ? fmin(2.0 * most / least, 1e300) : 0.0;
    for (int i = 0; i < 60 && hi > 0.0; i++) {
        const double mid = 0.5 * (lo + hi);
        *(counts_for(t, s, mid, first, most) > budget ? &hi : &lo) = mid;
    }
    counts_for(t, s, lo, first, most);
    t->most = first;
    for (int i = 0; i < tiles; i++)
        t->most = t->samples[i] > t->most ? t->samples[i] : t->most;
    free(s);
    return L2P_OK;
}

/* The rectangles, in tiles, that cover the tiles sample k renders (their count above k) once:
   from each tile not yet covered, row by row, as far right as they go, then as far down as
   the whole row of them goes, at most FIELD_PIECE_TILES_HIGH tiles. *out grows as needed;
   returns the new count, or -1 out of memory. */
static long rectangles(const field_tiles *t, int k, unsigned char *used, field_piece **out,
                       long n, long *cap)
{
    const int across = t->across, down = t->down;
    memset(used, 0, (size_t)across * down);
    for (int ty = 0; ty < down; ty++)
        for (int tx = 0; tx < across; tx++) {
            if (used[ty * across + tx] || k >= t->samples[ty * across + tx])
                continue;
            int x1 = tx + 1, y1 = ty + 1;
            while (x1 < across && !used[ty * across + x1] && k < t->samples[ty * across + x1])
                x1++;
            for (bool whole = true; whole && y1 < down && y1 - ty < FIELD_PIECE_TILES_HIGH;
                 y1 += whole) {
                for (int x = tx; x < x1 && whole; x++)
                    whole = !used[y1 * across + x] && k < t->samples[y1 * across + x];
            }
            for (int y = ty; y < y1; y++)
                memset(used + y * across + tx, 1, (size_t)(x1 - tx));
            if (n == *cap) {
                field_piece *more = realloc(*out, sizeof **out * (size_t)(*cap = 2 * *cap + 64));
                if (!more)
                    return -1;
                *out = more;
            }
            const int x0 = tx * FIELD_TILE_PX, y0 = ty * FIELD_TILE_PX;
            const int xe = x1 * FIELD_TILE_PX < t->width ? x1 * FIELD_TILE_PX : t->width;
            const int ye = y1 * FIELD_TILE_PX < t->height ? y1 * FIELD_TILE_PX : t->height;
            (*out)[n++] = (field_piece){k, x0, y0, xe - x0, ye - y0};
        }
    return n;
}

/* Taller pieces first, then wider (the shelves they are packed on, fieldpack.c), then in
   their order. */
static int taller_first(const void *a, const void *b)
{
    const field_piece *p = a, *q = b;
    if (p->h != q->h)
        return p->h > q->h ? -1 : 1;
    if (p->w != q->w)
        return p->w > q->w ? -1 : 1;
    if (p->k != q->k)
        return p->k < q->k ? -1 : 1;
    if (p->y0 != q->y0)
        return p->y0 < q->y0 ? -1 : 1;
    return (p->x0 > q->x0) - (p->x0 < q->x0);
}

long field_tiles_pieces(const field_tiles *t, int first, field_piece **out)
{
    unsigned char *used = malloc((size_t)t->across * t->down);
    long n = 0, cap = 0;
    *out = NULL;
    for (int k = first; used && n >= 0 && k < t->most; k++)
        n = rectangles(t, k, used, out, n, &cap);
    free(used);
    if (!used || n < 0) {
        free(*out);
        *out = NULL;
        return -1;
    }
    if (n > 0)
        qsort(*out, (size_t)n, sizeof **out, taller_first);
    return n;
}

void field_tiles_free(field_tiles *t)
{
    free(t->samples);
    t->samples = NULL;
}
