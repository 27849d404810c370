#!/bin/sh
# `cbvh vectors gen -u UNIT -o DIR` run in parallel into one directory: every
# file of every run ends up listed in DIR/MANIFEST (each gen re-reads and
# rewrites the manifest under a lock on DIR), and the result equals one
# sequential run of the default set, byte for byte.
# Usage: gen_parallel.sh PATH/TO/cbvh COMMITTED-VECTORS WORK-DIR
set -u
cbvh=$1
committed=$2
work=$3/gen_parallel
rm -rf "$work"
mkdir -p "$work" || exit 1
seed=$(sed -n 's/^seed: //p' "$committed/scale_estimate-N6-ms-30.vec")
# every unit the tool generates (its --help lists the unit table)
units=$("$cbvh" vectors gen --help | sed -n 's/.*one unit (\(.*\))$/\1/p' | tr -d ',')
[ -n "$units" ] || { echo "FAIL: no unit list in 'cbvh vectors gen --help'"; exit 1; }
nunits=$(echo $units | wc -w)
for round in 1 2 3; do
    d=$work/r$round
    pids=""
    for u in $units; do
        "$cbvh" vectors gen --seed "$seed" -u $u -o "$d" >/dev/null 2>"$work/err.$u" &
        pids="$pids $!"
    done
    for p in $pids; do wait "$p" || { echo "FAIL: a gen exited $?: $(cat "$work"/err.*)"; exit 1; }; done
    listed=$(wc -l <"$d/MANIFEST")
    files=$(ls "$d" | grep -c '\.vec$')
    if ! cmp -s "$d/MANIFEST" "$committed/MANIFEST"; then
        echo "FAIL: round $round: MANIFEST lists $listed of $files files (or other hashes) after parallel gens:"
        diff "$committed/MANIFEST" "$d/MANIFEST" | head -10
        exit 1
    fi
    "$cbvh" vectors check --backend model --quiet "$d" >"$work/check" 2>&1 || { echo "FAIL: check: $(cat "$work/check")"; exit 1; }
done
echo "PASS: 3 rounds of $nunits parallel gens: all $listed files listed, MANIFEST identical to the committed one"
rm -rf "$work"
