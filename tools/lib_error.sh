# Sourced (POSIX sh) by tools/report.sh, tools/report_field.sh and tools/bench_field_error.sh:
# image error against a reference picture, and what measuring it needs. The reference is pixel
# sampling's (full simulation, stop-image pupil) at ref_spp samples with a seed of its own
# (9001): pixel sampling has no error but noise, every sample an exact ray, so the error of
# anything measured against it is its noise plus its bias; a reference drawn by ray fields would
# share the field renders' structured error and hide it.
#
# The caller sets: tool (its name, for messages), out (its output folder; the references are
# cached in $out/cache), scene, camera (placement options), W, H, ref_spp, jobs.
# shellcheck shell=sh disable=SC2154,SC2034 # those variables are the caller's; ref_note is for it.

say() { printf '%s: %s\n' "$tool" "$*" >&2; }
die() { say "$*"; exit 1; }
now() { date +%s.%N; }

# err_setup BUILD: $work, a temporary folder removed on exit; $bin, a private copy of BUILD's
# lens2pov with the libraries it looks for beside it (others may rebuild BUILD meanwhile): the
# image library, and the one that shortens POV-Ray's polls, without which every POV-Ray run
# idles between frames and a field render took a quarter longer than the user's; $version, the
# hash of lens2pov and the image library (there is no --version: the binary changes with the
# code; the polls change no pixel), which keys the cache; $cache, with the references of other
# builds removed; $scene_key, the scene and camera's hash.
err_setup() {
  [ -x "$1/lens2pov" ] || die "no $1/lens2pov: run make first"
  [ -r "$scene" ] || die "cannot read scene $scene"
  cache=$out/cache
  mkdir -p "$cache"
  work=$(mktemp -d "$out/tmp.XXXXXX")
  trap 'rm -rf "$work"' EXIT
  cp "$1/lens2pov" "$1/lens2pov-image-io.so" "$1/lens2pov-povray-polls.so" "$work/"
  bin=$work/lens2pov
  version=$(cat "$bin" "$work/lens2pov-image-io.so" | sha256sum | cut -c1-12)
  find "$cache" -name 'ref-*.exr' ! -name "*-$version.exr" -exec rm -f {} +
  scene_key=$(printf '%s\n' "$camera" | cat "$scene" - | sha256sum | cut -c1-12)
}

# err_ref_of NAME: the cached reference of lenses/NAME.dat.
err_ref_of() {
  echo "$cache/ref-$1-$(sha256sum "lenses/$1.dat" | cut -c1-8)-${W}x$H-$ref_spp-$scene_key-$version.exr"
}

# err_references NAME...: renders the references not cached yet, two at a time (their time is
# not measured, and one lens2pov render leaves cores idle while POV-Ray parses its chunks, one
# thread each). Sets $ref_note.
err_references() {
  todo=''
  for n in "$@"; do
    [ -f "$(err_ref_of "$n")" ] || todo="$todo lenses/$n.dat $(err_ref_of "$n")"
  done
  if [ -z "$todo" ]; then
    ref_note=cached
    return 0
  fi
  say "references: pixel sampling at $ref_spp spp, two at a time, into $cache"
  t0=$(now)
  # shellcheck disable=SC2016,SC2086 # expanded by the inner sh; $todo holds plain paths.
  printf '%s %s\n' $todo | L2P_BIN="$bin" L2P_SCENE="$scene" L2P_CAMERA="$camera" W="$W" H="$H" \
      ref_spp="$ref_spp" jobs="$jobs" xargs -n 2 -P 2 sh -c '
      "$L2P_BIN" render "$L2P_SCENE" "$1" --sampling pixel --pupil stop-image --trace full \
          --spp "$ref_spp" --seed 9001 $L2P_CAMERA --width "$W" --height "$H" --jobs "$jobs" \
          --quiet -o "$2.tmp.exr" && mv "$2.tmp.exr" "$2" ||
          { echo "the reference render of $1 failed" >&2; exit 1; }' sh ||
      die "reference renders failed"
  ref_note=$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "rendered in %.0f s", b - a }')
}

# RMSE over all pixels and channels (idiff's "RMS error"); idiff exits non-zero on any difference.
rmse() { idiff "$1" "$2" 2>&1 | sed -n 's/^ *RMS error = //p'; }

# seconds COMMAND...: runs it, its output discarded, and prints its wall time (fails with it).
seconds() {
  s=$(now)
  "$@" >/dev/null 2>&1 || return 1
  awk -v a="$s" -v b="$(now)" 'BEGIN { printf "%.3f\n", b - a }'
}

# median NUMBER...
median() {
  printf '%s\n' "$@" | sort -g |
    awk '{ v[NR] = $1 } END { print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}
