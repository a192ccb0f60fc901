/* The folder of the running executable, where its installed companions are found relative to
   it: the image library in ../lib/lens2pov, the lenses in ../share/lens2pov/lenses. */
#ifndef LENS2POV_EXE_DIR_H
#define LENS2POV_EXE_DIR_H

#include <stdbool.h>
#include <stddef.h>

/* Into dir, resolved (a symlinked lens2pov still finds its companions); false with *why set
   when /proc/self/exe cannot be read. */
bool exe_dir(char *dir, size_t size, const char **why);

#endif
