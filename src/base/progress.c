#include "base/progress.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

enum { BAR_CELLS = 30 };

static double seconds_since(const struct timespec *t0)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)(now.tv_sec - t0->tv_sec) + 1e-9 * (double)(now.tv_nsec - t0->tv_nsec);
}

void progress_start(progress *p, const char *label, int wanted)
{
    memset(p, 0, sizeof *p);
    p->enabled = wanted && isatty(STDERR_FILENO);
    p->label = label ? label : "";
    clock_gettime(CLOCK_MONOTONIC, &p->start);
}

void progress_update(progress *p, double fraction, const char *detail)
{
    if (!p->enabled)
        return;
    if (!(fraction >= 0))  /* also NaN */
        fraction = 0;
    if (fraction > 1)
        fraction = 1;
    char bar[BAR_CELLS + 1];
    const int full = (int)(fraction * BAR_CELLS + 0.5);
    for (int i = 0; i < BAR_CELLS; i++)
        bar[i] = i < full ? '#' : '.';
    bar[BAR_CELLS] = '\0';
    char line[256];
    int n = snprintf(line, sizeof line, "%s [%s] %3d%% %5.0fs%s%s", p->label, bar,
                     (int)(fraction * 100), seconds_since(&p->start), detail ? "  " : "",
                     detail ? detail : "");
    if (n < 0)
        return;
    if (n >= (int)sizeof line)
        n = (int)sizeof line - 1;
    /* Pad with spaces over the rest of a longer previous drawing. */
    fprintf(stderr, "\r%s%*s", line, p->drawn_width > n ? p->drawn_width - n : 0, "");
    fflush(stderr);
    p->drawn_width = n;
}

void progress_finish(progress *p)
{
    if (!p->enabled || !p->drawn_width)
        return;
    fputc('\n', stderr);
    fflush(stderr);
    p->drawn_width = 0;
}
