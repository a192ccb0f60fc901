/* Light of many wavelengths (--dispersion): the CIE 1931 observer, how a sample's wavelength is
   drawn, and what each colour channel of the picture takes from it. docs/dispersion.md has
   the design. */
#ifndef LENS2POV_SPECTRUM_H
#define LENS2POV_SPECTRUM_H

/* The wavelengths sampled, nm: where the 1931 colour-matching functions are above 1e-4 of
   their peaks. */
#define SPECTRUM_MIN_NM 380.0
#define SPECTRUM_MAX_NM 780.0

/* The CIE 1931 2-degree colour-matching functions x, y, z at this wavelength (nm), by the
   piecewise-Gaussian fit of Wyman, Sloan and Shirley ("Simple Analytic Approximations to the
   CIE XYZ Color Matching Functions", JCGT 2013, their multi-lobe fit). */
void spectrum_cie1931_xyz(double wavelength_nm, double xyz[3]);

/* Linear sRGB (IEC 61966-2-1 primaries, D65 white) of a unit light at this wavelength: the
   XYZ above through the standard XYZ-to-sRGB matrix. Negative where the colour lies outside
   the sRGB gamut, as every pure spectral colour does. */
void spectrum_linear_srgb(double wavelength_nm, double rgb[3]);

/* The wavelength at u in [0, 1] of the sampling density p(lambda), proportional to
   x + y + z over [SPECTRUM_MIN_NM, SPECTRUM_MAX_NM]: lambda = P^-1(u), P its integral,
   tabulated (spectrum.c says how closely). Increasing; u = 0 and 1 give the ends exactly. */
double spectrum_wavelength_nm(double u);

/* The colour weights of band k of `bands`, the bands being equal parts of u (so equal shares
   of p): w_c = bands * (integral of rgb_c over the band) / (integral of rgb_c over all),
   c = r, g, b. Over all bands each channel's weights average exactly 1 (up to rounding):
   a scene of one colour seen with one sample in each band keeps that colour. */
void spectrum_band_weights(int band, int bands, double w[3]);

#endif
