#!/bin/sh
# make demo: the bundled scene through the double-Gauss at f/2.8, focused on the subject 4 m
# away (the look-at point), into out/demo.png.
set -e
bin=${1:-build/lens2pov}
mkdir -p out
"$bin" render pov/scene.pov lenses/dgauss.50mm.dat --width 640 --height 480 --spp 32 \
    --location 0,1.2,-4 --look-at 0,1,0 --f-number 2.8 -o out/demo.png
echo "demo: wrote out/demo.png"
