#!/bin/sh
# ctest driver for the RP2040 emulation (board_emu.mjs).
#   run_emu.sh BUILD SRC check [harness options]
#   run_emu.sh BUILD SRC vectors LINK SAMPLE [RESET_AFTER_BYTES]
# BUILD: the build tree, SRC: the source tree.  vectors: the harness serves
# the board on a unix socket and `cbvh vectors check --backend sim:unix:...
# --sample SAMPLE` runs every committed vector file through it (0 failures
# expected); with RESET_AFTER_BYTES the emulated chip is reset once that many
# reply bytes have gone out, and the host must recover (docs/protocol.md).
# Exit 77 (ctest SKIP) only when node or rp2040js is missing.
set -u
build=$1 src=$2 what=$3
shift 3
here=$src/tests/board/emu
command -v node >/dev/null 2>&1 || { echo "SKIP: node not installed (scripts/install-deps)"; exit 77; }
[ -f "$here/node_modules/rp2040js/package.json" ] ||
    { echo "SKIP: rp2040js not installed in $here/node_modules (scripts/install-deps)"; exit 77; }
uf2=$build/firmware/firmware_rp2040.uf2
bits=$build/firmware/cbvh_board.bin
regmap=$build/tests/board/emu/board_emu_regmap
[ -f "$uf2" ] || { echo "FAIL: $uf2 not built (needs arm-none-eabi-gcc)"; exit 1; }
[ -f "$bits" ] || { echo "FAIL: $bits not built (needs yosys, nextpnr-ice40, icepack)"; exit 1; }
emu() { exec node "$here/board_emu.mjs" --uf2 "$uf2" --bitstream "$bits" --regmap "$regmap" --protocol "$src/docs/protocol.md" "$@"; }

[ "$what" = check ] && emu "$@" check
[ "$what" = vectors ] || { echo "run_emu.sh: unknown mode '$what'"; exit 2; }
link=$1 sample=$2 reset=${3:-0}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cbvh-emu-XXXXXX") || exit 1
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null; rm -rf "$tmp"' EXIT INT TERM
set -- --link "$link" --listen "$tmp/board.sock" --ready "$tmp/ready" --stats "$tmp/stats.json"
[ "$reset" != 0 ] && set -- "$@" --reset-after-bytes "$reset"
(emu "$@" serve) &
pid=$! # node itself (exec), so that kill reaches it
i=0
while [ ! -f "$tmp/ready" ] && [ $i -lt 600 ]; do
    kill -0 "$pid" 2>/dev/null || { echo "FAIL: the emulated board ended before it listened"; exit 1; }
    sleep 0.1
    i=$((i + 1))
done
[ -f "$tmp/ready" ] || { echo "FAIL: the emulated board did not enumerate within 60 s"; exit 1; }
start=$(date +%s.%N)
# A reset takes the emulated chip a few seconds of real time to come back
# (boot, FPGA configuration, enumeration): a 3 s per-attempt timeout keeps
# the default 8 retries well within that (docs/protocol.md).
CBVH_LINK_TIMEOUT_MS=3000 "$build/host/cbvh" vectors check --backend "sim:unix:$tmp/board.sock" --sample "$sample" -q \
    "$src/vectors" >"$tmp/out" 2>&1
rc=$?
end=$(date +%s.%N)
cat "$tmp/out"
kill "$pid" && wait "$pid"
pid=
cat "$tmp/stats.json"
[ $rc -eq 0 ] || { echo "FAIL: cbvh vectors check exit $rc over the emulated $link link"; exit 1; }
grep -q "^total: .* 0 failed" "$tmp/out" || { echo "FAIL: vectors failed over the emulated $link link"; exit 1; }
grep -q "^backend: sim unix:.*(cbvh-rp2040 fw" "$tmp/out" || { echo "FAIL: not the emulated RP2040 board"; exit 1; }
if [ "$reset" != 0 ]; then
    grep -q '"chipResets": 1' "$tmp/stats.json" || { echo "FAIL: the chip was not reset mid-run"; exit 1; }
    conns=$(sed -n 's/.*"connections": \([0-9]*\).*/\1/p' "$tmp/stats.json")
    [ "$conns" -ge 2 ] || { echo "FAIL: the host did not reconnect after the reset ($conns connections)"; exit 1; }
    echo "the host reconnected after the chip reset and every vector passed"
fi
awk -v s="$start" -v e="$end" 'BEGIN { printf "wall time of the check: %.2f s\n", e - s }'
