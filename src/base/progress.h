/* A one-line progress bar on stderr, redrawn in place with \r; draws nothing when stderr is
   not a terminal (logs and pipes stay clean). */
#ifndef LENS2POV_PROGRESS_H
#define LENS2POV_PROGRESS_H

#include <time.h>

typedef struct progress {
    int enabled;
    const char *label;
    struct timespec start;
    int drawn_width;          /* characters of the last drawing, to blank what is left over */
} progress;

/* Starts the clock; the bar is drawn only when wanted and stderr is a terminal. */
void progress_start(progress *p, const char *label, int wanted);

/* Redraws: label, bar, percentage of fraction (clamped to [0, 1]), elapsed seconds and an
   optional short detail (NULL for none). */
void progress_update(progress *p, double fraction, const char *detail);

/* Ends the line so that later messages start on their own line. */
void progress_finish(progress *p);

#endif
