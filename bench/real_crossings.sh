#!/usr/bin/env bash
# Untangles every real garment slice whose input already crosses, at finer spacings than
# tests/data/crossing_slices (the benchmark's 16, every 0.5 dm): the MakeHuman suits with
# their body every STEP dm and the Codim-IPC skirt every STEP/10 m, from OFFSET (in STEPs: 0
# gives the multiples of STEP, 0.5 the heights halfway between). Each slice that `strata
# check` finds crossing (between layers or itself) is untangled by `strata untangle` (sides
# inferred, no original); prints one line per slice (exit code: 0 clean, 1 not; wall seconds)
# and a summary.
#
#   bench/real_crossings.sh OUT_DIR [STEP [OFFSET]]   default STEP 0.1, OFFSET 0
#
# Environment: STRATA (the strata binary; default build/tools/strata), DATA (the garments
# folder; default ../shared/data/garments), UNTANGLE_ARGS (more options of strata untangle,
# split at spaces), TIME_LIMIT (seconds a slice may take; default 300: a slice over it counts
# as exit 124).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
strata=${STRATA:-$root/build/tools/strata}
data=${DATA:-$root/../shared/data/garments}
[ $# -ge 1 ] || { echo "usage: $0 OUT_DIR [STEP [OFFSET]]" >&2; exit 2; }
out=$1
step=${2:-0.1}
offset=${3:-0}
limit=${TIME_LIMIT:-300}
read -ra untangle_args <<<"${UNTANGLE_ARGS:-}"
# is_number VALUE [positive]: exit 0 when VALUE is a finite number (> 0 with "positive").
is_number() {
  python3 -c '
import math, sys
try:
    v = float(sys.argv[1])
except ValueError:
    sys.exit(1)
sys.exit(0 if math.isfinite(v) and (len(sys.argv) < 3 or v > 0) else 1)' "$@"
}
is_number "$step" positive || { echo "$0: STEP must be a number > 0 (got '$step')" >&2; exit 2; }
is_number "$offset" || { echo "$0: OFFSET must be a number (got '$offset')" >&2; exit 2; }
[ -x "$strata" ] || { echo "$0: no strata binary at $strata" >&2; exit 2; }
[ -d "$data" ] || { echo "$0: no garments folder at $data" >&2; exit 2; }
mkdir -p "$out"

# heights FROM TO STEP OFFSET: --at arguments for every FROM + (k + OFFSET) STEP up to TO.
heights() {
  python3 -c '
import sys
lo, hi, step, offset = map(float, sys.argv[1:])
k = 0
while lo + (k + offset) * step <= hi:
    print("--at %.4f" % (lo + (k + offset) * step))
    k += 1' "$@"
}

mh=$data/makehuman
for suit in casualsuit03 casualsuit05 elegantsuit01; do
  # shellcheck disable=SC2046
  "$strata" slice "body=$mh/male_generic.obj" "suit=$mh/male_$suit.obj" --order body,suit \
    --units dm $(heights -8.5 9.5 "$step" "$offset") --prefix "mh_$suit" -o "$out/mh_$suit" \
    > "$out/mh_$suit.slice.log" 2>&1
done
cipc_step=$(python3 -c "print($step / 10)")
# shellcheck disable=SC2046
"$strata" slice "skirt=$data/codim-ipc/multilayer_drape.obj" --components --units m \
  $(heights -0.8 0.8 "$cipc_step" "$offset") --prefix cipc -o "$out/cipc" \
  > "$out/cipc.slice.log" 2>&1

mkdir -p "$out/untangled"
total=0
clean=0
seconds=0
for f in "$out"/mh_*/*.json "$out"/cipc/*.json; do
  report=$("$strata" check "$f" 2>/dev/null || true)
  x=$(sed -nE 's/^crossings between layers: ([0-9]+).*/\1/p' <<<"$report")
  s=$(sed -nE 's/^self-crossings: ([0-9]+).*/\1/p' <<<"$report")
  [ "${x:-0}" -gt 0 ] || [ "${s:-0}" -gt 0 ] || continue
  name=$(basename "$f" .json)
  t0=$EPOCHREALTIME
  code=0
  timeout "$limit" "$strata" untangle "$f" -o "$out/untangled/$name.json" \
    --report "$out/untangled/$name.report.json" "${untangle_args[@]}" \
    > "$out/untangled/$name.log" 2>&1 || code=$?
  t=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.2f", b - a }')
  echo "$name crossings $x self-crossings $s exit $code $t s"
  total=$((total + 1))
  [ "$code" -eq 0 ] && clean=$((clean + 1))
  seconds=$(awk -v a="$seconds" -v b="$t" 'BEGIN { print a + b }')
done
echo "$clean of $total crossing slices clean, $seconds s in all"
