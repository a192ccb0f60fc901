#!/bin/sh
# The field part of make report (issue 14): render --sampling pixel against --sampling field on
# the four standard lenses, in image error against wall time, with tools/report.sh's scene, size,
# spp and references (tools/lib_error.sh: pixel sampling at REF_SPP, the same reference for both
# samplings). Writes out/report/field.md (tables, the spp where each sampling wins, the default
# spp's verdict), field-error-vs-time.csv/.gp/.png, field-pictures/ (the pictures at 4, 16, 64
# and 256 spp, EXR) and field-pictures-LENS.png (drawn from them by tools/field_pictures.sh).
# tools/report.sh runs it after its own part; make report-field runs it alone.
#
#   sh tools/report_field.sh [BUILD]     (BUILD: the folder holding lens2pov; default build)
#
# Environment: as tools/report.sh (SCENE, CAMERA, SIZE, SPPS, REF_SPP, JOBS), and FIELD_LENSES
# (default the four standard lenses), TURNS (timed runs of each render, default 3; the times are
# their medians, pixel and field alternating at each spp, the first of the two swapped each turn),
# PICTURE_SPPS (default "4 16 64 256"), PICTURE_SCALE (pixels a rendered pixel, default 2).
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
scene=${SCENE:-pov/scene.pov}
camera=${CAMERA:---location 0,1.2,-4 --look-at 0,1,0}
size=${SIZE:-128x96}
spps=${SPPS:-1 4 16 64 256}
ref_spp=${REF_SPP:-1024}
jobs=${JOBS:-2}
lenses=${FIELD_LENSES:-dgauss.50mm wide.22mm fisheye.10mm telephoto.250mm}
turns=${TURNS:-3}
pic_spps=${PICTURE_SPPS:-4 16 64 256}
scale=${PICTURE_SCALE:-2}
default_spp=16
W=${size%x*} H=${size#*x}
out=out/report
tool=report-field
# shellcheck source=tools/lib_error.sh
. tools/lib_error.sh
err_setup "$build"
started=$(date +%s)
processor="$(sed -n 's/^model name[^:]*: *//p' /proc/cpuinfo | head -1), $(nproc) cores"

# render LENS SAMPLING SPP OUTPUT
render() {
  # shellcheck disable=SC2086 # $camera is a list of options.
  "$bin" render "$scene" "lenses/$1.dat" $camera --width "$W" --height "$H" --sampling "$2" \
      --spp "$3" --jobs "$jobs" --quiet -o "$4"
}
# shellcheck disable=SC2086 # plain lens names.
err_references $lenses

rm -rf "$out/field-pictures"
mkdir -p "$out/field-pictures"

# Every render TURNS times; the RMSE from the first turn (a render is the same picture every
# time: the samples come from the seed), the time the median of the turns. The pictures of
# PICTURE_SPPS are kept from the first turn, in out/report/field-pictures/.
: >"$work/times"
: >"$work/rmse"
turn=1
while [ "$turn" -le "$turns" ]; do
  say "turn $turn of $turns"
  for l in $lenses; do
    ref=$(err_ref_of "$l")
    for s in $spps; do
      order='pixel field'
      [ $((turn % 2)) = 1 ] || order='field pixel'
      for m in $order; do
        t=$(seconds render "$l" "$m" "$s" "$work/x.exr") || die "$l $m $s spp: render failed"
        echo "$l $m $s $t" >>"$work/times"
        if [ "$turn" = 1 ]; then
          e=$(rmse "$work/x.exr" "$ref")
          [ -n "$e" ] || die "$l $m $s spp: idiff gave no RMS error"
          echo "$l $m $s $e" >>"$work/rmse"
          say "$l $m $s spp: RMSE $e, $t s"
          case " $pic_spps " in *" $s "*) mv "$work/x.exr" "$out/field-pictures/$l-$m-$s.exr" ;; esac
        fi
      done
    done
  done
  turn=$((turn + 1))
done

csv=$out/field-error-vs-time.csv
echo 'lens,sampling,spp,seconds,rmse,seconds_by_turn' >"$work/f.csv"
for l in $lenses; do
  for m in pixel field; do
    for s in $spps; do
      ts=$(awk -v l="$l" -v m="$m" -v s="$s" '$1 == l && $2 == m && $3 == s { printf "%s%s", n++ ? " " : "", $4 }' "$work/times")
      e=$(awk -v l="$l" -v m="$m" -v s="$s" '$1 == l && $2 == m && $3 == s { print $4 }' "$work/rmse")
      # shellcheck disable=SC2086 # a list of plain numbers.
      echo "$l,$m,$s,$(median $ts),$e,$ts" >>"$work/f.csv"
    done
  done
done
mv "$work/f.csv" "$csv"

