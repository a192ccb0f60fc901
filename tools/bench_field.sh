#!/bin/sh
# make bench, ray fields (issue 14): lens2pov render --sampling field against POV-Ray's own
# perspective camera with the same view and primary rays, on the shaded bench scene
# (pov/bench.pov) and on a light one written here, at 16, 64 and 256 spp (goal: 1.15 or
# less); --sampling pixel beside it at 16 and 64 spp; then faces, POV-Ray memory and parse time
# a sample, field against pixel, from the renders' kept work folders.
#
#   sh tools/bench_field.sh [BUILD]
#
# Environment: SIZE (default 160x120), SPPS (default "16 64 256"), PIXEL_SPPS (the spp at which
# pixel sampling is timed too; default "16 64": 256 spp is 4.9 M faces at 160x120, about 1 GB
# of POV-Ray memory), COST_SIZE and COST_SPP (the per-sample figures; default 320x240, 16).
# The error against time is tools/bench_field_error.sh (make bench-field-error).
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
size=${SIZE:-160x120}
spps=${SPPS:-16 64 256}
pixel_spps=${PIXEL_SPPS:-16 64}
cost_size=${COST_SIZE:-320x240}
cost_spp=${COST_SPP:-16}
W=${size%x*} H=${size#*x}
root=$(pwd)
lens=lenses/dgauss.50mm.dat
camera='--location 0,1.2,-4 --look-at 0,1,0'
work=$(mktemp -d "${TMPDIR:-/tmp}/l2pfield.XXXXXX")
trap 'rm -rf "$work"' EXIT
command -v /usr/bin/time >/dev/null || { echo "bench_field: needs GNU time (/usr/bin/time)" >&2; exit 1; }
[ -n "${L2P_BENCH_CPU_SHOWN:-}" ] ||
    echo "processor: $(sed -n 's/^model name[^:]*: *//p' /proc/cpuinfo | head -1), $(nproc) cores"
started=$(date +%s)

seconds() {
  s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N)
  echo "$s $e" | awk '{ print $2 - $1 }'
}
middle() { printf '%s\n' "$@" | sort -g | sed -n 2p; }

# The light scene: plain pigments, one point light, no area lights, no reflection.
cat >"$work/light.pov" <<'POV'
// make bench's light scene: a few plain-pigment objects, one point light.
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { rgb <0.6, 0.7, 0.9> }
light_source { <-30, 40, -25> color rgb 1 }
camera { location <0, 1.2, -4> look_at <0, 1, 0> }
plane { y, 0 pigment { rgb <0.55, 0.55, 0.5> } }
sphere { <0, 1, 0>, 0.5 pigment { rgb <0.8, 0.2, 0.2> } }
box { <-1.7, 0, -0.4>, <-0.9, 0.8, 0.4> pigment { rgb <0.2, 0.6, 0.3> } }
cylinder { <1.3, 0, 0.5>, <1.3, 1.6, 0.5>, 0.25 pigment { rgb <0.2, 0.3, 0.8> } }
sphere { <0.5, 0.3, -1.3>, 0.3 pigment { rgb <0.9, 0.8, 0.2> } }
torus { 0.35, 0.08 rotate x * 90 translate <-0.6, 1.6, 1.5> pigment { rgb 0.9 } }
POV

# POV-Ray's camera framed as the lens frames it (the field of view from `info`), each film row
# rendered SPP times: the same primary rays as a lens render at SPP.
# shellcheck disable=SC2086 # $camera is a list of options.
fov=$("$build/lens2pov" info $lens --width "$W" --height "$H" $camera |
      awk '/^horizontal field of view/ { print $5 }')
for s in bench light; do
  if [ $s = bench ]; then inc=$root/pov/bench.pov; else inc=$work/light.pov; fi
  cat >"$work/perspective-$s.pov" <<POV
