/* The files a trace writes for its prefix, and what an earlier trace of the same prefix left
   that this one did not write. */
#ifndef LENS2POV_CLI_TRACESET_H
#define LENS2POV_CLI_TRACESET_H

/* The layouts of a trace's POV-Ray files: PREFIX.inc and .ini (one table), PREFIX.cNNN.inc and
   .ini (a table in chunks), PREFIX.fNNN.inc and .ini (the renders of a ray field). */
typedef enum trace_layout { TRACE_LAYOUT_ONE = 0, TRACE_LAYOUT_CHUNKS = 'c', TRACE_LAYOUT_FIELD = 'f' } trace_layout;

/* Removes the includes and inis of the prefix's set that a trace of this layout with count
   files of each kind did not write, and that lens2pov wrote (their first line says so): an
   earlier trace's, which would render rays the new map does not describe. Renders are left
   alone (develop warns of one older than its map). Returns how many were removed. */
int trace_set_remove_stale(const char *prefix, trace_layout layout, int count);

#endif
