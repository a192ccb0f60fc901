#!/bin/sh
# make valgrind: lens2pov under valgrind's memcheck on small runs: info, a trace (with the
# CSV), traces with dispersion (pixel and field sampling), a refused lens (the error path), develop of a file that is not an image and a whole
# render (trace, POV-Ray runner, develop); VALGRIND_ALL=1 adds info with a camera, a thick
# trace, a refused option and develop of a real render (develop and render cost some 10 s
# each: valgrind reads the OpenImageIO libraries that they alone load). Fails (exit 1) on any
# memory error and on any definite or indirect leak; "still reachable" blocks (OpenImageIO's
# and the C++ runtime's caches, freed by the system at exit) and "possibly lost" ones (thread
# stacks) do not count, nor does glibc's own loss while loading OpenImageIO
# (tools/valgrind.supp). POV-Ray itself runs outside valgrind.
#
# Some processors make valgrind unable to load the image library at all: OpenImageIO pulls in
# Google Highway, whose start-up code runs RDTSCP, and valgrind decodes that instruction only
# when the processor's CPUID lists it (some hypervisors hide it on AMD EPYC). The first run
# that loads the library is therefore a probe: when valgrind stops it on an instruction it
# cannot decode in a library that is not lens2pov's, the runs that load the image library are
# skipped with one line saying so; the sanitizer suite (make test-sanitize, with LeakSanitizer)
# runs develop and render on every processor.
set -eu
bin=${1:-build/lens2pov}
case $bin in /*) ;; *) bin=$(pwd)/$bin ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/l2pvalgrind.XXXXXX")
trap 'rm -rf "$work"' EXIT
lens=$root/lenses/dgauss.50mm.dat
status=0
probing=0

# run EXPECTED_EXIT DESCRIPTION ARGS...
run() {
    expect=$1 what=$2
    shift 2
    log=$work/valgrind.$(echo "$what" | tr -c 'a-z0-9\n' '-').log
    set +e
    valgrind --error-exitcode=99 --suppressions="$root/tools/valgrind.supp" --leak-check=full \
        --show-leak-kinds=definite,indirect --errors-for-leak-kinds=definite,indirect \
        --track-origins=yes --num-callers=30 \
        --log-file="$log" "$bin" "$@" >"$work/out" 2>"$work/err"
    got=$?
    set -e
    errors=$(sed -n 's/.*ERROR SUMMARY: \([0-9]*\) errors.*/\1/p' "$log" | tail -1)
    definite=$(sed -n 's/.*definitely lost: \([0-9,]*\) bytes.*/\1/p' "$log" | tail -1)
    indirect=$(sed -n 's/.*indirectly lost: \([0-9,]*\) bytes.*/\1/p' "$log" | tail -1)
    printf '%-44s exit %s, %s errors, definitely lost %s B, indirectly lost %s B\n' "$what" \
        "$got" "${errors:-?}" "${definite:-0}" "${indirect:-0}"
    [ "$probing" = 1 ] && image_library_unusable && return
    if [ "$got" = 99 ] || [ "${errors:-1}" != 0 ]; then
        echo "valgrind: $what: memory errors or leaks:" >&2
        sed -n '/^==[0-9]*== [A-Z].*/,$p' "$log" | head -80 >&2
        status=1
    elif [ "$got" != "$expect" ]; then
        echo "valgrind: $what: exit $got, expected $expect:" >&2
        cat "$work/err" >&2
        status=1
    fi
}

# image_library_unusable: true when the last run ended on SIGILL at an instruction valgrind
# cannot decode in a library that is not lens2pov's; sets $why.
image_library_unusable() {
    [ "$got" = 132 ] || return 1
    grep -q 'Unrecognised instruction' "$log" || return 1
    where=$(sed -n '/Unrecognised instruction/{n;s/.*(in \(.*\)).*/\1/p;q}' "$log")
    case $where in ''|*lens2pov*) return 1 ;; esac
    bytes=$(for b in $(sed -n 's/.*unhandled instruction bytes: \(\(0x[0-9A-F]* \)\{3\}\).*/\1/p' \
            "$log" | head -1); do printf '%02x ' "$b"; done)
    cpu=$(sed -n 's/^model name[^:]*: *//p' /proc/cpuinfo 2>/dev/null | head -1)
    why="$(valgrind --version) cannot decode the instruction ${bytes% } in $where on this processor (${cpu:-unknown})"
}