#include "$inc"
camera { perspective location <0, 1.2, -4> look_at <0, 1, 0> right x * $W / $H up y angle $fov }
POV
done
scene_of() { if [ "$1" = bench ]; then echo pov/bench.pov; else echo "$work/light.pov"; fi; }
# lens_render SCENE SAMPLING SPP [options]
lens_render() {
  sc=$1 sampling=$2 spp=$3; shift 3
  # shellcheck disable=SC2086
  "$build/lens2pov" render "$(scene_of "$sc")" $lens --width "$W" --height "$H" --spp "$spp" \
      $camera --sampling "$sampling" -o "$work/lens.exr" --quiet "$@"
}
perspective_render() {   # SCENE SPP
  (cd pov && povray "$work/perspective-$1.pov" +L"$root/pov" +W"$W" +H$((H * $2)) -A -D -V -GA \
      +FE +O"$work/own.exr")
}

echo "== render --sampling field against POV-Ray's perspective camera ($(printf %.1f "$fov") deg), same view and"
echo "   primary rays, ${W}x$H, $lens at full aperture, --jobs $(nproc); medians of three"
echo "   alternating runs (field, perspective, pixel), each ratio taken within its run"
for sc in bench light; do
  for spp in $spps; do
    f_t='' p_t='' x_t='' f_r='' x_r='' timing_pixel=''
    for s in $pixel_spps; do [ "$s" = "$spp" ] && timing_pixel=1; done
    for _ in 1 2 3; do
      f=$(seconds lens_render $sc field "$spp")
      p=$(seconds perspective_render $sc "$spp")
      f_t="$f_t $f" p_t="$p_t $p"
      f_r="$f_r $(awk -v a="$f" -v b="$p" 'BEGIN { print a / b }')"
      if [ -n "$timing_pixel" ]; then
        x=$(seconds lens_render $sc pixel "$spp")
        x_t="$x_t $x" x_r="$x_r $(awk -v a="$x" -v b="$p" 'BEGIN { print a / b }')"
      fi
    done
    # shellcheck disable=SC2086
    awk -v sc="$(scene_of $sc | sed 's|.*/||')" -v spp="$spp" -v f="$(middle $f_t)" \
        -v p="$(middle $p_t)" -v r="$(middle $f_r)" -v all="$f_r" 'BEGIN {
      n = split(all, a, " "); t = ""; for (i = 1; i <= n; i++) t = t sprintf(" %.2f", a[i])
      printf "%s %d spp: field %.2f s, perspective %.2f s, ratio %.2f (goal <= 1.15; turns%s)\n",
             sc, spp, f, p, r, t }'
    if [ -n "$timing_pixel" ]; then
      # shellcheck disable=SC2086
      awk -v sc="$(scene_of $sc | sed 's|.*/||')" -v spp="$spp" -v x="$(middle $x_t)" \
          -v r="$(middle $x_r)" 'BEGIN {
        printf "%s %d spp: pixel %.2f s, ratio to perspective %.2f (for comparison)\n", sc, spp, x, r }'
    fi
  done
done

