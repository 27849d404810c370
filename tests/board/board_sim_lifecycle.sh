#!/bin/sh
# `cbvh board-sim` starting, stopping and being found, through the CLI.
# Usage: board_sim_lifecycle.sh PATH/TO/cbvh GROUP VECTOR-DIR
#   stale_socket   a board killed with SIGKILL leaves its socket file: a new
#                  board replaces it; a live board's path is refused with
#                  "another board is already listening on PATH" (exit 1)
#   gateware_stop  SIGTERM while the gateware simulation never answers stops
#                  board-sim at once, exit 1 with one line, child and socket
#                  gone; an idle stop of an answering simulation exits 0
#   auto_sim       --backend auto (the default) uses the board at
#                  CBVH_SIM_ADDR as `cbvh devices` lists it; with no board
#                  there it falls back to the model, saying why
set -u
cbvh=$1
group=$2
vec=$3
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cbvh-life-XXXXXX") || exit 1
pids=
cleanup() {
    for p in $pids; do kill -9 "$p" 2>/dev/null; done
    rm -rf "$tmp"
}
trap cleanup EXIT INT TERM
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
ok() { echo "ok: $*"; }

# start_board NAME ARGS...: board-sim in the background, $bpid; waits for its socket
start_board() {
    sock=$1
    shift
    # emptied here, not only by the child's redirection: the wait below must
    # not find the previous board's "listening on" before the child has run
    : >"$tmp/board.out"
    "$cbvh" board-sim --listen "unix:$sock" "$@" >"$tmp/board.out" 2>"$tmp/board.err" &
    bpid=$!
    pids="$pids $bpid"
    i=0
    while ! grep -q "listening on" "$tmp/board.out" 2>/dev/null && kill -0 $bpid 2>/dev/null && [ $i -lt 250 ]; do
        sleep 0.02
        i=$((i + 1))
    done
    grep -q "listening on" "$tmp/board.out" || { fail "board-sim $* did not come up:"; cat "$tmp/board.err"; }
}

# ms since the epoch (date +%s%N: GNU coreutils)
now_ms() { echo $(($(date +%s%N) / 1000000)); }

one_file=$vec/axis_compress-N6-ms-30.vec

case $group in
stale_socket)
    sock=$tmp/b.sock
    start_board "$sock"
    first=$bpid
    # a second board on a live board's path: refused, naming it
    "$cbvh" board-sim --listen "unix:$sock" >/dev/null 2>"$tmp/err2" </dev/null &
    p2=$!
    pids="$pids $p2"
    i=0
    while kill -0 $p2 2>/dev/null && [ $i -lt 150 ]; do sleep 0.02; i=$((i + 1)); done
    kill $p2 2>/dev/null
    wait $p2
    rc=$?
    if [ "$rc" = 1 ] && [ "$(wc -l <"$tmp/err2")" = 1 ] &&
        grep -q -F "cbvh board-sim: another board is already listening on $sock" "$tmp/err2"; then
        ok "live board's path refused: $(cat "$tmp/err2")"
    else
        fail "second board on a live path: exit $rc (want 1), said:"; cat "$tmp/err2"
    fi
    # ... and the live board still answers
    "$cbvh" vectors check --backend "sim:unix:$sock" --sample 5 "$one_file" >"$tmp/out" 2>&1 ||
        { fail "the first board stopped answering:"; cat "$tmp/out"; }
    # a crash leaves the socket file; a new board replaces it and answers
    kill -9 $first
    wait $first 2>/dev/null
    [ -S "$sock" ] || fail "SIGKILL should leave the socket file (the case under test)"
    start_board "$sock"
    second=$bpid
    if "$cbvh" vectors check --backend "sim:unix:$sock" --sample 5 "$one_file" >"$tmp/out" 2>&1; then
        ok "board restarted over the stale socket file and answers"
    else
        fail "no check against the restarted board:"; cat "$tmp/board.err" "$tmp/out"
    fi
    kill -TERM $second
    wait $second
    rc=$?
    [ "$rc" = 0 ] && [ ! -e "$sock" ] && ok "SIGTERM: exit 0, socket removed" ||
        fail "SIGTERM of an idle board: exit $rc (want 0), socket $( [ -e "$sock" ] && echo left || echo removed)"
    # a path that is not a socket is not removed
    echo keep >"$tmp/file"
    "$cbvh" board-sim --listen "unix:$tmp/file" >/dev/null 2>"$tmp/err3" </dev/null
    rc=$?
    if [ "$rc" = 1 ] && [ "$(cat "$tmp/file")" = keep ] && grep -q "the path exists and is not a socket" "$tmp/err3"; then
        ok "a regular file at the path is left alone: $(cat "$tmp/err3")"
    else
        fail "regular file at the path: exit $rc, said:"; cat "$tmp/err3"
    fi
    ;;
