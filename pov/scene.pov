// lens2pov's demo scene: made to show what a real lens does. Units are metres.
//
//   depth of field   foreground flowers 1.5 m from the camera, the subject (sphere, text and
//                    checker cube on a plinth) at 4 m, a colonnade and lamps 10-30 m away
//   distortion       a tiled floor, rows of straight pillars and beams, the open horizon
//   vignetting       a bright, nearly even sky filling the upper corners
//   bokeh            small glowing lamps (brighter than white) against a dark hedge far
//                    behind the subject, chrome balls with the sun's highlight
//
// Render it on its own:  povray scene.pov +W640 +H480
// Through a lens:        lens2pov render scene.pov LENS --location 0,1.2,-4 --look-at 0,1,0 ...
// Fast on purpose: one light, no radiosity, no media, no area lights.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

#include "colors.inc"

camera {
  location <0, 1.2, -4>
  look_at <0, 1, 0>
}

// The sun, low and to the left, for shadows that show the shapes.
light_source { <-30, 40, -25> color rgb <1.0, 0.97, 0.9> * 1.1 }

// A bright sky: near white at the horizon, pale blue above; even enough to show vignetting.
sky_sphere {
  pigment {
    gradient y
    color_map {
      [0.00 color rgb <0.95, 0.96, 0.97>]
      [0.35 color rgb <0.80, 0.88, 0.98>]
      [1.00 color rgb <0.60, 0.75, 0.95>]
    }
  }
}

// The floor: half-metre tiles to the horizon, lines straight in every direction.
plane {
  y, 0
  texture {
    pigment { checker color rgb <0.75, 0.73, 0.68> color rgb <0.25, 0.27, 0.30> scale 0.5 }
    finish { ambient 0.15 diffuse 0.75 }
  }
}

// ---------------------------------------------------------------- the subject, 4 m away
#declare Plinth = box { <-0.45, 0, -0.35>, <0.45, 0.55, 0.35> }
object { Plinth texture { pigment { color rgb 0.85 } finish { ambient 0.15 diffuse 0.8 } } }

// A polished red sphere: reflections and a specular highlight.
sphere {
  <-0.15, 0.85, 0>, 0.30
  texture {
    pigment { color rgb <0.75, 0.08, 0.06> }
    finish { ambient 0.1 diffuse 0.6 specular 0.8 roughness 0.002 reflection 0.15 }
  }
}

// A small cube with a fine checker: sharp only where the focus is.
box {
  <-0.12, 0, -0.12>, <0.12, 0.24, 0.12>
  texture {
    pigment { checker color White color rgb <0.05, 0.15, 0.5> scale 0.03 }
    finish { ambient 0.15 diffuse 0.8 }
  }
  rotate 30 * y
  translate <0.28, 0.55, -0.05>
}

// Text to judge sharpness by, on the front of the plinth.
text {
  ttf "timrom.ttf" "lens2pov" 0.01, 0
  texture { pigment { color rgb <0.05, 0.05, 0.05> } finish { ambient 0.1 diffuse 0.7 } }
  scale 0.2
  translate <-0.36, 0.3, -0.36>
}

// ---------------------------------------------------------------- foreground, 1.5 m away
#macro Flower(Position, Height, Colour)
  union {
    cylinder { <0, 0, 0>, <0, Height, 0>, 0.008 texture { pigment { color rgb <0.15, 0.45, 0.1> } } }
    sphere { <0, Height, 0>, 0.045
      texture { pigment { color Colour } finish { ambient 0.15 diffuse 0.8 specular 0.3 } } }
    translate Position
  }
#end
Flower(<-0.45, 0, -2.55>, 0.95, rgb <0.95, 0.75, 0.1>)
Flower(<-0.30, 0, -2.45>, 0.88, rgb <0.9, 0.3, 0.6>)
Flower(<-0.55, 0, -2.35>, 0.82, rgb <0.95, 0.95, 0.95>)
Flower(< 0.42, 0, -2.50>, 0.90, rgb <0.3, 0.5, 0.95>)

// ---------------------------------------------------------------- the background, 10-30 m
// Two rows of white pillars along the view, 3 m apart, and nearer ones at the sides: straight
// vertical lines at every distance from the centre of the frame.
// They are low enough for the sky to fill the upper corners of a normal lens's frame.
#declare Pillar = union {
  cylinder { <0, 0, 0>, <0, 2.2, 0>, 0.12 }
  box { <-0.2, 0, -0.2>, <0.2, 0.15, 0.2> }
  box { <-0.2, 2.2, -0.2>, <0.2, 2.32, 0.2> }
  texture { pigment { color rgb 0.9 } finish { ambient 0.15 diffuse 0.8 } }
}
#for (Z, -1, 29, 3)
  object { Pillar translate <-3.0, 0, Z> }
  object { Pillar translate < 3.0, 0, Z> }
#end
#for (Z, -3, 6, 3)
  object { Pillar translate <-6.0, 0, Z> }
  object { Pillar translate < 6.0, 0, Z> }
#end

// A beam along each row, a long straight line near the top of the frame.
#declare Beam = box { <-0.2, 2.32, -1.2>, <0.2, 2.47, 29.2>
  texture { pigment { color rgb 0.85 } finish { ambient 0.15 diffuse 0.8 } } }
object { Beam translate -3 * x }
object { Beam translate 3 * x }

// A dark hedge closing the colonnade: a backdrop for the lamps.
box {
  <-2.7, 0, 30>, <2.7, 2.0, 31.5>
  texture {
    pigment { color rgb <0.04, 0.10, 0.05> }
    normal { bumps 0.6 scale 0.08 }
    finish { ambient 0.2 diffuse 0.6 }
  }
}

// Glowing lamps, brighter than white, in front of the hedge: discs of light out of focus.
#declare Lamp = sphere { 0, 0.05
  texture { pigment { color rgb <1.0, 0.75, 0.4> } finish { emission 8 diffuse 0 } } no_shadow }
#for (I, 0, 8)
  object { Lamp translate <-2.0 + 0.5 * I, 1.0 + 0.12 * mod(I, 3), 28> }
#end
#for (I, 0, 5)
  object { Lamp translate <-1.25 + 0.5 * I, 1.35 + 0.1 * mod(I, 2), 20> }
#end

// Chrome balls on the floor, 10-15 m away: small, sharp highlights of the sun.
#declare Chrome = texture {
  pigment { color rgb 0.6 }
  finish { ambient 0 diffuse 0.1 specular 1 roughness 0.0005 reflection 0.7 }
}
sphere { <-1.6, 0.15, 10>, 0.15 texture { Chrome } }
sphere { < 1.2, 0.15, 12>, 0.15 texture { Chrome } }
sphere { <-0.6, 0.15, 15>, 0.15 texture { Chrome } }
