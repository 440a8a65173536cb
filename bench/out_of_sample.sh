#!/bin/bash
# Out-of-sample judge of `strata untangle` (issues 13 and 19), on seeds other than the
# benchmark's: the 12 generated families of strata_bench_untangle at 300 points a layer (POINTS),
# decimated naively at random (90% and 95%) with each seed, untangled with `strata untangle`
# (sides inferred, no original), then judged by `strata check --reference ORIGINAL`: clean
# means no crossing, the gaps kept and every vertex on the original's side of its neighbours.
#
#   bench/out_of_sample.sh BUILD WORK [SEEDS...]        default seeds 2 3 4 5 6
#   REFERENCE=1 bench/out_of_sample.sh BUILD WORK ...   untangle with --reference ORIGINAL too
#   POINTS=600 bench/out_of_sample.sh BUILD WORK ...    inputs of 600 points a layer
#
# BUILD: a build folder with tools/strata and bench/strata_bench_untangle; WORK: a folder for
# the inputs and outputs. Prints each dirty case with the untangling's exit code (0: a wrong
# reading that holds; 1: the untangling said it failed) and the count of clean cases.
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
clean=0
total=0
start=$(date +%s.%N)
for f in $families; do
    original=$work/inputs/$f-naive90.input.json
    for r in 0.9 0.95; do
        for s in "${seeds[@]}"; do
            t=$work/out/$f-$r-$s.tangled.json
            u=$work/out/$f-$r-$s.json
            "$strata" simplify "$original" --remove "$r" --decimator random --seed "$s" \
                --no-untangle -o "$t" >/dev/null 2>&1 || true  # exit 1: it crosses
            reference=()
            [ "${REFERENCE:-0}" = 1 ] && reference=(--reference "$original")
            ue=0
            "$strata" untangle "$t" "${reference[@]}" -o "$u" >/dev/null 2>&1 || ue=$?
            ce=0
            "$strata" check "$u" --reference "$original" >/dev/null 2>&1 || ce=$?
            total=$((total + 1))
            if [ $ce = 0 ]; then
                clean=$((clean + 1))
            else
                echo "dirty: $f $r seed $s (untangle exit $ue)"
            fi
        done
    done
done
end=$(date +%s.%N)
echo "$clean of $total clean, $(echo "$end - $start" | bc) s"
