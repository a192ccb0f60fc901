/* render's workspace: the folder of its ray tables, renders and logs, removed at the end
   unless --keep-temp names it. */
#ifndef LENS2POV_CLI_WORKSPACE_H
#define LENS2POV_CLI_WORKSPACE_H

#include <stdbool.h>
#include "base/error.h"

typedef struct workspace {
    char dir[4096];
    bool keep;                 /* --keep-temp's folder: left in place */
} workspace;

/* keep (--keep-temp), made when missing; else a new lens2pov.PID.XXXXXX in the temporary
   folder, removed on a signal too, after removing those of processes that are gone. */
int workspace_make(workspace *w, const char *keep, l2p_error *err);

/* Removes the workspace and its files (nothing in it has folders), unless it is kept. */
void workspace_remove(const workspace *w);

#endif