# The pictures: kept in out/report/field-pictures/ with the references, drawn by
# tools/field_pictures.sh.
for l in $lenses; do
  cp "$(err_ref_of "$l")" "$out/field-pictures/$l-reference.exr"
done
# shellcheck disable=SC2086 # plain lens names.
PICTURE_SPPS="$pic_spps" REF_SPP="$ref_spp" sh tools/field_pictures.sh "$scale" "$out" $lenses ||
  die "the pictures could not be drawn"

# The figure: one panel a lens, pixel and field sampling, log-log, each point labelled by spp.
nl=$(echo "$lenses" | wc -w)
rows=$(((nl + 1) / 2))
{
  echo "set terminal pngcairo size 1100,$((380 * rows)) font 'DejaVu Sans,10'"
  echo "set output '$out/field-error-vs-time.png'"
  echo "set datafile separator ','"
  echo "set logscale xy; set grid; set key top right"
  echo "set xlabel 'wall time of lens2pov render (s, median of $turns)'; set ylabel 'RMSE against the reference (linear)'"
  echo "set multiplot layout $rows,2 title 'pixel against field sampling, ${W}x$H, spp $spps, reference pixel sampling at $ref_spp spp'"
  for l in $lenses; do
    m="strcol(1) eq '$l'"
    echo "set title '$l'"
    echo "plot '$csv' using (($m && strcol(2) eq 'pixel') ? \$4 : NaN):5 with linespoints lw 2 pt 7 lc rgb '#1b9e77' title 'pixel', \\"
    echo "  '' using (($m && strcol(2) eq 'field') ? \$4 : NaN):5 with linespoints lw 2 pt 5 lc rgb '#d95f02' title 'field', \\"
    echo "  '' using (($m && strcol(2) eq 'pixel') ? \$4 : NaN):5:3 with labels offset 0,1 font ',8' tc rgb '#1b9e77' notitle, \\"
    echo "  '' using (($m && strcol(2) eq 'field') ? \$4 : NaN):5:3 with labels offset 0,-1 font ',8' tc rgb '#d95f02' notitle"
  done
  echo "unset multiplot"
} >"$out/field-error-vs-time.gp"
gnuplot "$out/field-error-vs-time.gp" || die "gnuplot failed"

# field.md, from the measured numbers; its "In short" also goes to stdout.
elapsed=$(($(date +%s) - started))
awk -F, -v W="$W" -v H="$H" -v spps="$spps" -v ref_spp="$ref_spp" -v scene="$scene" \
    -v camera="$camera" -v version="$version" -v elapsed="$elapsed" -v refs="$ref_note" \
    -v jobs="$jobs" -v processor="$processor" -v turns="$turns" -v dspp="$default_spp" \
    -v lenses="$lenses" -v pics="$pic_spps" -v scale="$scale" -v short="$work/short" '
