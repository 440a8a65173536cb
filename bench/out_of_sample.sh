#!/bin/bash
# Out-of-sample judge of `strata untangle` (issues 13 and 19), on seeds other than the
# benchmark's: the 12 generated families of strata_bench_untangle at 300 points a layer (POINTS),
# decimated naively at random (90% and 95%) with each seed, untangled with `strata untangle`
# (sides inferred, no original), then judged by `strata check --reference ORIGINAL`: clean
# means no crossing, every vertex on the original's side of its neighbours (the check's exit
# code) and the gaps kept: the smallest gap / required >= 0.9 x min(1, the original's).
#
#   bench/out_of_sample.sh BUILD WORK [SEEDS...]        default seeds 2 3 4 5 6
#   REFERENCE=1 bench/out_of_sample.sh BUILD WORK ...   untangle with --reference ORIGINAL too
#   POINTS=600 bench/out_of_sample.sh BUILD WORK ...    inputs of 600 points a layer
#   UNTANGLE_ARGS="--backend grid" bench/out_of_sample.sh BUILD WORK ...   more options of
#                                                       strata untangle (split at spaces)
#
# BUILD: a build folder with tools/strata and bench/strata_bench_untangle; WORK: a folder for
# the inputs and outputs. Prints each dirty case with the untangling's exit code (0: a wrong
# reading that holds; 1: the untangling said it failed) and the count of clean cases. The check
# does not judge shape, so each clean case is also measured against the original: its largest
# per-layer Hausdorff distance (`strata check --reference --json`) against the tangled
# input's, the naive decimation's own error; a clean case more than twice as far is printed
# as distorted and counted (it stays counted as clean).
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: $0 BUILD WORK [SEEDS...]" >&2
    exit 2
fi
build=$1
work=$2
shift 2
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(2 3 4 5 6)
strata=$build/tools/strata
mkdir -p "$work/inputs" "$work/out"
points=${POINTS:-300}
read -ra untangle_args <<<"${UNTANGLE_ARGS:-}"
# The inputs are written once per WORK folder; a folder of other points is refused (inputs
# written before their points were recorded are of 300).
if [ -e "$work/inputs/stack-naive90.input.json" ]; then
    held=300
    [ -e "$work/inputs/points" ] && held=$(cat "$work/inputs/points")
    if [ "$held" != "$points" ]; then
        echo "$0: $work holds inputs of $held points, not $points" >&2
        exit 2
    fi
fi
if [ ! -e "$work/inputs/stack-naive90.input.json" ]; then
    "$build/bench/strata_bench_untangle" --points "$points" --slices none --write "$work/inputs" \
        >/dev/null
    echo "$points" >"$work/inputs/points"
fi
families="stack folded jacket legs loops stack_5x_gap_0.5 stack_12x_gap_4.0 rolled_both rolled
rolled_twice shirt_roll collar_wrap"
# Prints "HU HT" when the untangled scene's report $1 (`strata check --reference --json`) has a
# largest per-layer Hausdorff distance to the original more than twice that of the tangled
# scene's report $2 (files: a report is too long for one argument), nothing otherwise.
distortion() {
    python3 -c '
import json, sys
def far(path):
    with open(path) as f:
        return max(l["hausdorff"]["symmetric"] for l in json.load(f)["layers"])
hu, ht = far(sys.argv[1]), far(sys.argv[2])
if hu > 2 * ht:
    print(hu, ht)' "$1" "$2"
}
# The smallest gap / required of the check report $1 (`strata check --json`).
gap_ratio() {
    python3 -c '
import json, sys
with open(sys.argv[1]) as f:
    print(json.load(f)["min_separation_ratio"])' "$1"
}
# Exit 0 when the gap ratio $1 of an untangled scene keeps 0.9 x min(1, $2), the original's.
gaps_kept() {
    python3 -c 'import sys; u, o = map(float, sys.argv[1:]); sys.exit(u < 0.9 * min(1.0, o))' \
        "$1" "$2"
}
clean=0
distorted=0
total=0
start=$(date +%s.%N)
for f in $families; do
    original=$work/inputs/$f-naive90.input.json
    "$strata" check "$original" --json >"$work/inputs/$f.check" 2>/dev/null || true
    original_gap=$(gap_ratio "$work/inputs/$f.check")
    for r in 0.9 0.95; do
        for s in "${seeds[@]}"; do
            t=$work/out/$f-$r-$s.tangled.json
            u=$work/out/$f-$r-$s.json
            "$strata" simplify "$original" --remove "$r" --decimator random --seed "$s" \
                --no-untangle -o "$t" >/dev/null 2>&1 || true  # exit 1: it crosses
            reference=()
            [ "${REFERENCE:-0}" = 1 ] && reference=(--reference "$original")
            ue=0
            "$strata" untangle "$t" "${reference[@]}" "${untangle_args[@]}" -o "$u" >/dev/null \
                2>&1 || ue=$?
            ce=0
            "$strata" check "$u" --reference "$original" --json >"$u.check" 2>/dev/null || ce=$?
            total=$((total + 1))
            if [ $ce = 0 ] && ! gaps_kept "$(gap_ratio "$u.check")" "$original_gap"; then
                ce=gap
            fi
            if [ $ce = 0 ]; then
                clean=$((clean + 1))
                # (check exits 1 on the tangled scene, which crosses: its report is whole.)
                "$strata" check "$t" --reference "$original" --json >"$t.check" 2>/dev/null ||
                    true
                far=$(distortion "$u.check" "$t.check")
                if [ -n "$far" ]; then
                    distorted=$((distorted + 1))
                    read -r hu ht <<<"$far"
                    echo "distorted: $f $r seed $s (Hausdorff to the original $hu, tangled $ht)"
                fi
            else
                gap=""
                [ $ce = gap ] && gap=", gaps short: $(gap_ratio "$u.check") x required"
                echo "dirty: $f $r seed $s (untangle exit $ue$gap)"
            fi
        done
    done
done
end=$(date +%s.%N)
echo "$clean of $total clean ($distorted of them distorted), $(echo "$end - $start" | bc) s"
