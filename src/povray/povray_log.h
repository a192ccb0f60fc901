/* POV-Ray's log: why a run failed, in POV-Ray's own words, and how far it has got. */
#ifndef LENS2POV_POVRAY_LOG_H
#define LENS2POV_POVRAY_LOG_H

#include <stdbool.h>
#include <stddef.h>
#include "base/error.h"

typedef struct povray_path_link {
    char *link, *target;       /* a symlink lens2pov made for POV-Ray, and the user's path */
} povray_path_link;

/* What a path in POV-Ray's messages stands for. */
typedef struct povray_log_names {
    const char *scene;         /* the user's scene */
    const char *scene_dir;     /* POV-Ray's working folder: relative names are found there */
    const char *own[2];        /* lens2pov's wrapper and camera include: an error there is the
                                  scene's, left open, that POV-Ray noticed only reading on */
    const povray_path_link *links;
    int link_count;
} povray_log_names;

/* The reason in the log at log_path, as "FILE:LINE: message" in err with the user's paths:
   L2P_BAD_INPUT for a parse error or a possible one (the scene's), else L2P_FAILED; 0 when
   the log gives none. In an animation, only the last frame's messages
   count. */
int povray_log_error(const char *log_path, const povray_log_names *names, l2p_error *err);

/* The latest progress in the log: the parse (estimated from the chunk's face count) and the
   render, each in [0, 1]; left as they were when the log says nothing new. In an animation,
   only the current frame's. */
void povray_log_progress(const char *log_path, long long faces, double *parse, double *render);

/* Whether a failed run's log says it failed for a passing cause (its threads were slow to
   start on a loaded machine): the run may be started again. */
bool povray_log_transient(const char *log_path);

/* Whether a run that failed, its log at log_path, is to be started again after retries_made
   starts again: when it failed for that passing cause, at most seven times. It then warns on
   stderr and pauses first (0.1 s, doubling with each retry). */
bool povray_retry_transient(const char *log_path, int retries_made);

/* The log's last line that is not blank, without its end of line, cut to n - 1 bytes; "" when
   the log is empty or unreadable. */
void povray_log_last_line(const char *log_path, char *out, size_t n);

/* The frame an animation's log is at ("Rendering frame F of N"), or frame when its tail
   names none. */
int povray_log_frame(const char *log_path, int frame);

#endif
