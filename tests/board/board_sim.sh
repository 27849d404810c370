# Sourced by the test scripts that need a virtual board (needs $cbvh).
# board_sim_start [board-sim options] (re)starts `$cbvh board-sim` on $sock,
# a unix socket in the temporary folder $tmp, and returns 0 once it listens,
# 1 if it does not within 5 s; the board and $tmp are removed on exit.
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cbvh-board-XXXXXX") || exit 1
sock=$tmp/board.sock
pid=
board_sim_stop() {
    [ -n "$pid" ] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
    pid=
}
trap 'board_sim_stop; rm -rf "$tmp"' EXIT INT TERM
board_sim_start() {
    board_sim_stop
    rm -f "$sock"
    "$cbvh" board-sim --listen "unix:$sock" "$@" >/dev/null &
    pid=$!
    i=0
    while [ ! -S "$sock" ] && [ $i -lt 250 ]; do sleep 0.02; i=$((i + 1)); done
    [ -S "$sock" ]
}
