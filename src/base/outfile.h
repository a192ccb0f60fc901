/* Outputs that are never half-written: each is written to a temporary name beside its final
   path and renamed into place only when the whole run succeeded. Temporary files are removed
   on failure, and on a signal (base/cleanup.h). */
#ifndef LENS2POV_OUTFILE_H
#define LENS2POV_OUTFILE_H

#include <stdio.h>
#include <sys/types.h>
#include "base/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct outfile {
    FILE *fp;
    char *final_path;
    char *temp_path;
} outfile;

/* Creates an empty file named prefix, 12 random hex digits, suffix: exclusively (O_EXCL),
   never through a symbolic link (O_NOFOLLOW), with what the umask leaves of 0666, so that no
   one can guess the name beforehand or plant a link there. Returns its descriptor
   (close-on-exec) with its name in *path (malloc'd), or -1 with errno set. */
int outfile_create_temp(const char *prefix, const char *suffix, char **path);

/* The file an output named path goes to: path itself, or where its chain of symbolic links
   ends (a link's relative target is read from the link's folder), so that an output named by
   a link is written through it and the link stays, as with any program that opens the file.
   malloc'd; NULL with errno set (ELOOP after 40 links, ENOMEM). */
char *outfile_target(const char *path);

/* Refuses (L2P_BAD_INPUT) an output whose name does not end in suffix (any case), for a
   command that writes only format, so that the name does not lie about the file. */
int outfile_check_suffix(const char *path, const char *suffix, const char *format, l2p_error *err);

/* Refuses (L2P_BAD_INPUT, naming both) an output that is the input file read as what (its
   role, "the lens"): the same file, by any name or link. Either may not exist yet. */
int outfile_check_not_input(const char *output, const char *input, const char *what, l2p_error *err);

/* Checks, before any work, that path can become an output: its folder exists and may be
   written, and path is not a folder. L2P_BAD_INPUT with a message naming path otherwise. */
int outfile_check_path(const char *path, l2p_error *err);

/* The same for a folder that is kept or made: an existing one must be a folder that may be
   written, a new one's parent must exist and may be written. */
int outfile_check_dir(const char *path, l2p_error *err);

/* Opens a temporary file beside path's target (outfile_target) for writing
   (outfile_create_temp, "TARGET.tmp..."); final_path is the target. */
int outfile_open(outfile *f, const char *path, l2p_error *err);

/* Flushes and closes the temporary file (checking for write errors) without renaming it. */
int outfile_finish(outfile *f, l2p_error *err);

/* Renames a finished temporary file to its final path. */
int outfile_commit(outfile *f, l2p_error *err);

/* Closes if needed and removes the temporary file; safe to call on a committed or unopened file. */
void outfile_discard(outfile *f);

#ifdef __cplusplus
}
#endif

#endif
