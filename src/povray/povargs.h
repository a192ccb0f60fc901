/* POV-Ray's own options given after "--" to render: the ones that would break the ray table
   are refused; the rest are passed to every POV-Ray run. And the names POV-Ray gives the
   frames of an animation. */
#ifndef LENS2POV_POVARGS_H
#define LENS2POV_POVARGS_H

#include <stdbool.h>
#include "base/error.h"

/* L2P_BAD_INPUT, naming "--" and the option, for an option that sets the image's size, its
   antialiasing, crop, output file or type, or its input file: lens2pov sets those for the ray
   table. Values are not checked here: POV-Ray checks them on its first run. */
int povargs_check(char *const *args, int count, l2p_error *err);

/* The options with relative paths made absolute from the current folder: POV-Ray runs in the
   scene's folder. Library paths (+L, Library_Path=) and file names (an .ini, given alone)
   that exist here. NULL-terminated, malloc'd (povargs_free); NULL out of memory. */
char **povargs_resolve(char *const *args, int count);
void povargs_free(char **args);

/* Whether the options leave POV-Ray nothing to do once it has written its pictures, so that
   it need not be waited for: each an animation or subset-of-frames option (+K..., +SF, +EF,
   Initial_Frame=, ...), a quality or thread count (+Q, +WT), a library path (+L) or a
   Declare=. Any other (an ini named alone, a Post_Frame_Command=, ...) might. */
bool povargs_end_with_pictures(char *const *args, int count);

/* The ini files POV-Ray 3.7 may read before the scene run in folder, in order: the one POVINI
   names, folder's povray.ini and POVRAY.INI, the user's ~/.povray/3.7/povray.ini, the system's
   /etc/povray/3.7/povray.ini. NULL in place of POVINI's or the user's when POVINI or HOME is
   unset; the paths are written into buf. */
enum { POVARGS_INIS = 5, POVARGS_INI_PATH = 4200 };
void povargs_default_inis(const char *folder, char buf[POVARGS_INIS][POVARGS_INI_PATH],
                          const char *ini[POVARGS_INIS]);

/* The folders POV-Ray looks in for an #include, after folder (where it runs), with the
   options args: the Library_Path settings and +L options of the ini files it may read (POVINI,
   folder/povray.ini, ~/.povray/3.7/povray.ini, /etc/povray/3.7/povray.ini), of ini files
   among args, and of args; relative ones taken from folder. NULL-terminated, malloc'd
   (povargs_free); NULL out of memory. */
char **povargs_library_paths(const char *folder, char *const *args, int count);

/* The digits POV-Ray pads a frame number to: those of the final frame. */
int povargs_frame_digits(int final_frame);

/* path with the frame number before its extension, as POV-Ray names an animation's frames
   (out.png, frame 3 of 10: out03.png); malloc'd, NULL out of memory. */
char *povargs_frame_name(const char *path, int frame, int digits);

#endif
