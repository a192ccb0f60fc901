#!/bin/sh
# make bench-field-error (issue 14): the time render --sampling field needs to reach the RMSE of
# --sampling pixel at 256 spp, on the four standard lenses (goal: a quarter of pixel's time or
# less). The scene and the error are tools/report.sh's: the bundled scene (pov/scene.pov) with
# its own camera, RMSE over all pixels and channels (idiff) against a reference rendered by
# pixel sampling (full simulation, stop-image pupil) at REF_SPP with a seed of its own, cached in
# out/bench-field/cache/ (tools/lib_error.sh, shared with tools/report.sh, says why pixel
# sampling's).
#
#   sh tools/bench_field_error.sh [BUILD]
#
# For each lens: pixel sampling at 256 spp gives the target RMSE; field sampling renders at
# 4, 8, 16, ... spp until its RMSE is at or below it; the spp where it gets there is
# interpolated between the last two (log RMSE against log spp), and its time between their
# times (linear in spp). Times: three alternating turns of pixel at 256 spp and field at those
# two spp, the ratio taken within each turn; medians.
#
# Environment: SIZE (default 96x72), REF_SPP (default 1024), MAX_SPP (the most field sampling
# tries; default 2048), LENSES (default the four standard lenses), FIELD_OPTS (options added to
# every field render, e.g. --adaptive; default none).
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
size=${SIZE:-96x72}
ref_spp=${REF_SPP:-1024}
max_spp=${MAX_SPP:-2048}
lenses=${LENSES:-dgauss.50mm wide.22mm fisheye.10mm telephoto.250mm}
pixel_spp=256
scene=pov/scene.pov
camera='--location 0,1.2,-4 --look-at 0,1,0'
W=${size%x*} H=${size#*x}
jobs=$(nproc)
out=out/bench-field
tool=bench-field-error
# shellcheck source=tools/lib_error.sh
. tools/lib_error.sh
err_setup "$build"
started=$(date +%s)
echo "processor: $(sed -n 's/^model name[^:]*: *//p' /proc/cpuinfo | head -1), $(nproc) cores"

# render LENS SAMPLING SPP OUTPUT
render() {
  opts=''
  [ "$2" = pixel ] || opts=${FIELD_OPTS:-}
  # shellcheck disable=SC2086 # $camera and $opts are lists of options.
  "$bin" render "$scene" "lenses/$1.dat" $camera --width "$W" --height "$H" --sampling "$2" \
      --spp "$3" $opts --quiet -o "$4"
}

# shellcheck disable=SC2086 # plain lens names.
err_references $lenses

echo "== error against time: field sampling${FIELD_OPTS:+ $FIELD_OPTS} to pixel sampling's $pixel_spp-spp RMSE, $scene, ${W}x$H,"
echo "   against pixel sampling at $ref_spp spp (seed 9001); times are medians of three alternating"
echo "   runs (pixel $pixel_spp spp, field at the two spp around the crossing), --jobs $(nproc)"
for l in $lenses; do
  ref=$(err_ref_of "$l")
  render "$l" pixel $pixel_spp "$work/p.exr" || die "$l: pixel render failed"
  target=$(rmse "$work/p.exr" "$ref")
  [ -n "$target" ] || die "$l: idiff gave no RMS error"
  # Field sampling at doubling spp until it reaches the target.
  s=4 lo='' lo_e='' hi='' hi_e='' sweep=''
  while [ "$s" -le "$max_spp" ]; do
    render "$l" field "$s" "$work/f.exr" || die "$l: field render at $s spp failed"
    e=$(rmse "$work/f.exr" "$ref")
    sweep="$sweep $s:$e"
    if awk -v e="$e" -v t="$target" 'BEGIN { exit !(e <= t) }'; then hi=$s hi_e=$e; break; fi
    lo=$s lo_e=$e s=$((s * 2))
  done
  echo "$l field RMSE by spp:$sweep (pixel $pixel_spp spp: $target)"
  if [ -z "$hi" ]; then
    echo "$l: field sampling does not reach pixel's $pixel_spp-spp RMSE $target by $max_spp spp"
    continue
  fi
  # The spp where the RMSE crosses the target, interpolated in log-log (4 spp when the first
  # render already reaches it).
  at=$(awk -v a="$lo" -v ea="$lo_e" -v b="$hi" -v eb="$hi_e" -v t="$target" 'BEGIN {
    if (a == "") { print b; exit }
    f = (log(t) - log(ea)) / (log(eb) - log(ea)); print exp(log(a) + f * (log(b) - log(a))) }')
  [ -n "$lo" ] || lo=$hi
  p_t='' f_t='' r=''
  for _ in 1 2 3; do
    p=$(seconds render "$l" pixel $pixel_spp "$work/p.exr") || die "$l: pixel render failed"
    fh=$(seconds render "$l" field "$hi" "$work/f.exr") || die "$l: field render failed"
    fl=$fh
    [ "$lo" = "$hi" ] || fl=$(seconds render "$l" field "$lo" "$work/f.exr") || die "$l: field render failed"
    f=$(awk -v a="$lo" -v ta="$fl" -v b="$hi" -v tb="$fh" -v s="$at" 'BEGIN {
      print b == a ? tb : ta + (tb - ta) * (s - a) / (b - a) }')
    p_t="$p_t $p" f_t="$f_t $f" r="$r $(awk -v a="$f" -v b="$p" 'BEGIN { print a / b }')"
  done
  # shellcheck disable=SC2086
  awk -v l="$l" -v t="$target" -v at="$at" -v p="$(median $p_t)" -v f="$(median $f_t)" \
      -v r="$(median $r)" -v all="$r" -v ps=$pixel_spp 'BEGIN {
    n = split(all, a, " "); s = ""; for (i = 1; i <= n; i++) s = s sprintf(" %.2f", a[i])
    printf "%s: pixel %d spp RMSE %.4g in %.2f s; field reaches it at %.0f spp in %.2f s; ratio %.2f (goal <= 0.25; turns%s)\n",
           l, ps, t, p, at, f, r, s }'
done
echo "bench-field-error: $(($(date +%s) - started)) s (references $ref_note)"
