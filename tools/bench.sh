#!/bin/sh
# make bench: the tracer's figures; lens2pov trace against POV-Ray's parse of the same
# 1e6-ray include (the target: trace at no more than 10% of POV-Ray's time); lens2pov render
# against POV-Ray's own camera on the same view and primary rays (target: 1.5 or less), and
# one POV-Ray process against two; then an animation (tools/bench_anim.sh) and ray fields
# (tools/bench_field.sh; their error against time is make bench-field-error).
set -e
build=${1:-build}
echo "processor: $(sed -n 's/^model name[^:]*: *//p' /proc/cpuinfo | head -1), $(nproc) cores"
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

# Seconds a command takes (its output discarded).
seconds() {
  s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N)
  echo "$s $e" | awk '{ print $2 - $1 }'
}

# The middle of three numbers.
middle() { printf '%s\n' "$@" | sort -n | sed -n 2p; }

W=320 H=240 SPP=16
scene=pov/bench.pov   # the bundled scene with soft shadows: real shading
lens_render() {
  "$build/lens2pov" render "$scene" lenses/dgauss.50mm.dat --sampling pixel --width $W --height $H --spp $SPP \
      --location 0,1.2,-4 --look-at 0,1,0 -o "$work/lens.png" --quiet "$@"
}
# POV-Ray's camera framed as the lens frames it (its field of view from `info`; the scene's own
# camera sees twice as wide, mostly cheap sky), each film row rendered SPP times.
fov=$("$build/lens2pov" info lenses/dgauss.50mm.dat --width $W --height $H --location 0,1.2,-4 \
    --look-at 0,1,0 | awk '/^horizontal field of view/ { print $5 }')
cat >"$work/perspective.pov" <<POV
#include "bench.pov"
camera { perspective location <0, 1.2, -4> look_at <0, 1, 0> right x * $W / $H up y angle $fov }
POV
perspective_render() {
  (cd pov && povray "$work/perspective.pov" +L"$(pwd)" +W$W +H$((H * SPP)) -A -D -V -GA +FE \
      +O"$work/own.exr")
}

# The three commands run in turn, three times, and each ratio is taken within one turn: on a
# shared machine the speed drifts from one minute to the next.
echo "== lens2pov render against POV-Ray's perspective camera, same view and primary rays"
echo "   (and one POV-Ray process against two); three turns, middle values"
lens_t= pov_t= one_t= ratio= speedup=
for turn in 1 2 3; do
  l=$(seconds lens_render)
  p=$(seconds perspective_render)
  o=$(seconds lens_render --jobs 1)
  lens_t="$lens_t $l" pov_t="$pov_t $p" one_t="$one_t $o"
  ratio="$ratio $(awk -v a="$l" -v b="$p" 'BEGIN { print a / b }')"
  speedup="$speedup $(awk -v a="$o" -v b="$l" 'BEGIN { print a / b }')"
done
awk -v a="$(middle $lens_t)" -v b="$(middle $pov_t)" -v r="$(middle $ratio)" -v fov="$fov" \
    -v n=$((W * H * SPP)) 'BEGIN {
  printf "%d primary rays: lens2pov render %.2f s, povray perspective (%.1f deg) %.2f s, ratio %.2f (target <= 1.5)\n", n, a, fov, b, r }'
echo "   ratios of the three turns:$ratio"
awk -v a="$(middle $one_t)" -v b="$(middle $lens_t)" -v r="$(middle $speedup)" 'BEGIN {
  printf "chunked parallel parse: --jobs 1: %.2f s, --jobs 2: %.2f s, speed-up %.2f\n", a, b, r }'

sh tools/bench_anim.sh "$build"
L2P_BENCH_CPU_SHOWN=1 sh tools/bench_field.sh "$build"
