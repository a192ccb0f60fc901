/* `lens2pov trace`: the ray table of a lens and camera, for POV-Ray. */
#include "cli/commands.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/cores.h"
#include "base/outfile.h"
#include "cli/framing.h"
#include "cli/sizecheck.h"
#include "cli/traceset.h"
#include "field/field_render.h"
#include "raytable/chunk_ini.h"
#include "raytable/povmesh.h"
#include "raytable/raytable.h"

/* trace's outputs, checked before any work: PREFIX.inc, .ini and .map (a chunked table's
   files are checked again before the first is renamed into place). */
static int check_trace_outputs(const cli *c, l2p_error *err)
{
    char *path = malloc(strlen(c->output) + 5);
    if (!path)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    static const char *const ext[] = {"inc", "ini", "map"};
    int st = L2P_OK;
    for (int i = 0; i < 3 && !st; i++) {
        sprintf(path, "%s.%s", c->output, ext[i]);
        st = outfile_check_path(path, err);
    }
    free(path);
    if (!st)
        st = chunk_ini_check_prefix(c->output, err);
    if (!st && c->rays_csv)
        st = outfile_check_path(c->rays_csv, err);
    return st;
}

/* After a trace, what an earlier trace of the prefix left that this one did not write. */
static void remove_stale(const cli *c, trace_layout layout, int count)
{
    const int removed = trace_set_remove_stale(c->output, layout, count);
    if (removed && !c->quiet)
        fprintf(stderr, "lens2pov: removed %d include%s and ini%s of an earlier trace of %s\n",
                removed, removed == 1 ? "" : "s", removed == 1 ? "" : "s", c->output);
}

/* --sampling field: the field map and each render's include and ini (docs/fields.md). */
static int trace_field(const cli *c, const camera *cam, l2p_error *err)
{
    outfile csv = {0};
    int st = c->rays_csv ? outfile_open(&csv, c->rays_csv, err) : L2P_OK;
    const field_trace_options o = {c->output, c->jobs ? c->jobs : cores_online(),
                                   c->field_tolerance, c->rays_csv ? &csv : NULL};
    field_trace_stats stats;
    if (!st)
        st = field_trace(cam, &o, &stats, err);
    if (!st && c->rays_csv)
        st = outfile_commit(&csv, err);
    outfile_discard(&csv);
    if (!st)
        remove_stale(c, TRACE_LAYOUT_FIELD, stats.renders);
    if (!st && !c->quiet)
        fprintf(stderr, "lens2pov: %lld of %lld rays pass the lens (%.1f%%): %d sub-images, "
                "%lld faces in %d renders\n", stats.passed, stats.pixels,
                stats.pixels ? 100.0 * (double)stats.passed / (double)stats.pixels : 0.0,
                cam->samples.spp, stats.faces, stats.renders);
    return st;
}

int trace_command(const cli *given, l2p_error *err)
{
    camera cam;
    cli placed = *given;   /* with --scene's camera placement */
    const cli *c = &placed;
    int st = cli_expect_arguments(c, 1, true, err);
    if (!st && c->field_sampling && c->memory_mb > 0)
        st = l2p_fail(err, L2P_BAD_INPUT, NULL, 0, "--memory-mb splits a ray table of --sampling "
                      "pixel; a field's renders are split by their faces already");
    if (st || (st = check_trace_outputs(c, err)) || (st = size_check_trace(c, err)) ||
        (c->scene && (st = framing_from_scene(&placed, c->scene, err))) ||
        (st = framing_load_camera(c, c->positional[0], &cam, err)))
        return st;
    cli_warn(c, &cam, true);
    if (c->field_sampling) {
        st = trace_field(c, &cam, err);
        camera_free(&cam);
        return st;
    }
    raytable_stats stats;
    /* One include unless --memory-mb asks for chunks that fit a POV-Ray process each. */
    const long long chunk_faces = c->memory_mb > 0 ? raytable_faces_for_memory(c->memory_mb) : 0;
    const raytable_request q = {c->output, c->rays_csv, chunk_faces, !c->quiet, NULL, NULL};
    st = raytable_write(&cam, &q, &stats, err);
    if (!st)
        remove_stale(c, chunk_faces > 0 ? TRACE_LAYOUT_CHUNKS : TRACE_LAYOUT_ONE, stats.chunks);
    if (!st && !c->quiet)
        fprintf(stderr, "lens2pov: %lld of %lld rays pass the lens (%.1f%%), %.2f s\n",
                stats.passed, stats.samples,
                stats.samples ? 100.0 * (double)stats.passed / (double)stats.samples : 0.0,
                stats.seconds);
    camera_free(&cam);
    return st;
}
