/* Packing a field render's sub-images into POV-Ray renders (fieldpack.h). */
#include "field/fieldpack.h"

#include <math.h>
#include <stdlib.h>
#include "field/field_render.h"
#include "field/subimage.h"

/* n sub-images of w x h in a grid of nx columns: the render's final size. */
static void grid_size(int n, int nx, int w, int h, int *rw, int *rh)
{
    *rw = field_render_size(nx * w);
    *rh = field_render_size((n + nx - 1) / nx * h);
}

/* How far a picture of w x h is from square: POV-Ray's grid cells are a tenth of each side,
   and a face is a candidate in every cell its UV box touches, so square cells are straddled by
   fewer faces. */
static double oblong(int w, int h)
{
    return fabs(log((w + 1.0) / (h + 1.0)));
}

/* The grid of n sub-images (its columns) with the smallest picture no larger than the n lone
   sub-images' would be (its sides 2^a - 1: every UV a short binary fraction), of those the
   squarest; 0 when none is. A power of two always has one, and POV-Ray renders only the grid
   (write_ini): the rest of the picture costs memory, not time. */
static int grid_of(int n, int w, int h)
{
    const double lone = (field_render_size(w) + 1.0) * (field_render_size(h) + 1.0);
    double best = INFINITY, best_oblong = INFINITY;
    int best_nx = 0;
    for (int nx = 1; nx <= n; nx++) {
        int rw, rh;
        grid_size(n, nx, w, h, &rw, &rh);
        const double area = (rw + 1.0) * (rh + 1.0), shape = oblong(rw, rh);
        if (area > n * lone || area > best || (area == best && shape >= best_oblong))
            continue;
        best = area, best_oblong = shape, best_nx = nx;
    }
    return best_nx;
}

/* What a render of n sub-images (in a grid of nx columns) costs each of them, in seconds: the
   frame's overhead, frame_s of POV-Ray's waiting, which the other jobs' work partly fills
   (frame_s / jobs); its picture, written by POV-Ray and read back, PICTURE_S a pixel used or
   not; and POV-Ray's face search, SEARCH_S a face of the render for each pixel (it scans the
   faces in order up to the first that holds the pixel; docs/povray.md). More sub-images a
   render share its overhead and pay more search. */
#define SEARCH_S 4e-11
#define PICTURE_S 4e-8

static double cost_per_sub(int n, int nx, int w, int h, double faces_per_sub, int jobs,
                           double frame_s)
{
    int rw, rh;
    grid_size(n, nx, w, h, &rw, &rh);
    const double picture = (rw + 1.0) * (rh + 1.0);
    return (frame_s / jobs + picture * PICTURE_S) / n + (double)w * h * SEARCH_S * n * faces_per_sub;
}

/* How many renders: as many as the count of sub-images a render costs least with (of the
   counts that have a grid, that an equal share for every job allows and whose first
   sub-images stay within FIELD_FACES_PER_RENDER and FIELD_PIXELS_PER_RENDER); at least as
   many as all the faces need at
   FIELD_FACES_PER_RENDER a render; a multiple of the jobs, so that the jobs get equal
   shares. */
static int render_count(const field_packed *subs, int spp, int w, int h, int jobs, long long all,
                        double frame_s)
{
    const double faces_per_sub = fmax(1.0, (double)all / spp);
    const int most = (spp + jobs - 1) / jobs;
    long long faces = 0;
    int count = 1;
    double least = INFINITY;
    for (int n = 1; n <= spp; n++) {
        faces += subs[n - 1].faces;
        if (n > 1 && (faces > FIELD_FACES_PER_RENDER || n > most))
            break;
        const int nx = grid_of(n, w, h);
        int rw, rh;
        if (nx)
            grid_size(n, nx, w, h, &rw, &rh);
        if (n > 1 && nx && (rw + 1.0) * (rh + 1.0) > FIELD_PIXELS_PER_RENDER)
            break;
        const double cost = nx ? cost_per_sub(n, nx, w, h, faces_per_sub, jobs, frame_s) : INFINITY;
        if (cost < least)
            least = cost, count = n;
    }
    long long renders = (spp + count - 1) / count;
    if (renders < (all + FIELD_FACES_PER_RENDER - 1) / FIELD_FACES_PER_RENDER)
        renders = (all + FIELD_FACES_PER_RENDER - 1) / FIELD_FACES_PER_RENDER;
    renders = (renders + jobs - 1) / jobs * jobs;
    return (int)(renders < spp ? renders : spp);
}

int field_pack_count_estimate(int spp, int w, int h, int jobs, double faces_per_sub,
                              double frame_s)
{
    field_packed *subs = calloc((size_t)spp, sizeof *subs);
    if (!subs)
        return spp;
    for (int i = 0; i < spp; i++)
        subs[i].faces = (long long)ceil(faces_per_sub);
    const int count = render_count(subs, spp, w, h, jobs, (long long)spp * subs[0].faces, frame_s);
    free(subs);
    return count;
}

/* Groups consecutive sub-images into renders, spread evenly over render_count of them, all
   with one grid and size since a POV-Ray process renders all its renders at one size
   (assign_jobs); a render holds at most FIELD_FACES_PER_RENDER faces, or one sub-image (more
   renders then follow). Returns the number of renders. */
