#!/bin/sh
# make bench-field-error (issue 14): the time render --sampling field needs to reach the RMSE of
# --sampling pixel at 256 spp, on the four standard lenses (goal: a quarter of pixel's time or
# less). The scene and the error are tools/report.sh's: the bundled scene (pov/scene.pov) with
# its own camera, RMSE over all pixels and channels (idiff) against a reference rendered by
# pixel sampling (full simulation, stop-image pupil) at REF_SPP with a seed of its own, cached in
# out/bench-field/cache/. The reference is pixel sampling's because pixel sampling has no error
# of its own beyond noise (every sample an exact ray): a field reference would share the field
# renders' structured error, and any bias of the ray fields would not show.
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
# tries; default 2048), LENSES (default the four standard lenses).
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
out=out/bench-field
cache=$out/cache
say() { printf 'bench-field-error: %s\n' "$*" >&2; }
die() { say "$*"; exit 1; }
[ -x "$build/lens2pov" ] || die "no $build/lens2pov: run make first"
mkdir -p "$cache"
work=$(mktemp -d "$out/tmp.XXXXXX")
trap 'rm -rf "$work"' EXIT
started=$(date +%s)
echo "processor: $(sed -n 's/^model name[^:]*: *//p' /proc/cpuinfo | head -1), $(nproc) cores"

# A private copy of the binary (its hash keys the cache), as tools/report.sh does.
cp "$build/lens2pov" "$build/lens2pov-image-io.so" "$work/"
bin=$work/lens2pov
version=$(cat "$bin" "$work/lens2pov-image-io.so" | sha256sum | cut -c1-12)
find "$cache" -name 'ref-*.exr' ! -name "*-$version.exr" -exec rm -f {} +
scene_key=$(printf '%s\n' "$camera" | cat "$scene" - | sha256sum | cut -c1-12)
ref_of() {
  key=$1-$(sha256sum "lenses/$1.dat" | cut -c1-8)-${W}x$H-$ref_spp-$scene_key-$version
  echo "$cache/ref-$key.exr"
}
seconds() {
  s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N)
  echo "$s $e" | awk '{ print $2 - $1 }'
}
middle() { printf '%s\n' "$@" | sort -g | sed -n 2p; }
rmse() { idiff "$1" "$2" 2>&1 | sed -n 's/^ *RMS error = //p'; }
# render LENS SAMPLING SPP OUTPUT
render() {
  # shellcheck disable=SC2086 # $camera is a list of options.
  "$bin" render "$scene" "lenses/$1.dat" $camera --width "$W" --height "$H" --sampling "$2" \
      --spp "$3" --quiet -o "$4"
}

# The references, two at a time (their time is not measured).
todo=''
for l in $lenses; do
  [ -f "$(ref_of "$l")" ] || todo="$todo lenses/$l.dat $(ref_of "$l")"
done
if [ -n "$todo" ]; then
  say "references: pixel sampling at $ref_spp spp, two at a time, into $cache"
  t0=$(date +%s)
  export L2P_BIN="$bin" L2P_SCENE="$scene" L2P_CAMERA="$camera" W H ref_spp
  # shellcheck disable=SC2016,SC2086 # expanded by the inner sh; $todo holds plain paths.
  printf '%s %s\n' $todo | xargs -n 2 -P 2 sh -c '
      "$L2P_BIN" render "$L2P_SCENE" "$1" --pupil stop-image --trace full --spp "$ref_spp" \
          --seed 9001 $L2P_CAMERA --width "$W" --height "$H" --quiet -o "$2.tmp.exr" &&
          mv "$2.tmp.exr" "$2" || { echo "the reference render of $1 failed" >&2; exit 1; }' sh ||
      die "reference renders failed"
  refs="references rendered in $(($(date +%s) - t0)) s"
else
  refs="references cached"
fi

echo "== error against time: field sampling to pixel sampling's $pixel_spp-spp RMSE, $scene, ${W}x$H,"
echo "   against pixel sampling at $ref_spp spp (seed 9001); times are medians of three alternating"
echo "   runs (pixel $pixel_spp spp, field at the two spp around the crossing), --jobs $(nproc)"
for l in $lenses; do
  ref=$(ref_of "$l")
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
    p=$(seconds render "$l" pixel $pixel_spp "$work/p.exr")
    fh=$(seconds render "$l" field "$hi" "$work/f.exr")
    fl=$fh
    [ "$lo" = "$hi" ] || fl=$(seconds render "$l" field "$lo" "$work/f.exr")
    f=$(awk -v a="$lo" -v ta="$fl" -v b="$hi" -v tb="$fh" -v s="$at" 'BEGIN {
      print b == a ? tb : ta + (tb - ta) * (s - a) / (b - a) }')
    p_t="$p_t $p" f_t="$f_t $f" r="$r $(awk -v a="$f" -v b="$p" 'BEGIN { print a / b }')"
  done
  # shellcheck disable=SC2086
  awk -v l="$l" -v t="$target" -v at="$at" -v p="$(middle $p_t)" -v f="$(middle $f_t)" \
      -v r="$(middle $r)" -v all="$r" -v ps=$pixel_spp 'BEGIN {
    n = split(all, a, " "); s = ""; for (i = 1; i <= n; i++) s = s sprintf(" %.2f", a[i])
    printf "%s: pixel %d spp RMSE %.4g in %.2f s; field reaches it at %.0f spp in %.2f s; ratio %.2f (goal <= 0.25; turns%s)\n",
           l, ps, t, p, at, f, r, s }'
done
echo "bench-field-error: $(($(date +%s) - started)) s ($refs)"
