/* The commands of lens2pov, each in a file of its own: info.c, trace_command.c,
   develop_command.c, render.c, diagram_command.c and plot_command.c. Each takes the parsed command line and returns 0 or an
   error status with err set. */
#ifndef LENS2POV_COMMANDS_H
#define LENS2POV_COMMANDS_H

#include "base/error.h"
#include "cli/cli.h"

int info_command(const cli *c, l2p_error *err);
int trace_command(const cli *c, l2p_error *err);
int develop_command(const cli *c, l2p_error *err);
int render_command(const cli *c, l2p_error *err);
int diagram_command(const cli *c, l2p_error *err);
int plot_command(const cli *c, l2p_error *err);

#endif
