/* The camera a scene ends with, as POV-Ray evaluates it. POV-Ray 3.7 cannot print a camera, so
   lens2pov copies the scene with every `camera { ... }` statement replaced by #debug lines that
   print the statement's items (each vector, angle and transform evaluated by POV-Ray where the
   statement stands), lets POV-Ray parse the copy, and applies POV-Ray's own camera rules
   (parser.cpp, Parse_Camera) to the items of the last statement that ran
   (docs/povray.md, "The scene's camera"). */
#ifndef LENS2POV_SCENECAM_H
#define LENS2POV_SCENECAM_H

#include <stdbool.h>
#include <stddef.h>
#include "base/error.h"
#include "base/vec3.h"

typedef struct scene_camera {
    vec3 location;
    vec3 forward, up;          /* unit, perpendicular */
    bool mirrored;             /* right points against up x direction: the picture is mirrored */
    double focus_distance;     /* ahead to focal blur's plane (focal_point), else to the
                                  look_at point, else |direction| */
    double hfov_deg;           /* horizontal angle: 2 atan(|right| / (2 |direction|)) */
    bool found;                /* false: no camera statement ran, POV-Ray's default camera */
    int line;                  /* the statement's line in its file (0 when not found) */
    bool perturbed;            /* it has a normal { }, which the lens leaves out */
    int computed_include;      /* not found: the line of an #include of a computed name in
                                  the scene, whose camera statement would not be seen; 0 */
} scene_camera;

/* Runs POV-Ray on a copy of the scene at width x height (image_width and image_height read so)
   and gives the camera it ends with. L2P_BAD_INPUT, naming the scene and line, for a camera
   lens2pov cannot stand in for; L2P_FAILED with POV-Ray's error when the scene fails. */
int scene_camera_read(const char *scene_path, int width, int height, scene_camera *out,
                      l2p_error *err);

/* One frame of an animation: its number and clock as POV-Ray computes them, and its camera. */
typedef struct scene_frame {
    int number;
    double clock;
    scene_camera cam;
} scene_frame;

typedef struct scene_frames {
    scene_frame *frame;        /* in the order POV-Ray renders them */
    int count;
    bool animated;             /* POV-Ray numbers the frames' outputs (+KFI, +KFF, ...) */
    int final_frame;           /* for the digits of those numbers */
} scene_frames;

/* scene_camera_read with POV-Ray's own options (args, given before lens2pov's): the frames
   POV-Ray renders with them and each frame's camera. Without args, POV-Ray is not run for a
   scene without a camera statement (one frame, its default camera) nor for one whose camera
   is literal (scene_camera_literal_log) when no ini could change its version. */
int scene_frames_read(const char *scene_path, int width, int height, char *const *args,
                      int arg_count, scene_frames *out, l2p_error *err);
void scene_frames_free(scene_frames *f);

/* Whether an ini POV-Ray reads before the scene (POVINI, a povray.ini in the scene's folder,
   the user's, the system's) names frames, the clock, the language version or another ini:
   then POV-Ray may render the scene as an animation, or at another clock, without options. */
bool scene_inis_set_frames(const char *scene_path);

/* The files the probe's messages name: path[0] the scene, path[k] the k-th included file
   whose copy prints its camera statements (scene_copy_make). */
typedef struct scene_files {
    const char *const *path;
    int count;
} scene_files;

/* The frames of POV-Ray's output: from each "lens2pov-frame" message to the next, one
   camera (scene_camera_from_log). */
int scene_frames_from_log(const char *log, size_t n, const scene_files *files,
                          scene_frames *out, l2p_error *err);

/* The copy's text: every camera statement of text replaced by its #debug lines, on as many
   lines as the statement took, so that POV-Ray's messages keep their line numbers. */
char *scene_camera_rewrite(const char *text, size_t n);
/* The same for file number file (scene_files), which the messages then carry. */
char *scene_camera_rewrite_file(const char *text, size_t n, int file);

/* The probe's copy of a scene: its text rewritten, and every file it includes (nested too;
   found in the scene's folder, then in the library folders, NULL-terminated) that holds a
   camera statement, or includes one that does, copied into work rewritten as file number k;
   each #include of such a file points at its copy. */
typedef struct scene_copy {
    char *text;                /* the scene's copy */
    char **path, **copy;       /* [k], k >= 1: an included file, as found, and its copy in
                                  work ([0] the scene, no copy) */
    int count;
    bool unresolved;           /* an #include names a file not found as POV-Ray finds files:
                                  only POV-Ray can say what it holds, or that it is missing */
} scene_copy;
int scene_copy_make(const char *scene, const char *text, size_t n, const char *work,
                    char *const *library, scene_copy *out, l2p_error *err);
/* Removes the included files' copies and frees c. */
void scene_copy_free(scene_copy *c);

/* What the probe's copy of text would print, frame and camera, when the scene's camera needs
   no POV-Ray to evaluate: every camera statement outside #if, #while, #macro and other blocks,
   its items literals (numbers, <a, b, c>, x, y, z) of location, look_at, direction, up, right,
   sky and angle, and a literal #version from 3.5 to 3.7 in effect. NULL otherwise (and for a
   scene without a camera statement). */
char *scene_camera_literal_log(const char *text, size_t n);

/* The camera from the #debug lines of POV-Ray's output (log, n bytes); files name the scene
   and its rewritten includes in messages. */
int scene_camera_from_log(const char *log, size_t n, const scene_files *files,
                          scene_camera *out, l2p_error *err);

/* Calls visit with the name and line of every `#include "NAME"` of text (not in comments),
   in order, until it returns false. */
typedef bool (*scene_include_visit)(const char *name, size_t len, int line, void *ctx);
void scene_text_includes(const char *text, size_t n, scene_include_visit visit, void *ctx);

/* Whether text has a camera statement scene_camera_rewrite would replace; *line gets the
   first one's line. */
bool scene_text_has_camera(const char *text, size_t n, int *line);

/* The line of the first #include whose file is named by an expression, not a string (0 for
   none): lens2pov cannot see a camera statement in that file. */
int scene_text_computed_include(const char *text, size_t n);

#endif
