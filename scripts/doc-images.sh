#!/bin/sh
# Regenerates every picture in docs/ that prespline draws, with the commands the docs give
# beside each, so none can go stale: run from the repository root after a change to the
# renderer, the viewer or the HUD, then look at them (git diff shows which moved).
#
#   sh scripts/doc-images.sh [PRESPLINE]      # default: target/release/prespline
#
# The viewer picture is the last frame of a headless drag benchmark (README, first figure).
# Needs no display: render and bench run offscreen on lavapipe.
set -eu
P=${1:-target/release/prespline}
[ -x "$P" ] || { echo "error: $P is not an executable (cargo build --release first)" >&2; exit 1; }
r() { "$P" render "$@"; }
r examples/bezier_spline.json --badges --net --size 960x540 --out docs/bezier-spline-badges.png
r examples/catmull_rom.json --net --osculating centripetal@3.3 --size 960x540 --out docs/catmull-rom-osculating.png
r examples/erbs_detail.json --edits examples/erbs_detail_edits.json \
  --camera=-0.5,-2.8,2.6,1.4,1.3,0.2,40 --out docs/erbs_detail.png
for map in gaussian mean kmax kmin zebra; do
  r examples/bspline_surface.json --analysis $map --size 960x540 --out docs/analysis-$map.png
done
out=$(mktemp -d)
"$P" bench --scenario drag --frames 120 --warmup 10 --out "$out" >/dev/null
cp "$out/final.png" docs/viewer.png
rm -rf "$out"
echo "wrote docs/*.png: look at them before committing" >&2