command -v valgrind >/dev/null || { echo "valgrind: not installed (apt-get install valgrind)" >&2; exit 1; }
echo "== valgrind memcheck over $bin"
run 0 "info --json" info "$lens" --json
all=${VALGRIND_ALL:-0}
[ "$all" = 1 ] && run 0 "info with a camera" info "$lens" --width 32 --height 24 --focus-distance 3
run 0 "trace 32x24x4 --rays" trace "$lens" --width 32 --height 24 --spp 4 --look-at 0,0,3 \
    --rays "$work/t.csv" -o "$work/t" --quiet
[ "$all" = 1 ] && run 0 "trace --trace thick --pupil rear" trace "$lens" --width 16 --height 12 --spp 2 \
    --trace thick --pupil rear -o "$work/k" --quiet
run 0 "trace with dispersion, 16x12x4 --rays" trace "$(dirname "$lens")/cooke-triplet.50mm.dat" \
    --width 16 --height 12 --spp 4 --rays "$work/d.csv" -o "$work/d" --quiet
run 0 "trace --sampling field with dispersion, 24x18x3" trace \
    "$(dirname "$lens")/cooke-triplet.50mm.dat" --width 24 --height 18 --spp 3 --sampling field \
    -o "$work/f" --quiet
printf '50 5 1.5 20\n0 5 0 10\n-50 0 1\n' >"$work/bad.dat"
run 2 "trace of a malformed lens" trace "$work/bad.dat" -o "$work/b" --quiet
# The disk check once read the free space of a folder it could not measure (refused before
# POV-Ray runs or the image library loads).
printf 'background { rgb 1 }\n' >"$work/plain.pov"
run 2 "render of an animation into a missing folder" render "$work/plain.pov" "$lens" \
    --width 8 --height 6 --spp 1 --look-at 0,0,3 -o "$work/nodir/a.png" --quiet -- +KFI1 +KFF2
[ "$all" = 1 ] && run 2 "trace with a bad option" trace "$lens" --aperture-diameter 99 -o "$work/b" --quiet

# The probe: develop loads the image library, which then refuses a file that is not an image.
echo "not an image" >"$work/junk.exr"
probing=1
run 2 "develop of a file that is not an image" develop "$work/t" "$work/junk.exr" -o "$work/j.png"
probing=0
skipped=0
if image_library_unusable; then
    skipped=1
    echo "valgrind: SKIPPED develop and render (they load the image library): $why;" \
         "make test-sanitize runs them under ASan, LeakSanitizer and UBSan"
elif command -v povray >/dev/null; then
    cat >"$work/scene.pov" <<'POV'
#version 3.7;
global_settings { assumed_gamma 1.0 }
background { rgb <0.2, 0.3, 0.4> }
light_source { <-3, 5, -4> color rgb 1 }
sphere { <0, 0, 3>, 0.5 pigment { checker rgb <1, 0.2, 0.2> rgb <0.2, 1, 0.2> scale 0.1 } }
POV
    # develop needs POV-Ray's render of the traced table: the wrapper includes the scene, then
    # the ray table's camera.
    printf '#include "scene.pov"\n#include "t.inc"\n' >"$work/wrap.pov"
    [ "$all" = 1 ] && (cd "$work" && povray t.ini +Iwrap.pov +O"$work/t.exr" -D -V -GA +WT1 >/dev/null 2>&1)
    [ "$all" = 1 ] && run 0 "develop" develop "$work/t" "$work/t.exr" -o "$work/t.png"
    run 0 "render 16x12x2, two POV-Ray jobs" render "$work/scene.pov" "$lens" --width 16 \
        --height 12 --spp 2 --look-at 0,0,3 --jobs 2 -o "$work/r.exr" --quiet
else
    echo "povray not installed: render not checked" >&2
fi
if [ $status != 0 ]; then
    echo "valgrind: FAILED" >&2
elif [ $skipped = 1 ]; then
    echo "valgrind: clean, develop and render skipped (see above)"
else
    echo "valgrind: clean"
fi
exit $status
