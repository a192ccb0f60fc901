#!/bin/sh
# Pixel sampling above field sampling, side by side by spp, the reference at the right: the
# pictures tools/report_field.sh keeps in out/report/field-pictures/ (LENS-pixel-SPP.exr,
# LENS-field-SPP.exr, LENS-reference.exr), drawn as one PNG a lens (linear values as sRGB,
# 8 bits, each rendered pixel as SCALE x SCALE pixels, labelled in DejaVu Sans when fc-match
# finds it).
#
#   sh tools/field_pictures.sh SCALE OUTDIR LENS...     (writes OUTDIR/field-pictures-LENS.png)
#
# Environment: PICTURE_SPPS (default "4 16 64 256"), REF_SPP (the reference's, for its label;
# default 1024).
set -eu
cd "$(dirname "$0")/.."
[ $# -ge 3 ] || { echo "usage: sh tools/field_pictures.sh SCALE OUTDIR LENS..." >&2; exit 2; }
scale=$1 dir=$2
shift 2
pics=out/report/field-pictures
pic_spps=${PICTURE_SPPS:-4 16 64 256}
ref_spp=${REF_SPP:-1024}
die() { printf 'field_pictures: %s\n' "$*" >&2; exit 1; }
size=$(oiiotool --info "$pics/$1-reference.exr" 2>/dev/null | sed -n 's/.*: *\([0-9]*\) x *\([0-9]*\),.*/\1x\2/p')
[ -n "$size" ] || die "no $pics/$1-reference.exr: run make report-field first"
W=${size%x*} H=${size#*x}
font=$(fc-match -f '%{file}' 'DejaVu Sans' 2>/dev/null || :)
[ -n "$font" ] || printf 'field_pictures: no DejaVu Sans (fc-match): no labels\n' >&2
w=$((W * scale)) h=$((H * scale)) gap=4 left=44 top=18
n=$(echo "$pic_spps" | wc -w)
cw=$((left + (n + 1) * (w + gap))) ch=$((top + 2 * (h + gap)))
label() { [ -z "$font" ] || printf '%s\n' "--text:x=$1:y=$2:size=12:color=0,0,0:font=$font" "$3"; }
# pic EXR X Y: the picture, pasted (--swap: the canvas is the background) at X, Y.
pic() {
  [ -f "$1" ] || die "no $1"
  printf '%s\n' "$1" --ch R,G,B --colorconvert linear sRGB --resample:interp=0 "${w}x$h" --swap --paste "+$2+$3"
}
mkdir -p "$dir"
args=$(mktemp)
trap 'rm -f "$args"' EXIT
for l in "$@"; do
  {
    i=0
    for s in $pic_spps; do
      x=$((left + i * (w + gap)))
      pic "$pics/$l-pixel-$s.exr" "$x" "$top"
      pic "$pics/$l-field-$s.exr" "$x" $((top + h + gap))
      label $((x + 2)) $((top - 4)) "$s spp"
      i=$((i + 1))
    done
    x=$((left + n * (w + gap))) y=$((top + (h + gap) / 2))
    pic "$pics/$l-reference.exr" "$x" "$y"
    label $((x + 2)) $((y - 4)) "reference, $ref_spp spp"
    label 2 $((top + h / 2 + 4)) pixel
    label 2 $((top + h + gap + h / 2 + 4)) field
  } >"$args"
  # One argument a line (the labels hold spaces; the paths none).
  # shellcheck disable=SC2046
  (set -f; IFS='
'; oiiotool --pattern constant:color=1,1,1 "${cw}x$ch" 3 $(cat "$args") -d uint8 \
      -o "$dir/field-pictures-$l.png") || die "$l: oiiotool could not draw the pictures"
done
