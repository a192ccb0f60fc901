/* The scene's camera: POV-Ray parses a copy of the scene whose camera statements print their
   items (scenecam_text.c), run by scenecam_run.c; here POV-Ray 3.7's camera rules are applied
   to the items of the last statement that ran. */
#include "povray/scenecam.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* POV-Ray's EPSILON in the camera code. */
#define POV_EPSILON 1e-10
/* Cosine between two camera vectors above which lens2pov calls them skewed. A skew of c shears
   POV-Ray's picture by about c of its size, which lens2pov, making the vectors perpendicular,
   leaves out: half a pixel at 1000 pixels. A rotation matrix written to 4 decimals, as
   exporters write them, is skewed by up to about 1e-4. */
#define SKEW_COS 5e-4

/* ---------------------------------------------------------------- the items, as POV-Ray's rules */

typedef struct affine { vec3 o, ex, ey, ez; } affine;   /* images of 0, x, y, z */

static vec3 affine_dir(const affine *m, vec3 d)
{
    return v3(d.x * (m->ex.x - m->o.x) + d.y * (m->ey.x - m->o.x) + d.z * (m->ez.x - m->o.x),
              d.x * (m->ex.y - m->o.y) + d.y * (m->ey.y - m->o.y) + d.z * (m->ez.y - m->o.y),
              d.x * (m->ex.z - m->o.z) + d.y * (m->ey.z - m->o.z) + d.z * (m->ez.z - m->o.z));
}

static vec3 affine_point(const affine *m, vec3 p) { return v3_add(m->o, affine_dir(m, p)); }

/* b after a. */
static affine affine_then(const affine *a, const affine *b)
{
    affine r;
    r.o = affine_point(b, a->o);
    r.ex = affine_point(b, a->ex);
    r.ey = affine_point(b, a->ey);
    r.ez = affine_point(b, a->ez);
    return r;
}

typedef struct pov_camera {
    char type[32];
    vec3 location, direction, up, right, sky, look_at, focus, focal_point;
    double angle, focal_distance;
    bool has_look_at, has_angle, has_focal_point, declared, unsupported, directive, branch_type;
    bool has_normal;           /* a normal { } perturbs POV-Ray's rays; the lens leaves it out */
    affine trans, pending;     /* the transforms so far; the one being read */
    double version;
} pov_camera;

