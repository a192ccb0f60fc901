#include "cli/frames.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/framing.h"
#include "povray/povargs.h"
#include "povray/scenecam.h"

/* Frames whose focus distances differ by less than this share a table. */
#define SAME_FOCUS 1e-9

static char *placement_text(const camera_options *o, const char *scene, l2p_error *err)
{
    const vec3 ahead = v3_sub(o->look_at, o->location);
    const vec3 f = v3_normalize(ahead), side = v3_cross(o->sky, f);
    if (!(v3_length(ahead) > 0.0) || !(v3_length(side) > 1e-12 * v3_length(o->sky))) {
        l2p_fail(err, L2P_BAD_INPUT, scene, 0,
                 "a frame's camera looks along its sky vector (or at its own location)");
        return NULL;
    }
    /* The table's axes (right, up, forward) onto the frame's, as camera_setup places a lens;
       a mirrored picture is mirrored in the table itself. */
    const vec3 r = v3_normalize(side), u = v3_cross(f, r), l = o->location;
    char *s = malloc(640);
    if (!s) {
        l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
        return NULL;
    }
    snprintf(s, 640, "#declare Lens2pov_Placement = transform { matrix <%.17g, %.17g, %.17g, "
             "%.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g, %.17g> }",
             r.x, r.y, r.z, u.x, u.y, u.z, f.x, f.y, f.z, l.x, l.y, l.z);
    return s;
}

/* The table a frame is seen through: the lens at the origin looking along +z, focused as the
   frame's camera is. */
static cli table_options(const cli *frame)
{
    cli t = *frame;
    const double focus = v3_length(v3_sub(frame->cam.look_at, frame->cam.location));
    t.cam.location = v3(0, 0, 0);
    t.cam.look_at = v3(0, 0, focus);
    t.cam.sky = v3(0, 1, 0);
    return t;
}

static bool close_to(double a, double b)
{
    return a == b || fabs(a - b) <= SAME_FOCUS * fmax(fabs(a), fabs(b));
}

/* The look-at point's distance focuses the lens only when --focus-distance and
   --film-distance are not given (the same for every frame). */
static bool same_table(const cli *a, const cli *b)
{
    const bool focus_given = !isnan(a->cam.focus_distance_units) || !isnan(a->cam.film_distance_mm);
    return (focus_given || close_to(a->cam.look_at.z, b->cam.look_at.z)) &&
           a->cam.mirror == b->cam.mirror &&
           (!a->angle_scene || close_to(a->angle_deg, b->angle_deg));
}

static int plan_frame(render_frames *out, int i, const cli *c, const scene_frames *sf,
                      l2p_error *err)
{
    render_frame *f = &out->frame[i];
    cli placed = *c;
    framing_apply(&placed, &sf->frame[i].cam);
    f->number = sf->animated ? sf->frame[i].number : -1;
    f->output = sf->animated ? povargs_frame_name(c->output, f->number,
                                                 povargs_frame_digits(sf->final_frame))
                             : strdup(c->output);
    if (!f->output)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    if (!sf->animated) {   /* the table in world axes, as without options after "--" */
        f->table_cli = placed;
        return L2P_OK;
    }
    if (!(f->placement = placement_text(&placed.cam, c->positional[0], err)))
        return err->status;
    f->table_cli = table_options(&placed);
    f->table = out->tables;
    for (int k = 0; k < i; k++)
        if (same_table(&out->frame[k].table_cli, &f->table_cli)) {
            f->table = out->frame[k].table;
            return L2P_OK;
        }
    out->tables++;
    return L2P_OK;
}

int render_frames_plan(const cli *c, render_frames *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    if (!c->povray_args) {   /* one frame, no POV-Ray options: as it always was */
        out->frame = calloc(1, sizeof *out->frame);
        if (!out->frame)
            return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
        out->count = out->tables = 1;
        render_frame *f = &out->frame[0];
        f->number = -1;
        f->table_cli = *c;
        f->output = strdup(c->output);
        if (!f->output)
            return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
        return framing_from_scene(&f->table_cli, c->positional[0], err);
    }
    scene_frames sf;
    int st = scene_frames_read(c->positional[0], c->cam.width, c->cam.height, c->povray_args,
                               c->povray_arg_count, &sf, err);
    if (st)
        return st;
    out->frame = calloc((size_t)sf.count, sizeof *out->frame);
    st = out->frame ? L2P_OK : l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    out->animated = sf.animated;
    out->digits = povargs_frame_digits(sf.final_frame);
    out->tables = sf.animated ? 0 : 1;
    bool perturbed = false;
    int unseen = 0;
    for (int i = 0; !st && i < sf.count; i++, out->count++) {
        st = plan_frame(out, i, c, &sf, err);
        perturbed = perturbed || sf.frame[i].cam.perturbed;
        unseen = unseen ? unseen : sf.frame[i].cam.computed_include;
    }
    if (!st) {
        framing_warn_perturbed(c->positional[0], perturbed && !c->placed);
        framing_warn_unseen(c->positional[0], c->placed ? 0 : unseen);
    }
    scene_frames_free(&sf);
    return st;
}

void render_frames_free(render_frames *f)
{
    for (int i = 0; f->frame && i < f->count; i++) {
        free(f->frame[i].output);
        free(f->frame[i].placement);
    }
    free(f->frame);
    memset(f, 0, sizeof *f);
}
