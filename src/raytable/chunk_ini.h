/* A chunk's POV-Ray settings (.ini): the packed image's size, no antialiasing, and the EXR
   render's name, absolute because POV-Ray runs in the scene's folder. */
#ifndef LENS2POV_CHUNK_INI_H
#define LENS2POV_CHUNK_INI_H

#include <stdio.h>
#include "base/error.h"
#include "base/outfile.h"

/* path made absolute in the current folder (malloc'd); as it is when it cannot be. POV-Ray
   resolves an .ini's file names against its own folder, not the .ini's. */
char *chunk_ini_absolute(const char *path);

/* Checks, before any work, that the .ini files of the table at prefix can name its renders
   (absolute paths; povray_ini_can_carry): L2P_BAD_INPUT naming the path otherwise. */
int chunk_ini_check_prefix(const char *prefix, l2p_error *err);

/* The settings through which a render by hand sees what render gives the scene: the film's
   size as image_width and image_height (a Declare, which shadows the built-in ones as
   render's #declare does) and the display gamma. */
void chunk_ini_as_render(FILE *fp, int film_width, int film_height);

/* Writes ini_path (through *ini, finished, not committed) for an image width x height
   naming render exr_path (made absolute), for a film of film_width x film_height. */
int chunk_ini_write(outfile *ini, const char *ini_path, const char *exr_path, int width,
                    long long height, int film_width, int film_height, l2p_error *err);

#endif
