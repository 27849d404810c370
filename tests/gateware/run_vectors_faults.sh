#!/bin/sh
# The testbenches' vector reader (gateware/tb/vecfile.vh) must refuse what is
# not a well-formed vector line or header, in every simulator run-vectors
# drives, and must count a wrong expected value as a failure:
#   run_vectors_faults.sh GATEWARE_DIR VECTOR_FILE WORKDIR [icarus|verilator]
# VECTOR_FILE should be small (scale_estimate-N6-ms-30.vec: 4 fields a line).
# One run-vectors call over all the cases (one simulator build).
set -u
gw=$1 src=$2 work=$3 sim=${4:-icarus}
opt=""
[ "$sim" = verilator ] && opt="-V"
rm -rf "$work" && mkdir -p "$work" || exit 1

# case K: the first data line rewritten by an awk statement; K = 0 unchanged
mk() {
    awk "body == 1 { body = 2; $2; print; next } \$0 == \"---\" { body = 1 } { print }" "$src" > "$work/case-$1.vec"
}
mk 0 ''
mk 1 '$0 = $0 " 0"'                        # one field more
mk 2 '$0 = $1 " " $2 " " $3'               # one field less
mk 3 '$1 = "3F80000G"'                     # a field that is not hex
mk 4 '$1 = "1" $1'                         # a field of 9 digits, 2^32 or more
mk 5 '$NF = ($NF == "00" ? "01" : "00")'   # an expected value off
sed 's/^count: \([0-9]*\)$/count: 1\1/' "$src" > "$work/case-6.vec"   # a count that disagrees

out=$(bash "$gw/scripts/run-vectors" $opt -w "$work/sim" "$work"/case-[0-6].vec 2>&1)
rc=$?
fails=0
check() {  # DESC EXTENDED_RE: a line of the output must match
    if printf '%s\n' "$out" | grep -Eq "$2"; then echo "ok ($sim): $1"; else
        echo "FAIL ($sim): $1: no line matches /$2/"; fails=$((fails + 1)); fi
}
nofail() {
    if printf '%s\n' "$out" | grep -q "^FAIL $work/case-$2.vec\$"; then
        echo "FAIL ($sim): $1: reported as failed"; fails=$((fails + 1)); else echo "ok ($sim): $1"; fi
}
[ $rc -eq 1 ] || { echo "FAIL ($sim): run-vectors exit $rc, expected 1"; fails=$((fails + 1)); }
nofail "the unchanged file is not failed" 0
check  "the unchanged file passes" "case-0\.vec: [0-9]+ vectors, 0 failures$"
for k in 1 2 3 4; do
    check "case $k: malformed line refused" "case-$k\.vec:[0-9]+: malformed vector line"
    check "case $k: file failed" "^FAIL $work/case-$k\.vec\$"
done
check "an expected value off: one failure" "case-5\.vec: [0-9]+ vectors, 1 failures$"
check "an expected value off: file failed" "^FAIL $work/case-5\.vec\$"
check "count mismatch: refused" "header count"
check "count mismatch: file failed" "^FAIL $work/case-6\.vec\$"

[ $fails -eq 0 ] && echo "run_vectors_faults ($sim): PASS" && exit 0
printf '%s\n' "$out" | head -n 40
echo "run_vectors_faults ($sim): $fails FAILED"; exit 1
