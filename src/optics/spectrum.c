#include "optics/spectrum.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>

/* exp(-(x - mu)^2 / (2 s^2)) with s = s_below for x < mu, s_above beyond. */
static double lobe(double x, double mu, double s_below, double s_above)
{
    const double t = (x - mu) / (x < mu ? s_below : s_above);
    return exp(-0.5 * t * t);
}

void spectrum_cie1931_xyz(double nm, double xyz[3])
{
    xyz[0] = 1.056 * lobe(nm, 599.8, 37.9, 31.0) + 0.362 * lobe(nm, 442.0, 16.0, 26.7) -
             0.065 * lobe(nm, 501.1, 20.4, 26.2);
    xyz[1] = 0.821 * lobe(nm, 568.8, 46.9, 40.5) + 0.286 * lobe(nm, 530.9, 16.3, 31.1);
    xyz[2] = 1.217 * lobe(nm, 437.0, 11.8, 36.0) + 0.681 * lobe(nm, 459.0, 26.0, 13.8);
}

/* XYZ to linear sRGB, IEC 61966-2-1 (the inverse of its sRGB-to-XYZ matrix, 4 digits). */
static const double SRGB_FROM_XYZ[3][3] = {
    {3.2406, -1.5372, -0.4986},
    {-0.9689, 1.8758, 0.0415},
    {0.0557, -0.2040, 1.0570},
};

void spectrum_linear_srgb(double nm, double rgb[3])
{
    double xyz[3];
    spectrum_cie1931_xyz(nm, xyz);
    for (int c = 0; c < 3; c++)
        rgb[c] = SRGB_FROM_XYZ[c][0] * xyz[0] + SRGB_FROM_XYZ[c][1] * xyz[1] +
                 SRGB_FROM_XYZ[c][2] * xyz[2];
}

/* The integrals, tabulated once on a fine grid: cell i is [grid(i), grid(i + 1)]. p is taken
   constant over a cell (its mean by the trapezoid rule), so P is linear within a cell and P^-1
   exact; rgb's integrals are the trapezoid rule's, linear within a cell too. */
enum { CELLS = 1600 };   /* a quarter nanometre */
static double p_integral[CELLS + 1];          /* P, 0 .. 1 */
static double rgb_integral[3][CELLS + 1];     /* of rgb_c, from SPECTRUM_MIN_NM */
/* P^-1 at u = j / INVERSES, interpolated linearly between: a sample's wavelength in a few
   operations. It is within 0.07 nm of P^-1 for u in [0.001, 0.999]; in the first and last
   thousandth, where the observer is nearly 0 and P^-1 steep, the draw is nearly uniform in
   wavelength instead. The band weights are integrals between wavelengths found by this same
   function, so they stay those of the density actually drawn. */
enum { INVERSES = 4096 };
static double inverse_nm[INVERSES + 1];
static pthread_once_t tabulated = PTHREAD_ONCE_INIT;
static atomic_bool ready;

static void tabulate(void);

static void need_tables(void)
{
    if (!atomic_load_explicit(&ready, memory_order_acquire))
        pthread_once(&tabulated, tabulate);
}

static double grid_nm(int i)
{
    return SPECTRUM_MIN_NM + (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) * i / CELLS;
}

static void tabulate(void)
{
    const double h = (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) / CELLS;
    double xyz[3], rgb[3], last_p, last_rgb[3];
    spectrum_cie1931_xyz(grid_nm(0), xyz);
    spectrum_linear_srgb(grid_nm(0), last_rgb);
    last_p = xyz[0] + xyz[1] + xyz[2];
    for (int i = 1; i <= CELLS; i++) {
        spectrum_cie1931_xyz(grid_nm(i), xyz);
        spectrum_linear_srgb(grid_nm(i), rgb);
        const double p = xyz[0] + xyz[1] + xyz[2];
        p_integral[i] = p_integral[i - 1] + 0.5 * h * (p + last_p);
        last_p = p;
        for (int c = 0; c < 3; c++) {
            rgb_integral[c][i] = rgb_integral[c][i - 1] + 0.5 * h * (rgb[c] + last_rgb[c]);
            last_rgb[c] = rgb[c];
        }
    }
    const double total = p_integral[CELLS];
    for (int i = 1; i < CELLS; i++)
        p_integral[i] /= total;
    p_integral[CELLS] = 1.0;
    for (int j = 0, i = 0; j <= INVERSES; j++) {
        const double u = (double)j / INVERSES;
        while (i < CELLS - 1 && p_integral[i + 1] <= u)
            i++;
        const double f = (u - p_integral[i]) / (p_integral[i + 1] - p_integral[i]);
        inverse_nm[j] = grid_nm(i) + f * (grid_nm(i + 1) - grid_nm(i));
    }
    inverse_nm[INVERSES] = SPECTRUM_MAX_NM;
    atomic_store_explicit(&ready, true, memory_order_release);
}

double spectrum_wavelength_nm(double u)
{
    need_tables();
    if (!(u > 0.0))
        return SPECTRUM_MIN_NM;
    if (u >= 1.0)
        return SPECTRUM_MAX_NM;
    const double x = u * INVERSES;
    const int j = (int)x;
    return inverse_nm[j] + (x - j) * (inverse_nm[j + 1] - inverse_nm[j]);
}

/* The integral of rgb_c from SPECTRUM_MIN_NM to nm, linear within a cell. */
static double rgb_integral_to(int c, double nm)
{
    const double at = (nm - SPECTRUM_MIN_NM) / (SPECTRUM_MAX_NM - SPECTRUM_MIN_NM) * CELLS;
    const int i = at <= 0 ? 0 : at >= CELLS ? CELLS - 1 : (int)at;
    const double f = fmin(fmax(at - i, 0.0), 1.0);
    return rgb_integral[c][i] + f * (rgb_integral[c][i + 1] - rgb_integral[c][i]);
}

void spectrum_band_weights(int band, int bands, double w[3])
{
    need_tables();
    const double lo = spectrum_wavelength_nm((double)band / bands);
    const double hi = spectrum_wavelength_nm((double)(band + 1) / bands);
    for (int c = 0; c < 3; c++)
        w[c] = bands * (rgb_integral_to(c, hi) - rgb_integral_to(c, lo)) / rgb_integral[c][CELLS];
}
