/* The one spelling of a chunk's file name, shared by the writer of the ray table, the renderer
   that runs POV-Ray on it and the commands that list it. */
#ifndef LENS2POV_CHUNK_NAME_H
#define LENS2POV_CHUNK_NAME_H

/* PREFIX.cNNN.EXT (NNN the index, three digits or more), malloc'd; NULL out of memory. */
char *chunk_file_name(const char *prefix, int index, const char *ext);

#endif
