/* Spectral pupils: with dispersion, the camera's pupil covered over the spectrum, and the
   pupils fitted at wavelengths across it that samples are drawn from (camera_pupil_at). */
#ifndef LENS2POV_SPECTRAL_H
#define LENS2POV_SPECTRAL_H

#include "base/error.h"
#include "camera/camera.h"

/* Covers c->pupil, fitted at the d line, for every wavelength of the spectrum, and fits
   c->spectral where that grows the region much (spectral.c says when and how many). */
int camera_cover_spectrum(camera *c, l2p_error *err);

#endif
