#!/usr/bin/env bash
# Slices every garment of ../shared/data/garments with its body at regular heights, runs
# `strata check` on every slice, then `strata simplify` on every slice at 90% removal (or
# REMOVAL; a batch: slices whose input already crosses are untangled first, or fail with the
# reason when that cannot be done, e.g. a layer that crosses itself); prints one summary row per
# outfit for each stage, and writes one HTML gallery per outfit (OUT_DIR/NAME.html: a tile per
# slice, the input faint under the result, crossings ringed in red; bench/gallery.py).
#
#   bench/garments.sh [OUT_DIR [REMOVAL]]   (from the repository root, after building strata_cli)
#
# MakeHuman outfits (decimetres): body + suit, every 0.5 dm over their height, --order body,suit.
# Codim-IPC skirt (metres): split into components, every 0.05 m (the same 0.5 dm).
# Environment: STRATA (the strata binary), DATA (the garments folder).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
strata=${STRATA:-$root/build/tools/strata}
data=${DATA:-$root/../shared/data/garments}
out=${1:-$root/build/bench/garments}
removal=${2:-0.9}
[ -x "$strata" ] || { echo "garments.sh: no strata binary at $strata (build strata_cli)" >&2; exit 2; }
# 77: skipped (CTest's SKIP_RETURN_CODE) when the shared garments are not beside the project.
[ -d "$data" ] || { echo "garments.sh: no garments folder at $data (skipped)" >&2; exit 77; }
mkdir -p "$out"

