/* With dispersion, the pupils that samples are drawn from at each wavelength (spectral.h). */
#include "camera/spectral.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include "base/cores.h"
#include "base/workers.h"
#include "optics/spectrum.h"

/* The lens at wavelength nm, a copy of l. */
static int copy_at(lens *at, const lens *l, double nm, l2p_error *err)
{
    if (lens_copy(at, l))
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    lens_at_wavelength(at, nm);
    return L2P_OK;
}

/* Covers pupil p for the lens at wavelength nm (pupil_cover). */
static int cover_at(pupil *p, const lens *l, double nm, l2p_error *err)
{
    lens at;
    int st = copy_at(&at, l, nm, err);
    if (!st) {
        pupil_cover(p, &at);
        lens_free(&at);
    }
    return st;
}

/* Fits pupil p to the lens at wavelength nm over the film's reach (pupil_fit). */
static int fit_at(pupil *p, const lens *l, double nm, double reach_mm, l2p_error *err)
{
    lens at;
    int st = copy_at(&at, l, nm, err);
    if (!st) {
        pupil_fit(p, &at, reach_mm);
        lens_free(&at);
    }
    return st;
}

static double spectral_nm(int i, int count)
{
    return SPECTRUM_MIN_NM + i * (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) / (count - 1);
}

/* The ratio of the area of pupil b's region to that of a's (the same pupil after and before
   pupil_cover), over the film: each node weighted by its radius, as the film's area is. A
   region grown only near the reach, where it is small and few film points lie, counts little. */
static double grown_area(const pupil *a, const pupil *b)
{
    double sa = 0.0, sb = 0.0;
    for (int j = 0; j <= PUPIL_NODES; j++) {
        const double r = j * a->node_spacing_mm;
        pupil_shape ea, eb;
        if (!pupil_shape_at(a, r, &ea) || !pupil_shape_at(b, r, &eb))
            continue;
        for (int i = 0; i <= PUPIL_KNOTS; i++)
            sa += r * ea.radius_mm[i] * ea.radius_mm[i], sb += r * eb.radius_mm[i] * eb.radius_mm[i];
    }
    return sa > 0.0 ? sb / sa : 1.0;
}

/* Spectral pupils are fitted when covering the spectrum grows the region more than this: a
   sample then passes less than two times in three as often as with a region for its own
   wavelength. */
#define SPECTRAL_WORTH 1.5

/* The spectral pupils' fits, shared by the threads that make them. */
typedef struct spectral_job {
    camera *c;
    int count;
    atomic_int next;
    atomic_int status;
    double growth[CAMERA_SPECTRAL_PUPILS_MAX];   /* each pupil's growth in the covering */
    l2p_error err;                              /* the first failure's */
} spectral_job;

/* Pupil i fitted at its wavelength in the plane of c->pupil, then covered at its neighbours'. */
static int fit_one_spectral(spectral_job *j, int i, pupil *own, l2p_error *err)
{
    camera *c = j->c;
    pupil *p = &c->spectral[i];
    *p = c->pupil;
    int st = fit_at(p, &c->lens, spectral_nm(i, j->count), 0.5 * c->film.diagonal_mm, err);
    *own = *p;
    if (!st && i > 0)
        st = cover_at(p, &c->lens, spectral_nm(i - 1, j->count), err);
    if (!st && i + 1 < j->count)
        st = cover_at(p, &c->lens, spectral_nm(i + 1, j->count), err);
    if (!st)
        j->growth[i] = grown_area(own, p);
    return st;
}

static void *spectral_worker(void *arg)
{
    spectral_job *j = arg;
    pupil *own = malloc(sizeof *own);
    l2p_error err;
    int st = own ? L2P_OK : l2p_fail(&err, L2P_FAILED, NULL, 0, "out of memory");
    for (int i; !st && (i = atomic_fetch_add(&j->next, 1)) < j->count;)
        st = fit_one_spectral(j, i, own, &err);
    int none = L2P_OK;
    if (st && atomic_compare_exchange_strong(&j->status, &none, st))
        j->err = err;
    free(own);
    return NULL;
}

/* Fits count spectral pupils, each at its wavelength in the plane of c->pupil and covered at
   its neighbours', on every core (the fits are independent); *growth is the most any grew in
   the covering (grown_area). */
static int fit_spectral(camera *c, int count, double *growth, l2p_error *err)
{
    spectral_job *j = malloc(sizeof *j);
    pupil *pupils = malloc(sizeof *pupils * (size_t)count);
    if (!j || !pupils) {
        free(j);
        free(pupils);
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    }
    free(c->spectral);
    c->spectral = pupils;
    c->spectral_count = count;
    j->c = c;
    j->count = count;
    atomic_init(&j->next, 0);
    atomic_init(&j->status, L2P_OK);
    workers_run(spectral_worker, j, cores_online() < count ? cores_online() : count);
    const int st = atomic_load(&j->status);
    *growth = 1.0;
    for (int i = 0; !st && i < count; i++)
        *growth = fmax(*growth, j->growth[i]);
    if (st)
        *err = j->err;
    free(j);
    return st;
}

/* With dispersion the pupil fitted at the d line also covers the two ends of the spectrum
   (between them the passing regions move little and smoothly: pupil_cover); it bounds the
   film's reach. Samples are drawn from spectral pupils instead, when that grows the region
   much: through a small stop the passing region moves with the wavelength by more than its
   own size, and one region for the whole spectrum passes a small share of the samples. Their
   count starts at CAMERA_SPECTRAL_PUPILS; where covering its neighbours still grows a region
   too much, the neighbours are brought nearer, once: the growth in width is about in
   proportion to their spacing. */
int camera_cover_spectrum(camera *c, l2p_error *err)
{
    pupil *d_line = malloc(sizeof *d_line);
    if (!d_line)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    *d_line = c->pupil;
    int st = cover_at(&c->pupil, &c->lens, SPECTRUM_MIN_NM, err);
    if (!st)
        st = cover_at(&c->pupil, &c->lens, SPECTRUM_MAX_NM, err);
    const bool worth = !st && grown_area(d_line, &c->pupil) > SPECTRAL_WORTH;
    free(d_line);
    double growth;
    if (!worth || (st = fit_spectral(c, CAMERA_SPECTRAL_PUPILS, &growth, err)) ||
        !(growth > SPECTRAL_WORTH))
        return st;
    const double spacing = (sqrt(SPECTRAL_WORTH) - 1.0) / (sqrt(growth) - 1.0);
    int count = CAMERA_SPECTRAL_PUPILS;
    while (count < CAMERA_SPECTRAL_PUPILS_MAX &&
           (double)(CAMERA_SPECTRAL_PUPILS - 1) / (count - 1) > spacing)
        count = 2 * count - 1;
    return fit_spectral(c, count, &growth, err);
}

const pupil *camera_pupil_at(const camera *c, double nm)
{
    if (!c->spectral)
        return &c->pupil;
    const int last = c->spectral_count - 1;
    const double t = (nm - SPECTRUM_MIN_NM) / (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) * last;
    /* nearest, clamped before the conversion (NaN takes the first) */
    return &c->spectral[t > 0.0 ? (int)(fmin(t, last) + 0.5) : 0];
}

