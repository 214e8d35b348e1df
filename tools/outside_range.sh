#!/bin/bash
# Dressings on bodies outside the range the built-in garments and the shared bodies cover: four
# bodies made from measurements by `drape body` (a heavy 1.87 m man, a petite woman, a heavy woman,
# a tall thin man), each dressed with `drape dress` in every built-in garment (the size its chart
# gives the body) and, where ../shared/data is beside the repository, in the GarmentCode patterns
# and the 2021 templates (cut for other bodies). One line per dressing: the exit status, the
# figures `drape dress` prints and the gates that failed; then how many passed every gate.
#
#   tools/outside_range.sh [OUT_DIR]          (default /tmp/drape-outside-range; build/drape first)
#
# Where a body is larger than a garment's largest size, or smaller than its smallest, failing is the
# honest answer; docs/dressing.md ("Bodies outside the range") says which of these do what.
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
drape="$root/build/drape"
out=${1:-/tmp/drape-outside-range}
shared="$root/../shared/data/patterns"
[ -x "$drape" ] || { echo "outside_range.sh: $drape not built (make build)" >&2; exit 2; }
mkdir -p "$out"

bodies=(
  "heavy_man male height=1.87,bust=1.18,waist=1.08,hips=1.14"
  "petite_woman female height=1.55,bust=0.82,waist=0.64,hips=0.88"
  "heavy_woman female height=1.72,bust=1.12,waist=0.98,hips=1.20"
  "tall_thin_man male height=1.95,bust=0.96,waist=0.80,hips=0.94"
)
garments=(shirt skirt trousers jeans dress)
if [ -d "$shared" ]; then
  for f in garmentcode/shirt_mean_specification garmentcode/hoody_mean_specification \
           garmentcode/dress_pencil_specification garmentcode/flare_skirt_specification \
           garment_pattern_generator_2021/skirt_4_panels garment_pattern_generator_2021/pants_straight_sides \
           garment_pattern_generator_2021/tee garment_pattern_generator_2021/dress_sleeveless; do
    garments+=("$shared/$f.json")
  done
else
  echo "(../shared/data not found: the built-in garments only)"
fi

passed=0
total=0
for entry in "${bodies[@]}"; do
  read -r name sex measurements <<<"$entry"
  body="$out/$name.obj"
  "$drape" body --sex "$sex" --measurements "$measurements" -o "$body" >/dev/null || exit 1
  for g in "${garments[@]}"; do
    label=$(basename "$g" .json)
    dir="$out/${name}_$label"
    "$drape" dress --body "$body" --garment "$g" --out "$dir" >"$dir.log" 2>&1
    rc=$?
    total=$((total + 1))
    [ $rc -eq 0 ] && passed=$((passed + 1))
    size=$(sed -n 's/^dressing .* in .* \([A-Z0-9]*\) (collision.*/\1/p' "$dir.log" | head -1)
    figures=$(grep -E '^(dressed|FAILED quality gates):' "$dir.log" | sed 's/^[^:]*: //; s/ iterations in [^;]*; / iterations; /')
    gates=$(grep -o 'gate [a-z_]* failed' "$dir.log" | sed 's/gate //; s/ failed//' | paste -sd, -)
    printf '%-14s %-28s %-3s exit %d  %s%s\n' "$name" "$label" "$size" "$rc" "$figures" "${gates:+  [failed: $gates]}"
  done
done
echo "$passed of $total dressings pass every gate"
