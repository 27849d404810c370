#!/bin/sh
# An interrupted `cbvh vectors gen` leaves a folder that `vectors check`
# passes: each finished file is listed in MANIFEST as soon as it is renamed
# into place (or, after a SIGKILL between the two, in the journal), SIGTERM/SIGINT remove the file being written and exit non-zero
# with one line, and after a SIGKILL check ignores the stray temporary file
# with a note naming it.
# Usage: gen_interrupt.sh PATH/TO/cbvh WORK-DIR
set -u
cbvh=$1
work=$2/gen_interrupt
rm -rf "$work"
mkdir -p "$work" || exit 1
d=$work/vec
fail() { echo "FAIL: $*"; exit 1; }

# Kills gen ($1) with signal $2 once at least one file of this run is listed
# (MANIFEST differs from $3) and, if it shows up in time, a temporary file is
# being written.
interrupt() {
    i=0
    while cmp -s "$3" "$d/MANIFEST" && [ $i -lt 1500 ]; do sleep 0.01; i=$((i + 1)); done
    i=0
    while [ $i -lt 300 ]; do
        for t in "$d"/.*.tmp.*; do [ -e "$t" ] && break 2; done
        sleep 0.005; i=$((i + 1))
    done
    kill "-$2" "$1"
    wait "$1"
}

# Level-2 files of one unit, complete; then a level-2 run of every unit with
# another seed (which overwrites them first, and takes far longer than the
# test waits) interrupted after its first file.
"$cbvh" vectors gen --level 2 --unit scale_estimate -o "$d" >/dev/null || fail "first gen failed"
cp "$d/MANIFEST" "$work/before"
"$cbvh" vectors gen --level 2 --seed 5 -o "$d" >"$work/out" 2>"$work/err" &
interrupt $! TERM "$work/before"
rc=$?
[ "$rc" = 143 ] || fail "SIGTERM: gen exited $rc, want 143 (128 + SIGTERM)"
grep -q "^cbvh vectors gen: interrupted; the files finished before are listed in $d/MANIFEST\$" "$work/err" &&
    [ "$(wc -l <"$work/err")" = 1 ] || fail "SIGTERM: want one line on stderr, got: $(cat "$work/err")"
ls -a "$d" | grep -q '\.tmp\.' && fail "SIGTERM: temporary files left: $(ls -a "$d" | grep '\.tmp\.')"
cmp -s "$work/before" "$d/MANIFEST" && fail "SIGTERM: no file of the interrupted run was listed"
"$cbvh" vectors check --backend model --quiet "$d" >"$work/check" 2>&1 || fail "check after SIGTERM: $(cat "$work/check")"
echo "PASS: SIGTERM: exit 143, one line, no temporary file, check passes"

# SIGINT, where the shell lets a background job receive it.
if env --default-signal=INT true 2>/dev/null; then
    cp "$d/MANIFEST" "$work/before"
    env --default-signal=INT "$cbvh" vectors gen --level 2 --seed 6 -o "$d" >"$work/out" 2>"$work/err" &
    interrupt $! INT "$work/before"
    rc=$?
    [ "$rc" = 130 ] || fail "SIGINT: gen exited $rc, want 130 (128 + SIGINT)"
    [ "$(wc -l <"$work/err")" = 1 ] && grep -q "interrupted" "$work/err" || fail "SIGINT: stderr: $(cat "$work/err")"
    ls -a "$d" | grep -q '\.tmp\.' && fail "SIGINT: temporary files left"
    "$cbvh" vectors check --backend model --quiet "$d" >"$work/check" 2>&1 || fail "check after SIGINT: $(cat "$work/check")"
    echo "PASS: SIGINT: exit 130, no temporary file, check passes"
else
    echo "note: env --default-signal not available; SIGINT not tested"
fi

# SIGKILL: every finished file listed; a temporary file may be left, which
# check ignores, naming it.
cp "$d/MANIFEST" "$work/before"
"$cbvh" vectors gen --level 2 --seed 7 -o "$d" >/dev/null 2>&1 &
interrupt $! KILL "$work/before"
touch "$d/.ray_box-N6-ms-30.vec.tmp.999999" # as a kill during a write leaves
"$cbvh" vectors check --backend model --quiet "$d" >"$work/check" 2>&1 || fail "check after SIGKILL: $(cat "$work/check")"
grep -q "^cbvh: note: ignoring [0-9]* temporary files\{0,1\} of an interrupted \`vectors gen\`, e.g. $d/\..*\.tmp\.[0-9]*" \
    "$work/check" || fail "check after SIGKILL does not name the temporary file: $(cat "$work/check")"
echo "PASS: SIGKILL: finished files listed, check passes and names the temporary file"

# A SIGKILL between a rename and the MANIFEST update it belongs to (a window
# no kill can be aimed at, so made by hand): the journal vouches for the new
# file, check passes and says so, and the next gen lists it in MANIFEST.
# The SIGKILL above may itself have landed in that window and left a journal
# (check passed on it); a gen settles it first, so that the journal made here
# is the only one and does not overwrite an entry the directory needs.
if [ -e "$d/.MANIFEST.pending" ]; then
    "$cbvh" vectors gen --unit ray_box --bits 4 -o "$d" >/dev/null || fail "gen settling the SIGKILL's journal failed"
    [ -e "$d/.MANIFEST.pending" ] && fail "gen left the SIGKILL's journal"
fi
x=scale_estimate-N4-ms-30-L2.vec
"$cbvh" vectors gen --level 2 --unit scale_estimate --bits 4 --seed 8 -o "$work/side" >/dev/null || fail "side gen failed"
cmp -s "$work/side/$x" "$d/$x" && fail "side gen made the same $x"
cp "$work/side/$x" "$d/$x"
grep "  $x\$" "$work/side/MANIFEST" >"$d/.MANIFEST.pending"
"$cbvh" vectors check --backend model --quiet "$d" >"$work/check" 2>&1 || fail "check with a journal: $(cat "$work/check")"
grep -q "^cbvh: note: $d/$x was put in place by a \`vectors gen\` killed before it updated MANIFEST" "$work/check" ||
    fail "check does not name the journaled file: $(cat "$work/check")"
"$cbvh" vectors gen --unit ray_box --bits 4 -o "$d" >/dev/null || fail "gen after a journal failed"
[ -e "$d/.MANIFEST.pending" ] && fail "gen left the journal"
grep -q "^$(sha256sum <"$d/$x" | cut -c1-64)  $x\$" "$d/MANIFEST" || fail "gen did not list the journaled $x"
(cd "$d" && sha256sum --quiet -c MANIFEST) || fail "sha256sum -c after gen settled the journal"
echo "PASS: journal: check accepts the file it vouches for, the next gen lists it"
rm -rf "$work"
