#!/bin/sh
# Render a POV-Ray scene through every lens file, with each of the seed's three variants, and
# assemble a labelled contact sheet (one row per lens, one column per variant).
#
#   examples/render-all-lenses.sh SCENE OUTDIR [lens2pov render options...]
#
# Writes OUTDIR/<lens>-rear-full.png, <lens>-stop-image-full.png, <lens>-stop-image-thick.png
# and OUTDIR/contact-sheet.png. Extra options go to every `lens2pov render`.
# Defaults, each used only when you give none of its kind:
#   size      --width 320 --height 240 --spp 16
#   placement the scene's own camera (lens2pov render's default without --location,
#             --look-at and --sky); the film 35 mm full frame unless --angle or
#             --film-diagonal is given.
# Environment: LENS2POV (the binary; default build/lens2pov of this repo, else lens2pov on
# PATH), LENS_DIR (default lenses/ of this repo), FONT (oiiotool font, default DejaVuSans).
#
# A failed render (for instance a lens that cannot focus as close as the look-at point) is
# reported with its lens, variant and command line; the other renders still run, its tile in
# the contact sheet says "failed", and the script exits 1 at the end. When every render of the
# first two lenses fails, the scene or the options are wrong for all lenses: it stops there.
set -u

me=render-all-lenses.sh
say() { printf '%s: %s\n' "$me" "$*" >&2; }
die() { say "$*"; exit 2; }

