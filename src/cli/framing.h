/* Where the lens stands and how much it sees: the scene's camera for the placement when no
   --location, --look-at or --sky is given, and the film width for --angle. */
#ifndef LENS2POV_FRAMING_H
#define LENS2POV_FRAMING_H

#include "camera/camera.h"
#include "cli/cli.h"
#include "base/error.h"
#include "povray/scenecam.h"

/* Reads the scene's camera (src/povray/scenecam.h) when the placement or --angle scene needs
   it, and sets c->cam from it: the lens at the camera's location, looking along its
   direction, its film up along the camera's up, mirrored when the camera's right is, focused
   on the look_at point. */
int framing_from_scene(cli *c, const char *scene, l2p_error *err);

/* The warning for a scene camera with a normal { } (perturbed), which the lens leaves out. */
void framing_warn_perturbed(const char *scene, bool perturbed);
/* Warns that the scene's camera was taken for POV-Ray's default one while an #include of a
   computed name (at line, 0: none) may hold a camera statement lens2pov cannot see. */
void framing_warn_unseen(const char *scene, int line);

/* The same from a scene camera already read (one frame of an animation). */
void framing_apply(cli *c, const scene_camera *sc);

/* camera_setup for the command line: with --angle, the film diagonal that makes the lens's
   horizontal field of view (camera/fieldangle.h: its chief rays at the focus in effect) the
   angle asked (the film keeps its aspect); L2P_BAD_INPUT when it lies beyond the image circle.
   Takes the lens. */
int framing_camera_setup(camera *cam, lens *l, const cli *c, l2p_error *err);

/* framing_camera_setup of the lens found by name or path (cli/lens_lookup.h). */
int framing_load_camera(const cli *c, const char *lens_name, camera *cam, l2p_error *err);

#endif
