/* `lens2pov render`: trace, render the chunks with POV-Ray in parallel, develop. */
#ifndef LENS2POV_RENDER_H
#define LENS2POV_RENDER_H

#include "cli/cli.h"
#include "base/error.h"

int render_command(const cli *c, l2p_error *err);

#endif
