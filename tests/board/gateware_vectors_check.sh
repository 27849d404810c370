#!/bin/sh
# The whole board path with the gateware as the FPGA: `cbvh vectors check
# --backend sim:ADDR` -> frames -> firmware core -> register-map driver -> SPI
# bytes -> the board top's RTL (SPI slave, register map, units) simulated by
# Icarus or Verilator.  It must give exactly the model's results on the
# default design point's files of every unit; another design point, and a
# unit left out of the board's build, must be refused with one line naming the
# problem; a
# one-bit fault on the SPI bus must fail exactly that unit's files.
# A simulated FPGA runs a few hundred vectors per second, so each file is
# checked on an evenly spread sample (--sample; 0 = every vector).
# Usage: gateware_vectors_check.sh CBVH GATEWARE-DIR VECTOR-DIR WORK-DIR [icarus|verilator [SAMPLE]]
# (exit 77 = skipped: simulator not installed)
set -u
cbvh=$1 gw=$2 vec=$3 work=$4 sim=${5:-icarus} sample=${6:-100}
sample_opt="--sample $sample"; [ "$sample" = 0 ] && sample_opt=""
# A batch of 500 vectors is a minute of simulation, not the 1 s of a board.
export CBVH_LINK_TIMEOUT_MS=600000 CBVH_LINK_RETRIES=0
tool=iverilog; [ "$sim" = verilator ] && tool=verilator
command -v $tool >/dev/null 2>&1 || { echo "SKIP: $tool not installed (apt-get install $tool)"; exit 77; }
[ "$sim" = icarus ] && { command -v vvp >/dev/null 2>&1 || { echo "SKIP: vvp not installed"; exit 77; }; }
mkdir -p "$work" || exit 1
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cbvh-gwcheck-XXXXXX") || exit 1
sock=$tmp/board.sock
pid=
cleanup() {
    [ -n "$pid" ] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT INT TERM

prog=$work/board-$sim
start=$(date +%s)
bash "$gw/scripts/build-board-sim" --sim "$sim" -o "$prog" -n 6 -e -30 --encodings both ||
    { echo "FAIL: build-board-sim"; exit 1; }
echo "built $prog in $(( $(date +%s) - start )) s"

board() { # board [extra board-sim options]
    [ -n "$pid" ] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
    rm -f "$sock"
    "$cbvh" board-sim --listen "unix:$sock" --gateware "$prog" "$@" >/dev/null 2>"$tmp/board.err" &
    pid=$!
    i=0
    while [ ! -S "$sock" ] && [ $i -lt 500 ]; do sleep 0.02; i=$((i + 1)); done
    [ -S "$sock" ] || { echo "FAIL: board-sim --gateware did not come up:"; cat "$tmp/board.err"; exit 1; }
}

# Every unit with RTL at the built design point (N = 6, min scale -30, both encodings).
files=""
for u in scale_estimate axis_compress axis_decode nodepair_encode nodepair_decode ray_box ray_triangle ray_sphere \
         qbvh_stack; do
    for f in "$vec"/$u-N6-ms-30.vec "$vec"/$u-N6-ms-30-*.vec; do
        case $f in *-L2.vec) continue ;; esac
        [ -f "$f" ] && files="$files $f"
    done
done
[ -n "$files" ] || { echo "FAIL: no N6 ms-30 vector files in $vec"; exit 1; }

board
"$cbvh" vectors check --backend model $sample_opt $files >"$tmp/model.out" 2>&1
rc_model=$?
start=$(date +%s)
"$cbvh" vectors check --backend "sim:unix:$sock" $sample_opt $files >"$tmp/gw.out" 2>&1
rc_gw=$?
secs=$(( $(date +%s) - start ))
filter() { grep -v -i -E 'backend|model|sim[: ]' "$1" | sed -E 's/ \([0-9]+ vectors in [^)]*\)//'; }
filter "$tmp/model.out" >"$tmp/model.f"
filter "$tmp/gw.out" >"$tmp/gw.f"
echo "gateware (exit $rc_gw, $secs s):"; cat "$tmp/gw.out"
[ "$rc_model" = 0 ] || { echo "FAIL: the model itself fails the vectors"; exit 1; }
[ "$rc_gw" = 0 ] || { echo "FAIL: the gateware board failed (exit $rc_gw)"; cat "$tmp/board.err"; exit 1; }
cmp -s "$tmp/model.f" "$tmp/gw.f" || { echo "FAIL: outputs differ:"; diff "$tmp/model.f" "$tmp/gw.f" | head -20; exit 1; }
n=$(grep -c -E '\.vec: [1-9][0-9]* passed, 0 failed' "$tmp/gw.out")
[ "$n" = "$(echo $files | wc -w)" ] || { echo "FAIL: $n files passed, expected $(echo $files | wc -w)"; exit 1; }
echo "PASS: $n files through firmware, SPI and RTL agree with the model"

# Not built: another design point (config error), and a unit left out of the
# build (unit error), each refused with one line naming why, exit 2.
refused() { # refused FILE WHY
    "$cbvh" vectors check --backend "sim:unix:$sock" --sample 3 "$vec/$1" >"$tmp/refused.out" 2>&1
    rc=$?
    [ "$rc" = 2 ] || { echo "FAIL: $1 gave exit $rc, want 2"; cat "$tmp/refused.out"; exit 1; }
    grep -q -F "$2" "$tmp/refused.out" || { echo "FAIL: $1: not '$2':"; cat "$tmp/refused.out"; exit 1; }
    echo "PASS: $1 refused: $2"
}
refused axis_compress-N7-ms-30.vec "config error (the board's unit is not built for this N"
bash "$gw/scripts/build-board-sim" --sim "$sim" -o "$prog-nosphere" -n 6 -e -30 --encodings both \
    --units 1,2,3,4,5,6,7,8 || { echo "FAIL: build-board-sim --units"; exit 1; }
prog_all=$prog
prog=$prog-nosphere
board
refused ray_sphere-N6-ms-30.vec "unit error (the board's datapath has no such unit)"
prog=$prog_all

# A one-bit fault on the bus (OUT[0] of axis_compress) fails exactly those files.
board --break-unit axis_compress
"$cbvh" vectors check --backend "sim:unix:$sock" --sample 20 "$vec/axis_compress-N6-ms-30.vec" "$vec/scale_estimate-N6-ms-30.vec" \
    >"$tmp/broken.out" 2>&1
rc=$?
[ "$rc" = 1 ] || { echo "FAIL: a broken board gave exit $rc, want 1"; cat "$tmp/broken.out"; exit 1; }
grep -q -E 'axis_compress-N6-ms-30\.vec: 0 passed, [1-9][0-9]* failed' "$tmp/broken.out" &&
    grep -q -E 'scale_estimate-N6-ms-30\.vec: [1-9][0-9]* passed, 0 failed' "$tmp/broken.out" ||
    { echo "FAIL: the fault did not show up as expected:"; cat "$tmp/broken.out"; exit 1; }
echo "PASS: a one-bit fault fails axis_compress only"
