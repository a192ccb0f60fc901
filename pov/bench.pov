// The bundled scene with the shading a production scene pays for: a soft area light (8 x 8
// samples, adaptive) beside the sun, so that each primary ray costs what rays in real scenes
// cost. make bench renders it through the lens and with POV-Ray's own camera.
#include "scene.pov"
light_source {
  <-30, 40, -25> color rgb <1.0, 0.97, 0.9> * 0.6
  area_light <6, 0, 0>, <0, 0, 6>, 8, 8 adaptive 1 jitter circular orient
}
