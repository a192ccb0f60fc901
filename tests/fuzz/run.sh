#!/bin/sh
# make fuzz: builds the libFuzzer targets of tests/fuzz/ with clang (AddressSanitizer and
# UndefinedBehaviorSanitizer) against the sources in src/, and runs each for a short time
# from the committed seed corpus. Exits non-zero when a target crashes, leaks or trips a
# sanitizer; the input that did it is kept as build-fuzz/crash-<target>-*.
#
#   FUZZ_SECONDS  seconds per target (default 14)
#   FUZZ_BUILD    build folder (default build-fuzz, removed by make clean)
#   FUZZ_CC       compiler (default clang; needs libclang-rt-14-dev for -fsanitize=fuzzer)
#   FUZZ_CFLAGS, FUZZ_SANITIZERS   compiler and sanitizer flags: make fuzz passes the Makefile's
#
# New inputs the fuzzer finds go to FUZZ_BUILD/corpus-*, never into the committed seeds.
# To replay one input: build-fuzz/fuzz_lens FILE (or fuzz_options, fuzz_scene FILE).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${FUZZ_BUILD:-$root/build-fuzz}
cc=${FUZZ_CC:-clang}
seconds=${FUZZ_SECONDS:-14}
# The language and sanitizer flags are the Makefile's: run this as make fuzz.
san=${FUZZ_SANITIZERS:?"run it as make fuzz, which gives the flags"}
cflags="${FUZZ_CFLAGS:?"run it as make fuzz, which gives the flags"} -I$root/src"

mkdir -p "$out/obj"
# Every C source but main.c and povray_polls.c (a library POV-Ray preloads), instrumented for coverage (fuzzer-no-link), into an archive: the
# link then takes only the objects a target needs (no OpenImageIO, no POV-Ray runner).
objs=
for src in "$root"/src/*/*.c; do
    name=$(basename "$src" .c)
    [ "$name" = main ] || [ "$name" = povray_polls ] && continue
    $cc $cflags $san -fsanitize=fuzzer-no-link -c "$src" -o "$out/obj/$name.o"
    objs="$objs $out/obj/$name.o"
done
rm -f "$out/liblens2pov-fuzz.a"
ar rcs "$out/liblens2pov-fuzz.a" $objs

status=0
for target in lens options scene; do
    $cc $cflags $san -fsanitize=fuzzer "$here/fuzz_$target.c" "$out/liblens2pov-fuzz.a" -lm \
        -o "$out/fuzz_$target"
    mkdir -p "$out/corpus-$target"
    dict=
    [ -f "$here/$target.dict" ] && dict="-dict=$here/$target.dict"
    echo "== fuzz_$target: $seconds s from tests/fuzz/corpus/$target"
    # The first folder receives new inputs; the committed seeds are only read.
    if ! "$out/fuzz_$target" -max_total_time="$seconds" -max_len=4096 -timeout=10 \
            -rss_limit_mb=2048 -print_final_stats=1 $dict \
            -artifact_prefix="$out/crash-$target-" \
            "$out/corpus-$target" "$here/corpus/$target" 2>"$out/fuzz_$target.log"; then
        status=1
        grep -E 'ERROR|SUMMARY|fuzz_(lens|options|scene):|Test unit written' "$out/fuzz_$target.log" >&2 || true
        echo "fuzz_$target: FAILED (log: $out/fuzz_$target.log)" >&2
    fi
    grep -E '^(Done|stat::number_of_executed_units|stat::peak_rss_mb)' "$out/fuzz_$target.log" || true
    grep -E '^#[0-9]+ +DONE +cov' "$out/fuzz_$target.log" | tail -1 || true
done
exit $status
