#!/usr/bin/env bash
# Whole-command timing of `strata untangle` with one thread (--threads 1) and with all cores,
# in turn, on out-of-sample tangled scenes: where the tries fail one after the other, the
# tries of a list run two at a time (docs/untangle.md, "Tries two at a time"); where the first
# try is clean, nothing changes. Both outputs must be byte-identical.
#
# usage: bench/untangle_threads.sh BUILD WORK [CASE...]
#   CASE: FAMILY-REMOVAL-SEED, e.g. folded-0.95-58: the family's scene at 300 points a layer
#   (as bench/out_of_sample.sh makes it), decimated naively at random with that seed, untangled
#   without the original. Default: the slowest cases of the out-of-sample run and two quick ones.
#   REPEAT=N (default 1): runs of each, interleaved; the median time is printed.
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: $0 BUILD WORK [CASE...]" >&2
    exit 2
fi
build=$1
work=$2
shift 2
cases=("$@")
[ ${#cases[@]} -gt 0 ] || cases=(folded-0.95-58 folded-0.9-41 folded-0.95-82 folded-0.95-40
    folded-0.95-43 folded-0.95-3 collar_wrap-0.9-72 shirt_roll-0.9-30 stack-0.9-2 legs-0.95-2)
repeat=${REPEAT:-1}
strata=$build/tools/strata
mkdir -p "$work/inputs" "$work/out"
if [ ! -e "$work/inputs/stack-naive90.input.json" ]; then
    "$build/bench/strata_bench_untangle" --points 300 --slices none --write "$work/inputs" \
        >/dev/null
fi
now() { date +%s.%N; }
median() { tr ' ' '\n' | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }
printf "%-22s %6s %10s %10s %6s %s\n" case tries "1 thread" "all cores" ratio output
for c in "${cases[@]}"; do
    seed=${c##*-}
    rest=${c%-*}
    removal=${rest##*-}
    family=${rest%-*}
    original=$work/inputs/$family-naive90.input.json
    if [ ! -e "$original" ]; then
        echo "$0: no family '$family' (case $c)" >&2
        exit 2
    fi
    tangled=$work/out/$c.tangled.json
    "$strata" simplify "$original" --remove "$removal" --decimator random --seed "$seed" \
        --no-untangle -o "$tangled" >/dev/null 2>&1 || true # exit 1: it crosses
    one=() all=()
    for ((k = 0; k < repeat; ++k)); do
        t0=$(now)
        "$strata" untangle "$tangled" --threads 1 -o "$work/out/$c.1.json" \
            --report "$work/out/$c.1.report.json" >/dev/null 2>&1 || true
        t1=$(now)
        "$strata" untangle "$tangled" -o "$work/out/$c.all.json" >/dev/null 2>&1 || true
        t2=$(now)
        one+=("$(echo "$t1 - $t0" | bc)")
        all+=("$(echo "$t2 - $t1" | bc)")
    done
    m1=$(echo "${one[@]}" | median)
    m2=$(echo "${all[@]}" | median)
    tries=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["tries"])' \
        "$work/out/$c.1.report.json")
    same=DIFFERENT
    cmp -s "$work/out/$c.1.json" "$work/out/$c.all.json" && same=same
    printf "%-22s %6s %9.2fs %9.2fs %5.2fx %s\n" "$c" "$tries" "$m1" "$m2" \
        "$(echo "$m1 / $m2" | bc -l)" "$same"
done