int field_pack_grid(field_packed *subs, int spp, int w, int h, int jobs, double frame_s,
                field_render_plan *plans)
{
    long long all = 0;
    for (int k = 0; k < spp; k++)
        all += subs[k].faces;
    const int even = render_count(subs, spp, w, h, jobs, all, frame_s);
    const int grid_n = (spp + even - 1) / even;
    int grid_nx = grid_of(grid_n, w, h);
    if (!grid_nx)   /* fewer than a count that has a grid: the shortest row */
        grid_nx = grid_n;
    int renders = 0;
    for (int first = 0; first < spp; renders++) {
        const int target = spp / even + (renders < spp % even);
        long long faces = subs[first].faces;
        int n = 1;
        while (n < target && first + n < spp &&
               faces + subs[first + n].faces <= FIELD_FACES_PER_RENDER)
            faces += subs[first + n++].faces;
        field_render_plan *p = &plans[renders];
        grid_size(grid_n, grid_nx, w, h, &p->width, &p->height);
        p->used_width = grid_nx * w, p->used_height = (grid_n + grid_nx - 1) / grid_nx * h;
        p->first = first, p->count = n, p->faces = faces;
        for (int i = 0; i < n; i++)
            subs[first + i].at = (field_placement){renders, i % grid_nx * w, i / grid_nx * h};
        first += n;
    }
    return renders;
}

/* The faces a render of pieces takes: with R renders of F faces each out of all, over P
   pixels, the frames' overhead R frame_s / jobs and the face search P F SEARCH_S (as
   cost_per_sub weighs them) add up least at F = sqrt(all frame_s / (jobs P SEARCH_S)); as
   many renders as that needs, rounded up to a multiple of the jobs, share the faces
   equally, at most FIELD_FACES_PER_RENDER each. */
static long long faces_per_render(long long all, double pixels, int jobs, double frame_s)
{
    const double best = sqrt(all * frame_s / (jobs * fmax(pixels, 1.0) * SEARCH_S));
    const double renders = ceil(all / fmax(best, 1.0) / jobs) * jobs;
    const long long each = (long long)ceil(all / renders);
    return each < 1 ? 1 : each < FIELD_FACES_PER_RENDER ? each : FIELD_FACES_PER_RENDER;
}

/* Pieces (adaptive sampling's second round, taller first: field_tiles_pieces) on shelves,
   left to right across a render as wide as the crop's, each shelf as tall as its first piece;
   a render takes pieces up to faces_per_render and to a height that shares the pieces'
   pixels equally; every render has the size and the rendered rows and columns of the
   largest (assign_jobs runs a job's renders as the frames of one POV-Ray run). Returns the
   number of renders. */
int field_pack_shelves(field_packed *subs, int n, int crop_w, int jobs, double frame_s,
                        field_render_plan *plans)
{
    long long all = 0;
    double pixels = 0.0;
    for (int k = 0; k < n; k++)
        all += subs[k].faces, pixels += (double)subs[k].piece.w * subs[k].piece.h;
    const long long each = faces_per_render(all, pixels, jobs, frame_s);
    const int width = field_render_size(crop_w);
    /* the renders' height: their share of the pieces' pixels, a tenth more for what the
       shelves leave, or the tallest piece; every render is rendered to the tallest */
    const double renders = ceil((double)all / each);
    const double share = ceil(1.1 * pixels / renders / width);
    const double highest = FIELD_PIXELS_PER_RENDER / (width + 1.0) - 1;
    const int high = (int)fmin(fmax(share, n > 0 ? subs[0].piece.h : 1), highest);
    int r = -1, x = 0, y = 0, shelf = 0, tallest = 0;
    for (int k = 0; k < n; k++) {
        const field_piece *p = &subs[k].piece;
        const long long faces = subs[k].faces;
        if (x + p->w > width)   /* the next shelf */
            y += shelf, x = 0, shelf = 0;
        if (r < 0 || (plans[r].faces > 0 && plans[r].faces + faces > each) || y + p->h > high) {
            plans[++r] = (field_render_plan){.first = k};
            x = y = shelf = 0;
        }
        subs[k].at = (field_placement){r, x, y};
        x += p->w;
        shelf = p->h > shelf ? p->h : shelf;
        field_render_plan *pl = &plans[r];
        pl->count++, pl->faces += faces;
        pl->used_width = x > pl->used_width ? x : pl->used_width;
        pl->used_height = y + shelf > pl->used_height ? y + shelf : pl->used_height;
        tallest = pl->used_height > tallest ? pl->used_height : tallest;
    }
    /* a POV-Ray run renders all its frames with the first one's rows and columns */
    int widest = 0;
    for (int i = 0; i <= r; i++)
        widest = plans[i].used_width > widest ? plans[i].used_width : widest;
    for (int i = 0; i <= r; i++) {
        plans[i].width = width, plans[i].height = field_render_size(tallest);
        plans[i].used_width = widest, plans[i].used_height = tallest;
    }
    return r + 1;
}
