#!/bin/sh
# Runs the firmware self-test on qemu (mps2-an385, semihosting) and on the
# host; both must pass and print the same reply digest.
# Usage: run_qemu_selftest.sh BUILD_DIR qemu-system-arm cbvh-selftest.elf fw_selftest_host
# Builds the ARM image first (target firmware_selftest); when the model does
# not cross-compile, says why and exits 77 (skipped).
set -u
if ! out=$(cmake --build "$1" --target firmware_selftest 2>&1); then
    echo "$out" | grep -E "error" | head -n 5
    echo "SKIP: the bit-exact model does not cross-compile for Cortex-M3 (errors above); the firmware self-test cannot run"
    exit 77
fi
shift
arm=$(timeout 60 "$1" -M mps2-an385 -nographic -semihosting -kernel "$2" </dev/null)
rc=$?
echo "qemu:  $arm (exit $rc)"
[ "$rc" = 0 ] || { echo "FAIL: self-test on qemu failed"; exit 1; }
host=$("$3")
echo "host:  $host"
d_arm=$(echo "$arm" | sed -n 's/.*digest \([0-9a-f]*\).*/\1/p')
d_host=$(echo "$host" | sed -n 's/.*digest \([0-9a-f]*\).*/\1/p')
[ -n "$d_arm" ] && [ "$d_arm" = "$d_host" ] || { echo "FAIL: digests differ (ARM '$d_arm', host '$d_host')"; exit 1; }
echo "PASS: Cortex-M3 and host firmware agree bit for bit"