# Faces, memory and parse time a sample (a sample: one sub-image of field sampling, one layer of
# W x H rays of pixel sampling). Each sampling renders the light scene once with its work folder
# kept; then every POV-Ray run of it is repeated here with statistics on (+GS, which lens2pov's
# own runs turn off) and one image row (+SR2 +ER2: the parse and the whole image buffer, hardly
# any shading), its peak resident memory read by GNU time. The scene alone (16x16) is the
# baseline subtracted from each run's parse time and memory. Three alternating turns, medians.
CW=${cost_size%x*} CH=${cost_size#*x}
for sampling in pixel field; do
  # shellcheck disable=SC2086
  "$build/lens2pov" render "$work/light.pov" $lens --width "$CW" --height "$CH" --spp "$cost_spp" \
      $camera --sampling $sampling -o "$work/$sampling.exr" --quiet --keep-temp "$work/keep-$sampling"
done
# One POV-Ray run: prints "PARSE_SECONDS PEAK_KB".
pov_stats() {   # INI WRAPPER
  /usr/bin/time -f 'peak %M' povray "$1" +I"$2" +L"$root/pov" +O"$work/stats.exr" -D -P -C -UA -A \
      -V +GS -GR +FE +SR2 +ER2 2>&1 |
    awk '/Parse Time:/ { gsub(/[()]/, ""); p = $(NF - 1) } /^peak / { m = $2 } END { print p, m }'
}
echo '#include "light.pov"' >"$work/alone.pov"
alone() {
  /usr/bin/time -f 'peak %M' povray +I"$work/alone.pov" +L"$work" +O"$work/stats.exr" +W16 +H16 \
      -D -P -C -UA -A -V +GS -GR +FE 2>&1 |
    awk '/Parse Time:/ { gsub(/[()]/, ""); p = $(NF - 1) } /^peak / { m = $2 } END { print p, m }'
}
# Sums over the runs of one sampling, less the baseline each: "PARSE_SECONDS PEAK_KB RUNS".
runs_stats() {   # KEEP_DIR BASE_PARSE BASE_KB
  for inc in "$1"/rays.c*.inc "$1"/field.f*.inc; do
    [ -f "$inc" ] || continue
    printf '#include "%s"\n#include "%s"\n' "$work/light.pov" "$inc" >"$work/one.pov"
    pov_stats "${inc%.inc}.ini" "$work/one.pov"
  done | awk -v bp="$2" -v bm="$3" '{ p += $1 - bp; m += $2 - bm; n++ } END { print p, m, n }'
}
faces() { cat "$1"/*.inc | grep -o 'face_indices { [0-9]*' | awk '{ n += $3 } END { print n }'; }
inc_bytes() { cat "$1"/*.inc | wc -c; }
px_p='' px_m='' fd_p='' fd_m='' px_n='' fd_n=''
for _ in 1 2 3; do
  for sampling in pixel field; do
    # shellcheck disable=SC2046 # two numbers
    set -- $(alone)
    # shellcheck disable=SC2046 # three numbers
    set -- $(runs_stats "$work/keep-$sampling" "$1" "$2")
    if [ $sampling = pixel ]; then px_p="$px_p $1" px_m="$px_m $2" px_n=$3
    else fd_p="$fd_p $1" fd_m="$fd_m $2" fd_n=$3; fi
  done
done
# shellcheck disable=SC2086
awk -v spp="$cost_spp" -v size="$cost_size" -v pf="$(faces "$work/keep-pixel")" \
    -v ff="$(faces "$work/keep-field")" -v pb="$(inc_bytes "$work/keep-pixel")" \
    -v fb="$(inc_bytes "$work/keep-field")" -v pp="$(middle $px_p)" -v fp="$(middle $fd_p)" \
    -v pm="$(middle $px_m)" -v fm="$(middle $fd_m)" -v pn="$px_n" -v fn="$fd_n" 'BEGIN {
  printf "== a sample (one sub-image, or one layer of %s rays), field against pixel: light.pov,\n", size
  printf "   %s, %d spp, %d POV-Ray runs for pixel, %d for field; parse and memory: medians of three\n", size, spp, pn, fn
  printf "   alternating turns of those runs, less the scene alone in each run\n"
  printf "faces a sample: pixel %.0f, field %.0f (%.1f times fewer)\n", pf / spp, ff / spp, pf / ff
  printf "include bytes a sample: pixel %.0f kB, field %.1f kB (%.1f times fewer)\n", pb / spp / 1e3, fb / spp / 1e3, pb / fb
  printf "POV-Ray peak memory a sample, above the scene alone: pixel %.2f MB, field %.2f MB (%.1f times less)\n", pm / spp / 1024, fm / spp / 1024, pm / fm
  printf "POV-Ray parse time a sample: pixel %.1f ms, field %.2f ms (%.0f times less)\n", 1e3 * pp / spp, 1e3 * fp / spp, pp / fp }'
echo "bench_field: $(($(date +%s) - started)) s; error against time: make bench-field-error (several minutes)"
