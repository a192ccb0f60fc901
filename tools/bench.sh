#!/bin/sh
# make bench: the tracer's figures, then lens2pov trace against POV-Ray's parse of the same
# 1e6-ray include (the target: trace at no more than 10% of POV-Ray's time).
set -e
build=${1:-build}
work=$(mktemp -d "${TMPDIR:-/tmp}/l2pbench.XXXXXX")
trap 'rm -rf "$work"' EXIT
"$build/bench_trace" lenses "$work"

echo "== lens2pov trace against POV-Ray's parse of the same include (1024x1024 x 1 spp)"
t0=$(date +%s.%N)
"$build/lens2pov" trace lenses/dgauss.50mm.dat --width 1024 --height 1024 --spp 1 \
    --look-at 0,0,10 -o "$work/p" --quiet
t1=$(date +%s.%N)
faces=$(grep -o 'face_indices { [0-9]*' "$work/p.inc" | grep -o '[0-9]*$')
cat >"$work/scene.pov" <<POV
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { rgb <0.2, 0.3, 0.4> }
#include "p.inc"
POV
# One thread, so parse time is not hidden by tracing on the other core.
(cd "$work" && povray p.ini +Iscene.pov +O"$work/p.exr" -D -V -GA +WT1 >/dev/null 2>&1)
t2=$(date +%s.%N)
awk -v a="$t0" -v b="$t1" -v c="$t2" -v n="$faces" 'BEGIN {
  printf "lens2pov trace: %.2f s   povray (parse + render, 1 thread): %.2f s   ratio %.1f%%   (%d faces)\n",
         b - a, c - b, 100 * (b - a) / (c - b), n }'

# Medians of three runs of a command, in seconds.
median3() {
  for i in 1 2 3; do
    s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N)
    echo "$s $e" | awk '{ print $2 - $1 }'
  done | sort -n | sed -n 2p
}

echo "== lens2pov render against POV-Ray's perspective camera, same view and primary rays (median of 3)"
W=320 H=240 SPP=16
scene=pov/bench.pov   # the bundled scene with soft shadows: real shading
lens_t=$(median3 "$build/lens2pov" render "$scene" lenses/dgauss.50mm.dat --width $W --height $H \
    --spp $SPP --location 0,1.2,-4 --look-at 0,1,0 -o "$work/lens.png" --quiet)
# POV-Ray's camera framed as the lens frames it (its field of view from `info`; the scene's own
# camera sees twice as wide, mostly cheap sky), each film row rendered SPP times.
fov=$("$build/lens2pov" info lenses/dgauss.50mm.dat --width $W --height $H --location 0,1.2,-4 \
    --look-at 0,1,0 | awk '/^horizontal field of view/ { print $5 }')
cat >"$work/perspective.pov" <<POV
#include "bench.pov"
camera { perspective location <0, 1.2, -4> look_at <0, 1, 0> right x * $W / $H up y angle $fov }
POV
pov_t=$(median3 sh -c "cd pov && povray '$work/perspective.pov' +L'$(pwd)/pov' +W$W +H$((H * SPP)) -A -D -V -GA +FE +O'$work/own.exr'")
awk -v a="$lens_t" -v b="$pov_t" -v fov="$fov" -v n=$((W * H * SPP)) 'BEGIN {
  printf "%d primary rays: lens2pov render %.2f s, povray perspective (%.1f deg) %.2f s, ratio %.2f (target <= 1.5)\n", n, a, fov, b, a / b }'

echo "== chunked parallel parse: one POV-Ray process against two (same picture, median of 3)"
one=$(median3 "$build/lens2pov" render "$scene" lenses/dgauss.50mm.dat --width $W --height $H \
    --spp $SPP --location 0,1.2,-4 --look-at 0,1,0 -o "$work/one.png" --quiet --jobs 1)
awk -v a="$one" -v b="$lens_t" 'BEGIN {
  printf "--jobs 1: %.2f s, --jobs 2: %.2f s, speed-up %.2f\n", a, b, a / b }'
