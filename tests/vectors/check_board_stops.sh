#!/bin/sh
# A board that stops answering in the middle of a file: the one-line error
# names the vectors that did not run by their index in the file and their
# lines (the link reports them relative to the 1024-vector batch, and under
# --sample by sample position).  The virtual board's link drops requests at
# random (CBVH_LINK_FAULTS, seeded: reproducible) with no retries; seeds are
# tried until a drop falls in the file's second batch.
# Usage: check_board_stops.sh PATH/TO/cbvh VECTOR-DIR     (exit 77 = skipped)
set -u
cbvh=$1
file=$2/axis_decode-N6-ms-30-modulo.vec # 1878 vectors, vector 0 on line 13
first_line=13
count=1878
. "$(dirname "$0")/../board/board_sim.sh"
board_sim_start || { echo "SKIP: board-sim did not come up"; exit 77; }

# $1: extra options; $2: lowest first index that proves file numbering (the
# first vector of the second batch); $3: "sampled" when --sample is given.
try() {
    seed=1
    while [ $seed -le 60 ]; do
        CBVH_LINK_FAULTS=drop=0.08,seed=$seed CBVH_LINK_RETRIES=0 CBVH_LINK_TIMEOUT_MS=50 \
            "$cbvh" vectors check --backend "sim:unix:$sock" $1 "$file" >"$tmp/out" 2>"$tmp/err"
        rc=$?
        seed=$((seed + 1))
        grep -q "not run" "$tmp/err" || continue
        [ "$rc" = 2 ] || { echo "FAIL: exit $rc, want 2: $(cat "$tmp/err")"; exit 1; }
        [ "$(wc -l <"$tmp/err")" = 1 ] || { echo "FAIL: not one line: $(cat "$tmp/err")"; exit 1; }
        line=$(cat "$tmp/err")
        case $line in
        *"axis_decode-N6-ms-30-modulo.vec: backend sim "*" failed: axis_decode: "*) ;;
        *) echo "FAIL: unexpected message: $line"; exit 1 ;;
        esac
        range=$(echo "$line" | sed -n 's/.*vectors \([0-9]*\)\.\.\([0-9]*\) (lines \([0-9]*\)\.\.\([0-9]*\)) not run: .*/\1 \2 \3 \4/p')
        [ -n "$range" ] || { echo "FAIL: no 'vectors A..B (lines C..D) not run' in: $line"; exit 1; }
        set -- "$1" "$2" "$3" $range
        a=$4 b=$5 la=$6 lb=$7
        if [ "$3" = sampled ]; then
            echo "$line" | grep -q "axis_decode: [0-9]* sampled vectors among vectors $a\.\.$b " ||
                { echo "FAIL: the sample is not named as such: $line"; exit 1; }
        fi
        [ $((la - a)) = $first_line ] && [ $((lb - b)) = $first_line ] && [ "$a" -le "$b" ] && [ "$b" -lt $count ] ||
            { echo "FAIL: vectors $a..$b do not match lines $la..$lb of the file: $line"; exit 1; }
        if [ "$a" -ge "$2" ]; then
            echo "PASS ($1): $line"
            return 0
        fi
    done
    echo "FAIL ($1): no seed put a dropped request past vector $2 and had it reported there"
    exit 1
}
try "--max-errors 0" 1024 ""
# --sample 1500: sample position 1024 is file vector 1024 * 1878 / 1500 = 1281.
try "--sample 1500" 1281 sampled