FNR == 1 { next }
{ t[$1, $2, $3] = $4; e[$1, $2, $3] = $5; turn[$1, $2, $3] = $6 }
# The frontier of sampling m on lens l: its runs by time, each kept when its RMSE is below every
# faster run'"'"'s (a slower run with more error tells nothing about what the time buys): fn
# points (ft[k], fe[k]), time rising, RMSE falling.
function frontier(l, m,    i, j, k, x) {
    for (i = 1; i <= ns; i++) o[i] = sp[i]
    for (i = 2; i <= ns; i++) for (j = i; j > 1 && t[l, m, o[j]] < t[l, m, o[j - 1]]; j--) { x = o[j]; o[j] = o[j - 1]; o[j - 1] = x }
    fn = 0
    for (i = 1; i <= ns; i++) {
        k = o[i]
        if (fn == 0 || e[l, m, k] < fe[fn]) { fn++; ft[fn] = t[l, m, k]; fe[fn] = e[l, m, k] }
    }
}
# Pixel sampling'"'"'s RMSE in time x: its frontier, log RMSE linear in log time between points;
# beyond its ends the noise law, RMSE ~ time^-1/2, from the nearest end (xt set: extrapolated).
function p_at(l, x,    k) {
    frontier(l, "pixel")
    if (x < ft[1] || x > ft[fn]) { xt = 1; k = x < ft[1] ? 1 : fn; return fe[k] * sqrt(ft[k] / x) }
    for (k = 1; k < fn && x > ft[k + 1]; k++) ;
    return k == fn ? fe[k] : lerp(log(x), log(ft[k]), log(ft[k + 1]), fe[k], fe[k + 1])
}
# Field sampling'"'"'s time to RMSE y: its frontier likewise, time ~ RMSE^-2 beyond its low end;
# an RMSE its fastest run already beats gets that run'"'"'s time (xt = 2: at most).
function f_time(l, y,    k) {
    frontier(l, "field")
    if (y > fe[1]) { xt = 2; return ft[1] }
    if (y < fe[fn]) { xt = 1; return ft[fn] * (fe[fn] / y) ^ 2 }
    for (k = 1; k < fn && y < fe[k + 1]; k++) ;
    return k == fn ? ft[k] : lerp(log(y), log(fe[k]), log(fe[k + 1]), ft[k], ft[k + 1])
}
# u at x, log u linear in x through (a, ua) and (b, ub).
function lerp(x, a, b, ua, ub) { return exp(log(ua) + (x - a) / (b - a) * (log(ub) - log(ua))) }
function mark(v, x) { return sprintf("%s%.2f", x == 1 ? "~" : (x == 2 ? "<=" : ""), v) }
# Where log r crosses 0 between spp a and b (r: ratios at a and b).
function cross(a, b, ra, rb) { return exp(log(a) + log(ra) / (log(ra) - log(rb)) * (log(b) - log(a))) }
END {
    nl = split(lenses, L, " "); ns = split(spps, sp, " "); np = split(pics, pp, " ")
    for (i = 1; i <= nl; i++) for (q = 1; q <= ns; q++) {
        l = L[i]; s = sp[q]
        xt = 0; r[l, s] = e[l, "field", s] / p_at(l, t[l, "field", s]); rx[l, s] = xt
        xt = 0; g[l, s] = f_time(l, e[l, "pixel", s]) / t[l, "pixel", s]; gx[l, s] = xt
    }
    # The crossings: field spp where field'"'"'s RMSE meets pixel'"'"'s in the same time, and
    # pixel spp where field'"'"'s time meets pixel'"'"'s for the same RMSE.
    # Who wins at each spp (field'"'"'s RMSE against pixel'"'"'s in the same time), where that changes
    # (log-log between the spp around it), and who wins from the last change on.
    for (i = 1; i <= nl; i++) {
        l = L[i]; wp = wf = cs = ""; last = ""
        for (q = 1; q <= ns; q++) {
            if (r[l, sp[q]] < 1) wf = wf (wf == "" ? "" : ", ") sp[q]; else wp = wp (wp == "" ? "" : ", ") sp[q]
            if (q < ns && (r[l, sp[q]] - 1) * (r[l, sp[q + 1]] - 1) < 0) {
                x = cross(sp[q], sp[q + 1], r[l, sp[q]], r[l, sp[q + 1]])
                last = sprintf(x < 10 ? "%.2g" : "%.0f", x)
                cs = cs (cs == "" ? "" : ", ") last
            }
        }
        w = r[l, sp[ns]] < 1 ? "field" : "pixel"
        c = sprintf("pixel wins at %s spp, field at %s", wp == "" ? "no" : wp, wf == "" ? "none" : wf " spp")
        if (last == "") c = c sprintf(": %s wins at every spp measured, no crossover", w)
        else c = c sprintf("; crossing near %s spp: %s wins from about %s spp on (to %d)", cs, w, last, sp[ns])
        crossing[l] = c
        win[l] = r[l, dspp] < 1 && g[l, dspp] < 1 ? "field" : (r[l, dspp] > 1 && g[l, dspp] > 1 ? "pixel" : "neither")
        wins[win[l]]++
    }
    verdict = wins["pixel"] > wins["field"] ? "pixel" : (wins["field"] > wins["pixel"] ? "field" : "neither")

    print "# Pixel against field sampling: error against time"
    print ""
    printf "Generated by `tools/report_field.sh` (`make report`, or `make report-field` alone) in %d s;\n", elapsed
    printf "%s, `--jobs %d`; references %s. Scene `%s` (%s), %dx%d pixels,\n", processor, jobs, refs, scene, camera, W, H
    printf "%s samples per pixel, the lenses'"'"' default aperture and pupil; lens2pov binary sha256 %s.\n", spps, version
    print "Both samplings are measured against the same reference, `make report`'"'"'s: pixel sampling at"
    printf "%d spp with a seed of its own (9001). Pixel sampling has no error but noise (every sample is an\n", ref_spp
    print "exact ray), so against it field sampling'"'"'s structured error (copies of out-of-focus highlights,"
    print "stepped vignetting) and any bias show; a field reference would share them. Every time is the"
    printf "median of %d runs, pixel and field alternating at each spp (which first swapped each turn);\n", turns
    print "every RMSE is of one run (a render is the same picture every time). Data:"
    print "`field-error-vs-time.csv`; the figure is drawn by `field-error-vs-time.gp`."
    print ""
    print "![RMSE against time, pixel and field sampling](field-error-vs-time.png)"
    print ""
    print "## In short"
    print ""
    if (!((L[1], "pixel", dspp) in e)) {
        x = sprintf("- %d spp (render'"'"'s default) is not among the spp measured: no verdict.", dspp)
        print x; print x >short; nl0 = nl; nl = 0
    }
    for (i = 1; i <= nl; i++) {
        l = L[i]
        x = sprintf("- %s, %d spp: pixel RMSE %.4g in %.2f s, field %.4g in %.2f s; field'"'"'s RMSE %s times pixel'"'"'s in the same time, its time %s times pixel'"'"'s for the same RMSE: %s.", l, dspp, e[l, "pixel", dspp], t[l, "pixel", dspp], e[l, "field", dspp], t[l, "field", dspp], mark(r[l, dspp], rx[l, dspp]), mark(g[l, dspp], gx[l, dspp]), win[l] == "neither" ? "neither wins on both counts" : win[l] " wins")
        print x; print x >short
    }
    if (nl) x = sprintf("- At %d spp (render'"'"'s default) pixel wins on %d of the %d lenses, field on %d: %s at this film, %dx%d; render'"'"'s default film, 640x480, is measured in `default-film.md` (`make report-default-film`), where POV-Ray'"'"'s start-up weighs far less.", dspp, wins["pixel"] + 0, nl, wins["field"] + 0, verdict == "neither" ? "no sampling wins across the lenses" : verdict " sampling wins", W, H)
    if (nl) { print x; print x >short }
    if (!nl) nl = nl0
    for (i = 1; i <= nl; i++) {
        x = sprintf("- %s: %s.", L[i], crossing[L[i]])
        print x; print x >short
    }
    print ""
    print "## Each lens"
    print ""
    print "Times in seconds (median; the turns in `field-error-vs-time.csv`). \"Same time\": field'"'"'s RMSE over"
    print "the RMSE pixel sampling gets in field'"'"'s time (its curve interpolated in log-log); \"same RMSE\":"
    print "the time field sampling needs for pixel sampling'"'"'s RMSE over pixel'"'"'s time. Below 1 field wins."
    print "Each curve is its frontier: the runs by time, a slower run kept only when its RMSE is lower."
    print "~: beyond the measured curve, extrapolated with the noise law (RMSE ~ time^-1/2); <=: field"
    print "sampling'"'"'s fastest run already has a lower RMSE, so its time is an upper bound."
    print ""
    print "| lens | spp | pixel s | pixel RMSE | field s | field RMSE | same time: field / pixel RMSE | same RMSE: field / pixel time |"
    print "|---|---|---|---|---|---|---|---|"
    for (i = 1; i <= nl; i++) for (q = 1; q <= ns; q++) {
        l = L[i]; s = sp[q]
        printf "| %s | %d | %.2f | %.4g | %.2f | %.4g | %s | %s |\n", l, s, t[l, "pixel", s], e[l, "pixel", s], t[l, "field", s], e[l, "field", s], (s == dspp ? "**" : "") mark(r[l, s], rx[l, s]) (s == dspp ? "**" : ""), (s == dspp ? "**" : "") mark(g[l, s], gx[l, s]) (s == dspp ? "**" : "")
    }
    print ""
    print "## The pictures"
    print ""
    printf "Pixel sampling (top row) and field sampling (bottom row) at %s spp, the reference at the\n", pics
    printf "right; linear values shown as sRGB, each rendered pixel as %dx%d. Pixel sampling'"'"'s error\n", scale, scale
    print "is noise; field sampling'"'"'s is structured: at few spp an out-of-focus highlight shows as spp"
    print "sharp copies of the pupil sample positions, and vignetting falls in spp steps, each the edge of"
    print "the region one shared sample reaches."
    print ""
    for (i = 1; i <= nl; i++) printf "![%s: pixel above, field below](field-pictures-%s.png)\n\n", L[i], L[i]
    print "## Caveats"
    print ""
    printf "- The reference has noise of its own (%d spp), the same for both samplings: at %d spp an\n", ref_spp, sp[ns]
    printf "  unbiased picture reads about %.0f%% high.\n", 100 * (sqrt(1 + sp[ns] / ref_spp) - 1)
    print "- The times include lens2pov'"'"'s tracing (and field sampling'"'"'s mesh building) and every POV-Ray"
    print "  process'"'"'s start-up; at low spp these dominate both samplings. On a machine shared with other"
    print "  work single runs varied by a factor of up to 2: compare the ratios, taken from medians."
}' "$csv" >"$work/field.md"
mv "$work/field.md" "$out/field.md"
echo "== pixel against field sampling, ${W}x$H, $processor, --jobs $jobs (out/report/field.md)"
cat "$work/short"
say "done in ${elapsed}s: $out/field.md, $csv, $out/field-error-vs-time.png, $out/field-pictures-*.png"
