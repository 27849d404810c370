#!/bin/sh
# Runs the firmware self-test on qemu (mps2-an385, semihosting) and on the
# host; both must pass and print the same reply digest, and both must pass
# every golden vector of VECTOR_DIR (read by the ARM image through semihosting).
# Usage: run_qemu_selftest.sh BUILD_DIR qemu-system-arm cbvh-selftest.elf fw_selftest_host VECTOR_DIR
# Builds the ARM image first (target firmware_selftest); when the model does
# not cross-compile, says why and exits 77 (skipped).
set -u
if ! out=$(cmake --build "$1" --target firmware_selftest 2>&1); then
    echo "$out" | grep -E "error" | head -n 5
    echo "SKIP: the bit-exact model does not cross-compile for Cortex-M3 (errors above); the firmware self-test cannot run"
    exit 77
fi
shift
vdir=$4
qvdir=$(printf '%s' "$vdir" | sed 's/,/,,/g') # qemu option syntax: a comma is written twice
arm=$(timeout 120 "$1" -M mps2-an385 -nographic -kernel "$2" \
      -semihosting-config "enable=on,target=native,arg=cbvh-selftest,arg=$qvdir" </dev/null)
rc=$?
echo "qemu:"
echo "$arm" | sed 's/^/  /'
echo "  (exit $rc)"
[ "$rc" = 0 ] || { echo "FAIL: self-test on qemu failed"; exit 1; }
host=$("$3" "$vdir")
rc=$?
echo "host:"
echo "$host" | sed 's/^/  /'
[ "$rc" = 0 ] || { echo "FAIL: self-test on the host failed"; exit 1; }
d_arm=$(echo "$arm" | sed -n 's/.*digest \([0-9a-f]*\).*/\1/p')
d_host=$(echo "$host" | sed -n 's/.*digest \([0-9a-f]*\).*/\1/p')
[ -n "$d_arm" ] && [ "$d_arm" = "$d_host" ] || { echo "FAIL: digests differ (ARM '$d_arm', host '$d_host')"; exit 1; }
for out in "$arm" "$host"; do
    echo "$out" | grep -Eq '^golden vectors: [1-9][0-9]* files, [1-9][0-9]* vectors, 0 failures' ||
        { echo "FAIL: the golden vectors did not all pass"; exit 1; }
done
echo "PASS: Cortex-M3 and host firmware agree bit for bit, and both pass every golden vector"