gateware_stop)
    # never answers a transaction (keeps its stdout open, so it is not "ended")
    printf '#!/bin/sh\necho $$ >"%s/stub.pid"\ncat >/dev/null\n' "$tmp" >"$tmp/stuck"
    chmod +x "$tmp/stuck"
    sock=$tmp/g.sock
    start_board "$sock" --gateware "$tmp/stuck"
    # a request that will wait on the stuck simulation
    CBVH_LINK_RETRIES=0 CBVH_LINK_TIMEOUT_MS=30000 "$cbvh" vectors check --backend "sim:unix:$sock" --sample 1 \
        "$one_file" >"$tmp/host.out" 2>&1 &
    hpid=$!
    pids="$pids $hpid"
    sleep 0.3
    t0=$(now_ms)
    kill -TERM $bpid
    wait $bpid
    brc=$?
    took=$(($(now_ms) - t0))
    if [ "$brc" = 1 ] && [ $took -lt 3000 ] && [ "$(wc -l <"$tmp/board.err")" = 1 ] &&
        grep -q "stopped by a signal while waiting for the gateware simulation" "$tmp/board.err"; then
        ok "stuck simulation: stopped in $took ms, exit 1: $(cat "$tmp/board.err")"
    else
        fail "stuck simulation: exit $brc (want 1) after $took ms (want < 3000), said:"; cat "$tmp/board.err"
    fi
    [ ! -e "$sock" ] || fail "socket file left behind"
    if [ -s "$tmp/stub.pid" ] && kill -0 "$(cat "$tmp/stub.pid")" 2>/dev/null; then
        fail "the simulation process is still running"
    fi
    i=0
    while kill -0 $hpid 2>/dev/null && [ $i -lt 250 ]; do sleep 0.02; i=$((i + 1)); done
    kill -0 $hpid 2>/dev/null && fail "the host still waits after the board stopped"
    wait $hpid
    hrc=$?
    [ "$hrc" != 0 ] && ok "host check failed (exit $hrc) as it must" || fail "host check passed against an abandoned board"
    # an answering simulation (every MISO byte 0: never busy), stopped while idle: exit 0
    cat >"$tmp/answers" <<'EOF'
#!/bin/sh
while read -r n rest; do
    [ "$n" = 0 ] && exit 0
    line=@
    i=0
    while [ "$i" -lt "$n" ]; do line="$line 00"; i=$((i + 1)); done
    echo "$line"
done
EOF
    chmod +x "$tmp/answers"
    start_board "$sock" --gateware "$tmp/answers"
    sleep 0.2
    kill -TERM $bpid
    wait $bpid
    brc=$?
    [ "$brc" = 0 ] && [ ! -s "$tmp/board.err" ] && ok "idle stop with an answering simulation: exit 0" ||
        { fail "idle stop: exit $brc (want 0), said:"; cat "$tmp/board.err"; }
    ;;
auto_sim)
    sock=$tmp/a.sock
    start_board "$sock"
    CBVH_SIM_ADDR=unix:$sock "$cbvh" vectors check --sample 5 "$one_file" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    if [ "$rc" = 0 ] && grep -q "^backend: sim unix:$sock" "$tmp/out" && [ ! -s "$tmp/err" ]; then
        ok "auto used the board at CBVH_SIM_ADDR"
    else
        fail "auto with CBVH_SIM_ADDR and a live board: exit $rc:"; cat "$tmp/out" "$tmp/err"
    fi
    CBVH_SIM_ADDR=unix:$sock "$cbvh" devices >"$tmp/dev" 2>&1
    grep -q "^sim: *sim unix:$sock" "$tmp/dev" && ok "devices lists the same board" ||
        { fail "devices did not list the board:"; cat "$tmp/dev"; }
    kill -TERM $bpid
    wait $bpid
    CBVH_SIM_ADDR=unix:$sock "$cbvh" vectors check --sample 5 "$one_file" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    if [ "$rc" = 0 ] && grep -q "^backend: model" "$tmp/out" && [ "$(wc -l <"$tmp/err")" = 1 ] &&
        grep -q "no board found (usb: .*; hid: .*; sim: no virtual board: connect to $sock" "$tmp/err"; then
        ok "no board at CBVH_SIM_ADDR: the model, saying why: $(cat "$tmp/err")"
    else
        fail "auto with CBVH_SIM_ADDR and no board: exit $rc:"; cat "$tmp/out" "$tmp/err"
    fi
    ;;
*)
    echo "unknown group '$group'"; exit 2 ;;
esac
[ "$fails" = 0 ] || { echo "$fails case(s) failed"; exit 1; }
echo "PASS: $group"
