#!/bin/sh
# ctest driver for the board as a umockdev USB device (board_umockdev.c):
# the host's real libusb and hidapi-libusb code paths against the board's
# own USB stack and firmware core.
#   run_umockdev.sh BOARD_UMOCKDEV CBVH VECTORS CASE
# CASE: devices | vectors_usb | vectors_hid | unplug | permission (CBVH = cbvh,
# hidapi-libusb), devices_hidraw | vectors_hidraw (CBVH = cbvh_hidraw, cbvh
# built against hidapi-hidraw).
# Exit 77 (ctest SKIP) when umockdev is not installed (scripts/install-deps).
set -u
board=$1 cbvh=$2 vectors=$3 case=$4
command -v umockdev-wrapper >/dev/null 2>&1 ||
    { echo "SKIP: umockdev not installed (scripts/install-deps: umockdev, libumockdev-dev)"; exit 77; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cbvh-umockdev-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
fail() { echo "FAIL: $*"; exit 1; }
run() { # run [board options] -- cbvh args: output in $tmp/out, $tmp/err; status in $rc
    "$board" "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    cat "$tmp/out" "$tmp/err"
}
# vectors_ok BACKEND SAMPLE: every vector of --sample SAMPLE passed on the
# board through that backend: SAMPLE from each file the set's MANIFEST lists
# (every committed file holds more than SAMPLE vectors)
vectors_ok() {
    [ $rc -eq 0 ] || fail "cbvh vectors check exit $rc"
    grep -q "^backend: $1 1209:c0b1 cbvh-rp2040 " "$tmp/out" || fail "not the $1 board"
    files=$(grep -c '\.vec$' "$vectors/MANIFEST") || fail "no MANIFEST in $vectors"
    grep -q "^total: $files files, $((files * $2)) passed, 0 failed" "$tmp/out" || fail "not every sampled vector passed"
}
case $case in
devices)
    run -- "$cbvh" devices
    [ $rc -eq 0 ] || fail "cbvh devices exit $rc"
    grep -q '^usb:   1209:c0b1 bus 1 addr 2 "cbvh board" serial 0001$' "$tmp/out" || fail "libusb did not list the board"
    grep -q '^hid:   1209:c0b1 .* "cbvh board" serial 0001$' "$tmp/out" || fail "hidapi-libusb did not list the board" ;;
vectors_usb)
    # --backend auto must pick the board: no fallback line
    run -- "$cbvh" vectors check --sample 20 -q "$vectors"
    vectors_ok usb 20
    grep -q 'no board found' "$tmp/err" && fail "auto fell back to the model" ;;
vectors_hid)
    run -- "$cbvh" vectors check --backend hid --sample 10 -q "$vectors"
    vectors_ok hid 10 ;;
unplug)
    # pulled out after 100 data URBs: the documented 'link lost' error, exit
    # non-zero, the vectors named as not run, nothing reported as passed
    CBVH_LINK_TIMEOUT_MS=300 run --remove-after-urbs 100 -- "$cbvh" vectors check --backend usb --sample 10 -q "$vectors"
    [ $rc -ne 0 ] || fail "a board unplugged mid-run went unnoticed (exit 0)"
    grep -q 'device unplugged after' "$tmp/err" || fail "the device was not unplugged"
    grep -q 'not run: no valid reply to command 0x03 .* after 9 attempts: link lost and not back within 300 ms' "$tmp/err" ||
        fail "not the documented error (docs/protocol.md)"
    grep -q '^total: .*0 failed' "$tmp/out" && fail "a total was printed as if the run had finished" ;;
permission)
    [ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root to run cbvh as user nobody"; exit 77; }
    command -v setpriv >/dev/null 2>&1 || { echo "SKIP: setpriv (util-linux) not installed"; exit 77; }
    run --no-permission -- "$cbvh" devices
    grep -q '^usb:   1209:c0b1 bus 1 addr 2: cannot open (Access denied (insufficient permissions)); install firmware/udev/60-cbvh.rules' "$tmp/out" ||
        fail "no udev hint for a node without permission"
    run --no-permission -- "$cbvh" vectors check --backend usb --sample 1 "$vectors"
    [ $rc -ne 0 ] || fail "vectors check without permission exit 0"
    grep -q "found but cannot be opened: Access denied .*install firmware/udev/60-cbvh.rules" "$tmp/err" ||
        fail "no udev hint from vectors check" ;;
devices_hidraw)
    run -- "$cbvh" devices
    [ $rc -eq 0 ] || fail "cbvh devices exit $rc"
    grep -q '^hid:   1209:c0b1 /dev/hidraw0 "cbvh board" serial 0001$' "$tmp/out" || fail "hidapi-hidraw did not list the board" ;;
vectors_hidraw)
    run -- "$cbvh" vectors check --backend hid --sample 5 -q "$vectors"
    vectors_ok hid 5 ;;
*) echo "run_umockdev.sh: unknown case '$case'"; exit 2 ;;
esac
echo "ok: $case"