# elapsed T0: wall seconds since T0 (an $EPOCHREALTIME), to the hundredth.
elapsed() { awk -v a="$1" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.2f", b - a }'; }

# slice_outfit NAME STEP STRATA-SLICE-ARGS...
rows=()
slice_outfit() {
  local name=$1 step=$2
  shift 2
  rm -rf "${out:?}/$name"
  local t0=$EPOCHREALTIME
  "$strata" slice "$@" --every "$step" --prefix "$name" -o "$out/$name" > "$out/$name.slice.log" 2> "$out/$name.slice.err"
  local slices=0 layers=0 vertices=0 crossing=0 nesting=0 links=0 welded
  welded=$(grep -c '^  welded: ' "$out/$name.slice.log" || true)
  while IFS= read -r line; do
    links=$((links + $(sed -E 's/.* ([0-9]+) nesting links.*/\1/' <<< "$line")))
  done < <(grep ' nesting links' "$out/$name.slice.log")
  for f in "$out/$name"/*.json; do
    local report
    report=$("$strata" check "$f" 2>/dev/null || true)
    slices=$((slices + 1))
    layers=$((layers + $(head -1 <<< "$report" | sed -E 's/.*: ([0-9]+) layers, ([0-9]+) vertices.*/\1/')))
    vertices=$((vertices + $(head -1 <<< "$report" | sed -E 's/.*: ([0-9]+) layers, ([0-9]+) vertices.*/\2/')))
    local x s
    x=$(sed -nE 's/^crossings between layers: ([0-9]+).*/\1/p' <<< "$report")
    s=$(sed -nE 's/^self-crossings: ([0-9]+).*/\1/p' <<< "$report")
    if [ "$x" -gt 0 ] || [ "$s" -gt 0 ]; then
      crossing=$((crossing + 1))
    elif ! grep -q '^nesting: holds' <<< "$report"; then
      nesting=$((nesting + 1))
    fi
  done
  rows+=("$(printf '%-20s %6d %7d %9d %7d %7d %10d %9d %6ss' "$name" "$slices" "$layers" "$vertices" "$links" \
            "$welded" "$crossing" "$nesting" "$(elapsed "$t0")")")
  # Simplify the whole folder at $removal (batch, parallel over slices).
  t0=$EPOCHREALTIME
  rm -rf "${out:?}/$name-simplified"
  "$strata" simplify "$out/$name" -o "$out/$name-simplified" --remove "$removal" --compare-naive \
    --report "$out/$name.simplify.json" > "$out/$name.simplify.log" 2> "$out/$name.simplify.err" || true
  local seconds gaps
  seconds=$(elapsed "$t0")
  # Smallest gap after / gap before over the near pairs of every simplified slice.
  gaps=$(python3 "$root/bench/gap_ratios.py" "$out/$name" "$out/$name-simplified" | tee "$out/$name.gaps.log" |
         sed -nE 's/^smallest ratio ([0-9.inf]+); pairs below 0.9: ([0-9]+).*/\1 \2/p')
  python3 "$root/bench/gallery.py" --title "$name: strata simplify --remove $removal" --strata "$strata" \
    --report "$out/$name.simplify.json" --out "$out/$name.html" > /dev/null
  srows+=("$(python3 - "$out/$name.simplify.json" "$name" "$seconds" $gaps <<'PY'
import json, sys
runs = json.load(open(sys.argv[1]))
ok = [r for r in runs if "error" not in r and "skipped" not in r]
untangled = sum(1 for r in ok if "input_untangled" in r)
before = sum(l["before"] for r in ok for l in r["layers"])
after = sum(l["after"] for r in ok for l in r["layers"])
naive = sum(r["naive"]["crossings"] for r in ok)
strata = sum(r["crossings"] for r in ok)
refused = sum(r["refused"] for r in ok)
tangled = sum(1 for r in ok if not r["collision_free"])
# The guarantee: a collision-free input gives a collision-free output. Outputs of inputs that
# were untangled first are counted apart ("after-untangle"): see the README, Real garments.
broken = sum(1 for r in ok if not r["collision_free"] and "input_untangled" not in r)
over = sum(1 for r in ok for l in r["layers"] if l["after"] > 1.05 * l["target"] and l["after"] > 3)
# The issue's budget: a slice's vertices within 5% of the sum of its layers' targets (which hold
# the floor of 3 vertices of a closed layer).
over_slices = sum(1 for r in ok if sum(l["after"] for l in r["layers"]) >
                  1.05 * sum(l["target"] for l in r["layers"]))
# End vertices of open layers taken out to meet a target (SimplifyParams::trim_ends).
trimmed = sum(r.get("trimmed_ends", 0) for r in ok)
print("%-20s %6d %9d %6d %9d %8d %9d %8d %8d %8d %8d %8d %6d %9s %5d %6ss %d" % (sys.argv[2], len(runs), untangled,
      len(runs) - len(ok), before, after, naive, strata, tangled, refused, over_slices, over, trimmed, sys.argv[4],
      int(sys.argv[5]), sys.argv[3], broken))
PY
)")
}
srows=()

mh=$data/makehuman
for suit in casualsuit03 casualsuit05 elegantsuit01; do
  slice_outfit "mh_$suit" 0.5 "body=$mh/male_generic.obj" "suit=$mh/male_$suit.obj" --order body,suit --units dm
done
slice_outfit cipc_multilayer 0.05 "skirt=$data/codim-ipc/multilayer_drape.obj" --components --units m

printf '%-20s %6s %7s %9s %7s %7s %10s %9s %7s\n' outfit slices layers vertices links welded "crossing" "nest-viol" time
for r in "${rows[@]}"; do echo "$r"; done
echo "welded: slices where strata slice joined pieces at a seam; crossing: slices whose input already crosses"
echo "(strata check: crossings or self-crossings > 0)"
echo "nest-viol: crossing-free slices whose inferred nesting strata check rejects"
echo "slices in $out"
echo
printf '%-20s %6s %9s %6s %9s %8s %9s %8s %8s %8s %8s %8s %6s %9s %5s %7s %s\n' outfit slices untangled failed vertices \
  after "naive-x" "strata-x" tangled refused "sl-5%" "over-5%" ends "gap-ratio" "<0.9" time bad
for r in "${srows[@]}"; do echo "$r"; done
echo "simplification of every slice: $(for r in "${srows[@]}"; do awk '{print $16}' <<< "$r"; done |
  awk '{sub(/s$/, ""); s += $1} END {printf "%.2f", s}') s in all (column time: wall seconds of the outfit's batch, 2 threads, naive run included)"
echo "untangled: inputs that crossed, untangled before simplifying; failed: not simplified (the"
echo "reason is in the .simplify.json: e.g. a layer that crosses itself cannot be untangled);"
echo "naive-x / strata-x: crossings after naive decimation / after strata; tangled: outputs not collision-free;"
echo "sl-5%: slices whose vertices exceed the sum of their layers' targets by more than 5%;"
echo "over-5%: layers (of more than 3 vertices) kept more than 5% above their target;"
echo "ends: end vertices of open layers taken out to meet a target (strata simplify --no-trim-ends keeps them);"
echo "gap-ratio: smallest gap after / gap before over the near pairs that do not cross in the input (bench/gap_ratios.py); <0.9: pairs below 0.9;"
echo "bad: of those, outputs of inputs that were collision-free as read (the guarantee)"
echo "galleries: $out/<outfit>.html"
# Fail when an output has crossings, or when an output of a collision-free input is not
# collision-free (column "bad", the last of each row); tangled outputs of untangled
# inputs (whose only possible fault left is the nesting check's reading of an open layer's
# side) are reported, not failed.
crossed=$(for r in "${srows[@]}"; do awk '{print $8}' <<< "$r"; done | awk '{s += $1} END {print s + 0}')
bad=$(for r in "${srows[@]}"; do awk '{print $NF}' <<< "$r"; done | awk '{s += $1} END {print s + 0}')
tangled=$(for r in "${srows[@]}"; do awk '{print $9}' <<< "$r"; done | awk '{s += $1} END {print s + 0}')
if [ "$tangled" -gt 0 ]; then
  echo "garments.sh: $tangled simplified slices are NOT collision-free ($bad of them from clean inputs, $crossed crossings)" >&2
fi
if [ "$crossed" -gt 0 ] || [ "$bad" -gt 0 ]; then
  exit 1
fi
