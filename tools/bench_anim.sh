#!/bin/sh
# make bench, animations: lens2pov render of a 10-frame animation of the bundled scene
# (pov/scene.pov, the camera moving sideways with the clock) against POV-Ray's own camera with
# the same view and primary rays, per frame; and what tracing the lens once saves against
# tracing it for every frame (ten one-frame renders, +K CLOCK each). Usage: bench_anim.sh BUILD
set -e
build=${1:-build}
work=$(mktemp -d "${TMPDIR:-/tmp}/l2panim.XXXXXX")
trap 'rm -rf "$work"' EXIT
W=${W:-320} H=${H:-240} SPP=${SPP:-16} FRAMES=${FRAMES:-10}
root=$(pwd)
lens=lenses/dgauss.50mm.dat

seconds() {
  s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N)
  echo "$s $e" | awk '{ print $2 - $1 }'
}

# The scene's own camera replaced by one that slides 1 m to the right over the animation:
# the focus (the look_at point) stays 4 m ahead, so one ray table serves every frame.
cat >"$work/anim.pov" <<POV
#include "scene.pov"
camera { location <clock - 0.5, 1.2, -4> look_at <clock - 0.5, 1, 0> }
POV
fov=$("$build/lens2pov" info $lens --width $W --height $H --location 0,1.2,-4 \
    --look-at 0,1,0 | awk '/^horizontal field of view/ { print $5 }')
cat >"$work/perspective.pov" <<POV
#include "scene.pov"
camera { perspective location <clock - 0.5, 1.2, -4> look_at <clock - 0.5, 1, 0>
         right x * $W / $H up y angle $fov }
POV

animation() {
  "$build/lens2pov" render "$work/anim.pov" $lens --sampling pixel --width $W --height $H --spp $SPP \
      --quiet -o "$work/lens.png" "$@" -- +L"$root/pov" +KFI1 +KFF$FRAMES
}
perspective() {   # each film row rendered SPP times: the same primary rays
  (cd pov && povray "$work/perspective.pov" +L"$root/pov" +W$W +H$((H * SPP)) -A -D -V -GA \
      +FE +O"$work/own.exr" +KFI1 +KFF$FRAMES)
}
every_frame() {   # the lens traced again for each frame: ten one-frame renders
  for f in $(seq 1 $FRAMES); do
    clock=$(awk -v f="$f" -v n=$FRAMES 'BEGIN { print (f - 1) / (n - 1) }')
    "$build/lens2pov" render "$work/anim.pov" $lens --sampling pixel --width $W --height $H --spp $SPP \
        --quiet -o "$work/one$f.png" -- +L"$root/pov" +K"$clock"
  done
}
trace_once() {
  "$build/lens2pov" trace $lens --width $W --height $H --spp $SPP --location 0,1.2,-4 \
      --look-at 0,1,0 --quiet -o "$work/t"
}

echo "== an animation: $FRAMES frames of pov/scene.pov, ${W}x$H, $SPP spp, the camera moving"
a=$(seconds animation)
p=$(seconds perspective)
e=$(seconds every_frame)
t=$(seconds trace_once)
awk -v a="$a" -v p="$p" -v e="$e" -v t="$t" -v n=$FRAMES -v fov="$fov" 'BEGIN {
  printf "per frame: lens2pov render %.2f s, povray perspective (%.1f deg) %.2f s, ratio %.2f\n",
         a / n, fov, p / n, a / p
  printf "traced once: %.2f s for %d frames; traced every frame: %.2f s (saved %.2f s a frame; one trace alone %.2f s)\n",
         a, n, e, (e - a) / n, t }'
