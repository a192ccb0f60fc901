/* What the scene-camera tests share (test_scene_camera.c, test_scene_camera_refused.c): a
   scene of three coloured markers, and POV-Ray's own picture of a scene against the lens's. */
#ifndef LENS2POV_SCENE_MARKERS_H
#define LENS2POV_SCENE_MARKERS_H

#include "support.h"

#define DGAUSS LENS_DIR "dgauss.50mm.dat"
#define L2P(out, errtext, ...) run_lens2pov(out, errtext, __VA_ARGS__, (char *)NULL)
#define SIZE "--width", "64", "--height", "48"

/* The camera uses #declared vectors, an expression, a macro, angle and image_width. */
#define MARKERS_HEAD                                                                            \
    "#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"                                    \
    "#declare Eye = <1, 1.5, -4>;\n#declare Target = <0.2, 0.5, 0>;\n"                         \
    "#macro Lift(V) (V + <0, 0.5, 0> * 2) #end\n"                                               \
    "#macro Marker(P, C) sphere { P, 0.06 pigment { rgb C }\n"                                  \
    "    finish { ambient 0 emission 1 diffuse 0 } } #end\n"                                   \
    "Marker(Target, <1, 0, 0>)\nMarker(Target + <0.8, 0, 0>, <0, 1, 0>)\n"                      \
    "Marker(Target + <0, 0.6, 0.3>, <0, 0, 1>)\n"

#define CAMERA(right)                                                                           \
    "camera {\n  location Lift(Eye) // where it stands\n  look_at Target\n  angle 40\n"        \
    "  right " right " * image_width / image_height\n}\n"

/* The scene, in dir, through the lens, with no placement and --angle scene, against POV-Ray's
   camera: each marker within a pixel; library, when not NULL, a folder given to both as +L. */
void expect_markers_in(const char *dir, const char *scene_text, const char *library);

/* The same in a fresh folder. */
void expect_markers_as_povray(const char *scene_text);

#endif
