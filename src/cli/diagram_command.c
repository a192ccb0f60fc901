/* `lens2pov diagram`: the lens in its meridional section, as SVG (src/draw/diagram.h). */
#include "cli/commands.h"

#include "base/outfile.h"
#include "cli/framing.h"
#include "draw/diagram.h"

int diagram_command(const cli *c, l2p_error *err)
{
    int st = cli_expect_arguments(c, 1, true, err);
    camera cam;
    if (st || (st = outfile_check_suffix(c->output, ".svg", "SVG", err)) || (st = outfile_check_path(c->output, err)) ||
        (st = framing_load_camera(c, c->positional[0], &cam, err)))
        return st;
    cli_warn(c, &cam, false);
    outfile f;
    if (!(st = outfile_open(&f, c->output, err))) {
        st = diagram_write_svg(f.fp, &cam, err);
        if (!st)
            st = outfile_finish(&f, err);
        if (!st)
            st = outfile_commit(&f, err);
        outfile_discard(&f);
    }
    camera_free(&cam);
    return st;
}
