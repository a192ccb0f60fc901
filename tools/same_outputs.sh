#!/bin/sh
# Runs a fixed set of commands with two lens2pov binaries and compares every file they write,
# byte for byte: a refactoring must leave the include, ini, sample map, CSV, developed image and
# info text unchanged. Usage: tools/same_outputs.sh OLD_BINARY NEW_BINARY
set -eu
[ $# -eq 2 ] || { echo "usage: $0 OLD_BINARY NEW_BINARY" >&2; exit 2; }
old=$(realpath "$1")
new=$(realpath "$2")
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d /tmp/same_outputs.XXXXXX)
trap 'rm -rf "$work"' EXIT
L="$root/lenses"

# Each line: a name, then the arguments; OUT is replaced by the output folder's prefix.
cases() {
    cat <<EOF
info_dgauss info $L/dgauss.50mm.dat --width 64 --height 48 --f-number 4
info_fisheye info $L/fisheye.10mm.dat --width 320 --height 240
trace_dgauss trace $L/dgauss.50mm.dat --width 24 --height 16 --spp 3 --f-number 8 --seed 5 --rays OUT.csv -o OUT
trace_wide_rear trace $L/wide.22mm.dat --width 20 --height 14 --spp 2 --pupil rear --location 1,2,-3 --look-at 0,0,0 --rays OUT.csv -o OUT
trace_fisheye trace $L/fisheye.10mm.dat --width 16 --height 16 --spp 2 --film-diagonal 40 --rays OUT.csv -o OUT
trace_tele_thick trace $L/telephoto.250mm.dat --width 16 --height 12 --spp 2 --trace thick --weighting physical --rays OUT.csv -o OUT
trace_stop_crop trace $L/dgauss.50mm.dat --width 32 --height 24 --spp 2 --pupil stop --crop 4,4,20,12 --focus-distance 2 --rays OUT.csv -o OUT
trace_chunks trace $L/dgauss.50mm.dat --width 32 --height 24 --spp 4 --memory-mb 0.05 -o OUT
render_dgauss render $root/pov/scene.pov $L/dgauss.50mm.dat --sampling pixel --width 32 --height 24 --spp 2 --f-number 4 --location 0,1,-4 --look-at 0,0.5,0 --jobs 2 --quiet -o OUT.exr
EOF
}

run_all() {   # binary folder
    bin=$1
    dir=$2
    cases | while read -r name args; do
        mkdir -p "$dir/$name"
        # shellcheck disable=SC2086
        set -- $(echo "$args" | sed "s#OUT#$dir/$name/out#g")
        (cd "$dir/$name" && "$bin" "$@" >stdout.txt 2>stderr.txt; echo $? >status.txt) || true
    done
}

run_all "$old" "$work/old"
run_all "$new" "$work/new"
# Paths of the two folders appear in includes and messages: compare with them made equal.
differ=0
# Images are compared by their pixels and metadata, leaving out the time they were written;
# messages leaving out the durations they report.
digest() {   # folder file
    case $2 in
    *.exr | *.png | *.tif)
        oiiotool --info -v "$1/$2" --dumpdata "$1/$2" | grep -v 'DateTime\|^Reading\|^/' | md5sum ;;
    */stderr.txt) sed -E "s#$1#W#g; s/[0-9]+\.[0-9]+ s\b/T s/g" "$1/$2" | md5sum ;;   # timings
    *) sed "s#$1#W#g" "$1/$2" | md5sum ;;
    esac
}
for f in $(cd "$work/old" && find . -type f | sort); do
    if ! [ -f "$work/new/$f" ] || ! [ "$(digest "$work/old" "$f")" = "$(digest "$work/new" "$f")" ]; then
        echo "differs: $f"
        differ=$((differ + 1))
    fi
done
n=$(cd "$work/old" && find . -type f | wc -l)
m=$(cd "$work/new" && find . -type f | wc -l)
[ "$n" -eq "$m" ] || { echo "old wrote $n files, new $m"; differ=$((differ + 1)); }
echo "$n files compared, $differ differ"
[ "$differ" -eq 0 ]
