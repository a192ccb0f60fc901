#!/bin/sh
# make valgrind: lens2pov under valgrind's memcheck on small runs: info, a trace (with the
# CSV), a refused lens (the error path) and a whole render (trace, POV-Ray runner, develop);
# VALGRIND_ALL=1 adds info with a camera, a thick trace, a refused option and develop on its
# own (develop and render cost some 10 s each: valgrind reads the OpenImageIO libraries that
# they alone load). Fails (exit 1) on any memory error and on any definite or indirect leak;
# "still reachable" blocks (OpenImageIO's and the C++ runtime's caches, freed by the system at
# exit) and "possibly lost" ones (thread stacks) do not count, nor does glibc's own loss while
# loading OpenImageIO (tools/valgrind.supp). POV-Ray itself runs outside valgrind.
set -eu
bin=${1:-build/lens2pov}
case $bin in /*) ;; *) bin=$(pwd)/$bin ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/l2pvalgrind.XXXXXX")
trap 'rm -rf "$work"' EXIT
lens=$root/lenses/dgauss.50mm.dat
status=0

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

command -v valgrind >/dev/null || { echo "valgrind: not installed (apt-get install valgrind)" >&2; exit 1; }
echo "== valgrind memcheck over $bin"
run 0 "info --json" info "$lens" --json
all=${VALGRIND_ALL:-0}
[ "$all" = 1 ] && run 0 "info with a camera" info "$lens" --width 32 --height 24 --focus-distance 3
run 0 "trace 32x24x4 --rays" trace "$lens" --width 32 --height 24 --spp 4 --look-at 0,0,3 \
    --rays "$work/t.csv" -o "$work/t" --quiet
[ "$all" = 1 ] && run 0 "trace --trace thick --pupil rear" trace "$lens" --width 16 --height 12 --spp 2 \
    --trace thick --pupil rear -o "$work/k" --quiet
printf '50 5 1.5 20\n0 5 0 10\n-50 0 1\n' >"$work/bad.dat"
run 2 "trace of a malformed lens" trace "$work/bad.dat" -o "$work/b" --quiet
[ "$all" = 1 ] && run 2 "trace with a bad option" trace "$lens" --aperture-diameter 99 -o "$work/b" --quiet
if command -v povray >/dev/null; then
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
    echo "povray not installed: develop and render not checked" >&2
fi
[ $status = 0 ] && echo "valgrind: clean" || echo "valgrind: FAILED" >&2
exit $status
