/* render's workspace: the folder of its ray tables, renders and logs, removed at the end
   unless --keep-temp names it. */
#ifndef LENS2POV_CLI_WORKSPACE_H
#define LENS2POV_CLI_WORKSPACE_H

#include <stdbool.h>
#include "base/error.h"

typedef struct workspace {
    char dir[4096];
    bool keep;                 /* --keep-temp's folder: left in place */
    bool made;                 /* kept, and made by this render (removed when left empty) */
    int lock_fd;               /* the kept folder, locked while this render uses it; else -1 */
} workspace;

/* keep (--keep-temp), made when missing and locked (L2P_BAD_INPUT when another render holds
   it: the two would write the same files); else a new lens2pov.PID.XXXXXX in the temporary
   folder, removed on a signal too, after removing those of processes that are gone. */
int workspace_make(workspace *w, const char *keep, l2p_error *err);

/* Removes the workspace and its files (nothing in it has folders), unless it is kept; a kept
   one is unlocked, and removed when this render made it and left it empty. */
void workspace_remove(const workspace *w);

#endif