if [ $# -lt 2 ] || [ "$1" = -h ] || [ "$1" = --help ]; then
    sed -n '2,/^set -u/{/^#/s/^# \{0,1\}//p}' "$0" >&2
    exit 2
fi
scene=$1
outdir=$2
shift 2

here=$(CDPATH='' cd -- "$(dirname -- "$0")" && pwd) || exit 2
repo=$(dirname -- "$here")
# From a clone, the repository's lenses and build; installed (PREFIX/bin/lens2pov-render-all),
# PREFIX/share/lens2pov/lenses and the lens2pov beside it.
lens_dir=$repo/lenses
[ -d "$lens_dir" ] || lens_dir=$repo/share/lens2pov/lenses
lens_dir=${LENS_DIR:-$lens_dir}
font=${FONT:-DejaVuSans}
if [ -n "${LENS2POV:-}" ]; then
    bin=$LENS2POV
elif [ -x "$repo/build/lens2pov" ]; then
    bin=$repo/build/lens2pov
elif [ -x "$here/lens2pov" ]; then
    bin=$here/lens2pov
else
    bin=$(command -v lens2pov) || die "no lens2pov: run make in $repo, put it on PATH or set LENS2POV"
fi
command -v oiiotool >/dev/null || die "oiiotool not found (Debian package openimageio-tools)"
{ [ -f "$scene" ] && [ -r "$scene" ]; } || die "cannot read scene '$scene'"
total=0
for lens in "$lens_dir"/*.dat; do
    [ -f "$lens" ] || die "no lens files (*.dat) in '$lens_dir'"
    total=$((total + 3))
done

# Which kinds of options did the user give? (--opt VALUE and --opt=VALUE both count.)
have_size=''
for a in "$@"; do
    case $a in
        --width | --width=* | --height | --height=*) have_size=1 ;;
        -o | --output | --output=* | --pupil | --pupil=* | --trace | --trace=*)
            die "$a is set by this script (it renders every variant into OUTDIR)" ;;
    esac
done

defaults=''
[ -n "$have_size" ] || defaults='--width 320 --height 240 --spp 16'
# Without --location, --look-at and --sky, lens2pov render places the lens as the scene's own
# camera, evaluated by POV-Ray (README). The film stays 35 mm, so that each lens shows its own
# field of view; --angle scene would refuse the lenses that cannot see as wide as the scene.
# shellcheck disable=SC2086 # $defaults holds separate words without blanks or globs.
set -- $defaults "$@"

# The command line, quoted so that it can be pasted back into a shell.
quoted() {
    q=''
    for a in "$@"; do
        case $a in
            '' | *[!A-Za-z0-9_./,=:+@%-]*) a="'$(printf '%s' "$a" | sed "s/'/'\\\\''/g")'" ;;
        esac
        q="$q $a"
    done
    printf '%s' "${q# }"
}

mkdir -p -- "$outdir" || die "cannot make folder '$outdir'"
variants='rear-full stop-image-full stop-image-thick'
lenses=0 done_ok=0 failed='' n=0
for lens in "$lens_dir"/*.dat; do
    name=$(basename -- "$lens" .dat)
    lenses=$((lenses + 1))
    for v in $variants; do
        n=$((n + 1))
        case $v in
            rear-full) vopts='--pupil rear --trace full' ;;
            stop-image-full) vopts='--pupil stop-image --trace full' ;;
            stop-image-thick) vopts='--pupil stop-image --trace thick' ;;
        esac
        out=$outdir/$name-$v.png
        # A stale picture from an earlier run must not stand in for a failed render.
        rm -f -- "$out"
        say "[$n/$total] $name $v -> $out"
        # shellcheck disable=SC2086 # $vopts is four plain words.
        if "$bin" render "$scene" "$lens" "$@" $vopts -o "$out"; then
            done_ok=$((done_ok + 1))
        else
            st=$?
            # shellcheck disable=SC2086
            say "FAILED (exit $st): lens $name, variant $v: $(quoted "$bin" render "$scene" "$lens" "$@" $vopts -o "$out")"
            failed="$failed $name/$v"
        fi
    done
    if [ "$lenses" -ge 2 ] && [ "$done_ok" -eq 0 ]; then
        die "every render of the first $lenses lenses failed: stopping (see the messages above)"
    fi
done

# The contact sheet: a label column, a header row, and one 320x240 tile per render (fitted and
# padded, so that any image size or aspect fits). oiiotool's --paste puts the image *below* the
# top of the stack onto the top one, hence the --swap after each tile.
tile_w=320 tile_h=240 gap=6 label_w=230 head_h=34
sheet_w=$((label_w + 3 * (tile_w + gap)))
sheet_h=$((head_h + lenses * (tile_h + gap)))
text="--text:size=18:color=0.95,0.95,0.95:font=$font"
contact_sheet() {
    tmp=$outdir/contact-sheet.tmp$$.png
    set -- --pattern constant:color=0.13,0.13,0.13 "${sheet_w}x$sheet_h" 3
    col=0
    for v in $variants; do
        set -- "$@" "$text:x=$((label_w + col * (tile_w + gap) + 8)):y=24" "$v"
        col=$((col + 1))
    done
    row=0
    for lens in "$lens_dir"/*.dat; do
        name=$(basename -- "$lens" .dat)
        y=$((head_h + row * (tile_h + gap)))
        set -- "$@" "$text:x=10:y=$((y + tile_h / 2))" "$name"
        col=0
        for v in $variants; do
            x=$((label_w + col * (tile_w + gap)))
            if [ -f "$outdir/$name-$v.png" ]; then
                set -- "$@" "$outdir/$name-$v.png" --ch R,G,B --fit:pad=1 "${tile_w}x$tile_h"
            else
                set -- "$@" --pattern constant:color=0.35,0.08,0.08 "${tile_w}x$tile_h" 3 \
                    "$text:x=110:y=$((tile_h / 2))" "render failed"
            fi
            set -- "$@" --swap --paste "+$x+$y"
            col=$((col + 1))
        done
        row=$((row + 1))
    done
    if oiiotool "$@" -o "$tmp" && mv -f -- "$tmp" "$outdir/contact-sheet.png"; then
        say "contact sheet: $outdir/contact-sheet.png"
    else
        rm -f -- "$tmp"
        say "FAILED: the contact sheet (oiiotool; is the font '$font' installed? Debian: fonts-dejavu-core)"
        return 1
    fi
}
contact_sheet || failed="$failed contact-sheet"

if [ -n "$failed" ]; then
    say "$done_ok of $total renders done; failed:$failed"
    say "(lens2pov's reason is above each FAILED line; a lens that cannot focus on the look-at" \
        "point needs --focus-distance UNITS or --film-distance MM)"
    exit 1
fi
say "$done_ok of $total renders done in $outdir"