static void pov_camera_default(pov_camera *c)
{
    memset(c, 0, sizeof *c);
    strcpy(c->type, "perspective");
    c->direction = v3(0, 0, 1);
    c->up = v3(0, 1, 0);
    c->right = v3(1.33, 0, 0);
    c->sky = v3(0, 1, 0);
    c->trans = (affine){v3(0, 0, 0), v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
    c->version = 3.7;
}

static void apply_transform(pov_camera *c, const affine *m)
{
    c->location = affine_point(m, c->location);
    c->focus = affine_point(m, c->focus);
    c->direction = affine_dir(m, c->direction);
    c->up = affine_dir(m, c->up);
    c->right = affine_dir(m, c->right);
}

static void apply_angle(pov_camera *c)
{
    if (strcmp(c->type, "perspective") || !(c->angle > 0.0))
        return;
    c->direction = v3_scale(v3_normalize(c->direction),
                            v3_length(c->right) / tan(c->angle * M_PI / 360.0) / 2.0);
}

/* look_at keeps the lengths of direction, up and right and the handedness of the three. */
static int apply_look_at(pov_camera *c, const char *scene, int line, l2p_error *err)
{
    const double dl = v3_length(c->direction), ul = v3_length(c->up), rl = v3_length(c->right);
    const double hand = v3_dot(v3_cross(c->up, c->direction), c->right);
    vec3 d = v3_sub(c->look_at, c->location);
    if (v3_dot(d, d) < POV_EPSILON)
        return l2p_fail(err, L2P_BAD_INPUT, scene, line,
                        "the camera's location and look_at are the same point");
    d = v3_normalize(d);
    vec3 r = v3_cross(c->sky, d);
    if (fabs(r.x) < POV_EPSILON && fabs(r.y) < POV_EPSILON && fabs(r.z) < POV_EPSILON)
        r = c->right;
    r = v3_normalize(r);
    c->up = v3_scale(v3_cross(d, r), ul);
    c->direction = v3_scale(d, dl);
    c->right = v3_scale(r, hand > 0.0 ? rl : -rl);
    c->focus = c->look_at;
    return L2P_OK;
}

/* Focal blur's plane: |focal_point - location| ahead along direction, measured before the
   transforms and kept through them (Parse_Camera; TracePixel::JitterCameraRay scales the
   unnormalized ray to that distance), 1 for a focal point at the location. */
static void apply_focal_point(pov_camera *c)
{
    c->focal_distance = v3_length(v3_sub(c->focal_point, c->location));
    if (c->focal_distance == 0.0)
        c->focal_distance = 1.0;
}

/* ---------------------------------------------------------------- reading the #debug lines */

/* The next message "lens2pov-WORD rest|" at or after *pos: its lines joined (POV-Ray wraps
   its console at 80 columns, at a blank kept on the next line or inside a word), into buf. */
static bool next_message(const char *log, size_t n, size_t *pos, char *buf, size_t cap)
{
    size_t i = *pos;
    while (i < n) {
        const bool at_line = i == 0 || log[i - 1] == '\n';
        if (at_line && n - i >= 9 && !memcmp(log + i, "lens2pov-", 9)) {
            size_t k = 0;
            for (; i < n && log[i] != '|'; i++)
                if (log[i] != '\n' && log[i] != '\r' && k + 1 < cap)
                    buf[k++] = log[i];
            buf[k] = '\0';
            *pos = i < n ? i + 1 : n;
            return i < n;
        }
        const char *nl = memchr(log + i, '\n', n - i);
        i = nl ? (size_t)(nl - log) + 1 : n;
    }
    *pos = n;
    return false;
}

static bool read_numbers(const char *s, double *v, int count)
{
    for (int k = 0; k < count; k++) {
        char *end;
        v[k] = strtod(s, &end);
        if (end == s || !isfinite(v[k]))
            return false;
        s = end;
    }
    return true;
}

/* An item message take_item cannot read: a value that is not finite is the scene's (POV-Ray's
   clock is nan in a one-frame animation, +KFI3 +KFF3), anything else lens2pov's. */
static int item_unreadable(const char *msg, const char *scene, int line, l2p_error *err)
{
    const char *value = strchr(msg, ' ');
    if (value && (strstr(value, "nan") || strstr(value, "inf")))
        return l2p_fail(err, L2P_BAD_INPUT, scene, line, "the camera's %.*s is not a finite "
                        "number as POV-Ray evaluates it (%s); POV-Ray's clock, for one, is "
                        "nan in an animation of one frame (+KFI3 +KFF3)", (int)(value - msg) - 9,
                        msg + 9, value + 1);
    return l2p_fail(err, L2P_FAILED, scene, line, "cannot read POV-Ray's value: %s", msg);
}

/* One item message into the camera; false when it cannot be read. The old syntax (before
   #version 3.5) applies each item at once, the new one at the end (finish_camera). */
static bool take_item(pov_camera *c, const char *msg, const char *scene, int line, int *st,
                      l2p_error *err)
{
    char word[32];
    int used = 0;
    if (sscanf(msg, "lens2pov-%31s %n", word, &used) < 1)
        return false;
    const char *rest = msg + used;
    const bool old = c->version < 3.5;
    double v[12];
    if (!strcmp(word, "version"))
        return read_numbers(rest, &c->version, 1);
    if (!strcmp(word, "type"))
        return sscanf(rest, "%31s", c->type) == 1;
    if (!strcmp(word, "declared"))
        return c->declared = true;
    if (!strcmp(word, "directive"))
        return c->unsupported = c->directive = true;
    if (!strcmp(word, "branch_type"))
        return c->unsupported = c->branch_type = true;
    if (!strcmp(word, "unknown"))
        return c->unsupported = true;
    if (!strcmp(word, "normal"))
        return c->has_normal = true;
    if (!strcmp(word, "angle")) {
        if (!read_numbers(rest, &c->angle, 1))
            return false;
        c->has_angle = true;
        if (old)
            apply_angle(c);
        return true;
    }
    /* A transform: its images of the origin and of x, y and z, one a message. */
    if (word[0] == 't' && word[1] >= '0' && word[1] <= '3' && !word[2]) {
        vec3 *slot[4] = {&c->pending.o, &c->pending.ex, &c->pending.ey, &c->pending.ez};
        if (!read_numbers(rest, v, 3))
            return false;
        *slot[word[1] - '0'] = v3(v[0], v[1], v[2]);
        if (word[1] != '3')
            return true;
        if (old)
            apply_transform(c, &c->pending);
        else
            c->trans = affine_then(&c->trans, &c->pending);
        return true;
    }
    if (!read_numbers(rest, v, 3))
        return false;
    const vec3 x = v3(v[0], v[1], v[2]);
    if (!strcmp(word, "location"))
        c->location = x;
    else if (!strcmp(word, "direction"))
        c->direction = x;
    else if (!strcmp(word, "up"))
        c->up = x;
    else if (!strcmp(word, "right"))
        c->right = x;
    else if (!strcmp(word, "sky"))
        c->sky = x;
    else if (!strcmp(word, "look_at")) {
        c->look_at = x;
        c->has_look_at = true;
        if (old)
            *st = apply_look_at(c, scene, line, err);
    } else if (!strcmp(word, "focal_point")) {
        c->focal_point = x;
        c->has_focal_point = true;
        if (old)
            apply_focal_point(c);
    } else
        return false;
    return true;
}

/* The new syntax's fixed order: angle, look_at, then the transforms. */
static int finish_camera(pov_camera *c, const char *scene, int line, l2p_error *err)
{
    if (c->version < 3.5)
        return L2P_OK;
    if (c->has_angle && !strcmp(c->type, "perspective") && c->angle >= 180.0)
        return l2p_fail(err, L2P_BAD_INPUT, scene, line,
                        "the camera's angle must be smaller than 180 degrees");
    if (c->has_angle)
        apply_angle(c);
    if (c->has_look_at) {
        const int st = apply_look_at(c, scene, line, err);
        if (st)
            return st;
    }
    if (c->has_focal_point)
        apply_focal_point(c);
    apply_transform(c, &c->trans);
    return L2P_OK;
}

static int refuse(l2p_error *err, const char *scene, int line, const char *why)
{
    return l2p_fail(err, L2P_BAD_INPUT, scene, line,
                    "%s: lens2pov cannot stand in for this camera; give --location and "
                    "--look-at (and --sky, --angle) instead", why);
}

/* The lens camera for POV-Ray's: perspective, with right, up and direction perpendicular. */
static int to_scene_camera(const pov_camera *c, const char *scene, int line, scene_camera *out,
                           l2p_error *err)
{
    char why[128];
    if (c->declared)
        return refuse(err, scene, line, "the camera starts from a declared camera");
    if (c->directive)
        return refuse(err, scene, line, "the camera block holds a directive other than #if, "
                      "#ifdef, #ifndef, #elseif, #else, #switch, #case, #range, #break, #end, "
                      "#debug and #warning, or one that does not stand between its items");
    if (c->branch_type)
        return refuse(err, scene, line, "the camera's type is chosen by a conditional directive");
    if (c->unsupported)
        return refuse(err, scene, line,
                      "the camera block holds a word that is not a camera item");
    if (strcmp(c->type, "perspective")) {
        snprintf(why, sizeof why, "the camera is %s, not perspective", c->type);
        return refuse(err, scene, line, why);
    }
    const double dl = v3_length(c->direction), ul = v3_length(c->up), rl = v3_length(c->right);
    if (!(dl > 0.0 && ul > 0.0 && rl > 0.0) || !v3_isfinite(c->location) ||
        !isfinite(dl * ul * rl))
        return refuse(err, scene, line, "the camera has a zero or non-finite direction, up or right");
    const vec3 d = v3_scale(c->direction, 1.0 / dl), u = v3_scale(c->up, 1.0 / ul),
               r = v3_scale(c->right, 1.0 / rl);
    if (fabs(v3_dot(d, u)) > SKEW_COS || fabs(v3_dot(d, r)) > SKEW_COS ||
        fabs(v3_dot(u, r)) > SKEW_COS)
        return refuse(err, scene, line, "the camera's direction, up and right are not perpendicular");
    out->location = c->location;
    out->forward = d;
    /* up made exactly perpendicular to forward: lens2pov builds right from it */
    out->up = v3_normalize(v3_sub(u, v3_scale(d, v3_dot(u, d))));
    out->mirrored = v3_dot(v3_cross(u, d), r) < 0.0;
    /* What the scene's author put in focus: focal blur's plane, else the look_at point, else
       |direction| ahead (where POV-Ray's focal blur focuses then). */
    const double focus = v3_dot(v3_sub(c->focus, c->location), d);
    if (c->has_focal_point && isfinite(c->focal_distance))
        out->focus_distance = c->focal_distance;
    else
        out->focus_distance = c->has_look_at && focus > 0.0 && isfinite(focus) ? focus : dl;
    out->hfov_deg = 2.0 * atan(0.5 * rl / dl) * 180.0 / M_PI;
    out->found = true;
    out->line = line;
    out->perturbed = c->has_normal;
    return L2P_OK;
}

/* The file a camera message names: its number after the line (none: the scene). */
static const char *file_of(const char *msg, const scene_files *files)
{
    int index, line, k = 0;
    if (sscanf(msg, "lens2pov-camera %d %d %d", &index, &line, &k) < 3 || k < 1 ||
        k >= files->count)
        k = 0;
    return files->path[k];
}

int scene_camera_from_log(const char *log, size_t n, const scene_files *files,
                          scene_camera *out, l2p_error *err)
{
    /* The last statement that ran: it replaces every earlier one entirely (POV-Ray 3.7 starts
       each camera statement from the default camera). */
    size_t pos = 0, last = n;
    char buf[4096];
    int index, line = 0;
    for (size_t at = 0; next_message(log, n, &pos, buf, sizeof buf); at = pos)
        if (sscanf(buf, "lens2pov-camera %d %d", &index, &line) == 2)
            last = at;
    memset(out, 0, sizeof *out);
    if (last == n) {   /* POV-Ray's default camera */
        pov_camera c;
        pov_camera_default(&c);
        c.focus = v3(0, 0, 1);
        int st = to_scene_camera(&c, files->path[0], 0, out, err);
        out->found = false;
        return st;
    }
    pos = last;
    next_message(log, n, &pos, buf, sizeof buf);
    sscanf(buf, "lens2pov-camera %d %d", &index, &line);
    const char *scene = file_of(buf, files);
    pov_camera c;
    pov_camera_default(&c);
    int st = L2P_OK;
    while (!st && next_message(log, n, &pos, buf, sizeof buf) && strcmp(buf, "lens2pov-end")) {
        if (!take_item(&c, buf, scene, line, &st, err) && !st)
            st = item_unreadable(buf, scene, line, err);
    }
    if (!c.has_look_at)
        c.focus = v3_add(c.location, c.direction);   /* before the transforms */
    if (!st)
        st = finish_camera(&c, scene, line, err);
    return st ? st : to_scene_camera(&c, scene, line, out, err);
}

/* One frame message: "lens2pov-frame NUMBER FINAL CLOCK". */
static void take_frame(const char *msg, scene_frames *out, scene_frame *f)
{
    int number = 0, final = 0;
    char clock[64] = "0";
    sscanf(msg, "lens2pov-frame %d %d %63s", &number, &final, clock);
    f->number = number;
    f->clock = strtod(clock, NULL);
    if (final > 0) {   /* POV-Ray declares final_frame only in an animation */
        out->animated = true;
        out->final_frame = final;
    }
}

int scene_frames_from_log(const char *log, size_t n, const scene_files *files,
                          scene_frames *out, l2p_error *err)
{
    memset(out, 0, sizeof *out);
    char buf[4096];
    int count = 0;
    for (size_t pos = 0; next_message(log, n, &pos, buf, sizeof buf);)
        count += !strncmp(buf, "lens2pov-frame ", 15);
    out->frame = calloc((size_t)(count > 0 ? count : 1), sizeof *out->frame);
    if (!out->frame)
        return l2p_fail(err, L2P_FAILED, NULL, 0, "out of memory");
    out->count = count > 0 ? count : 1;
    int k = count > 0 ? -1 : 0, st = L2P_OK;
    size_t start = 0, pos = 0;
    for (size_t at = 0; !st && next_message(log, n, &pos, buf, sizeof buf); at = pos) {
        if (strncmp(buf, "lens2pov-frame ", 15))
            continue;
        if (k >= 0)
            st = scene_camera_from_log(log + start, at - start, files, &out->frame[k].cam, err);
        take_frame(buf, out, &out->frame[++k]);
        start = at;
    }
    if (!st)
        st = scene_camera_from_log(log + start, n - start, files, &out->frame[k].cam, err);
    return st;
}
