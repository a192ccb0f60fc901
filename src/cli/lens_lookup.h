/* Finding a lens file from what the user typed: a path, or a lens's name. */
#ifndef LENS2POV_LENS_LOOKUP_H
#define LENS2POV_LENS_LOOKUP_H

#include "base/error.h"
#include "optics/lens.h"

/* The path as given when a file is there; otherwise NAME or NAME.dat in ./lenses, then in the
   installed lens folder (PREFIX/share/lens2pov/lenses for PREFIX/bin/lens2pov), then in the
   source tree's (lenses/ beside build/lens2pov). *path gets
   the path found (malloc'd): name itself when it holds a '/' or nothing is found elsewhere and
   it is not a bare name, so that reading it gives the system's reason. L2P_BAD_INPUT naming
   the places looked in for a bare name found nowhere. */
int lens_lookup(const char *name, char **path, l2p_error *err);

/* lens_read of the lens found by lens_lookup. */
int lens_read_named(const char *name, lens *l, l2p_error *err);

#endif
