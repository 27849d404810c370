#!/bin/sh
# Bad options and environment of `cbvh board-sim` / `cbvh devices`: each must
# exit 2 with exactly one line on stderr naming the problem (nothing taken in
# part, nothing ignored).  A board-sim that does start (on a private socket)
# is killed after 5 s, which fails the case.
# Usage: cli_bad_input.sh PATH/TO/cbvh GROUP VECTOR-DIR
#   GROUP: listen, rx_idle, host_idle, faults, env, devices_sim, gateware, options, backend; VECTOR-DIR: a valid one, so
#   that `vectors check` gets as far as opening its backend
set -u
cbvh=$1
group=$2
vec=$3
tmp=$(mktemp -d "${TMPDIR:-/tmp}/cbvh-badin-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
fails=0

# expect RC SUBSTRING [VAR=VALUE ...] -- ARGS...
expect() {
    want_rc=$1 want=$2
    shift 2
    vars=
    while [ "$1" != "--" ]; do vars="$vars $1"; shift; done
    shift
    # shellcheck disable=SC2086
    env $vars timeout 5 "$cbvh" "$@" >"$tmp/out" 2>"$tmp/err" </dev/null
    rc=$?
    lines=$(wc -l <"$tmp/err")
    if [ "$rc" != "$want_rc" ] || [ "$lines" != 1 ] || ! grep -q -F -- "$want" "$tmp/err"; then
        echo "FAIL:$vars cbvh $*: exit $rc (want $want_rc), $lines stderr lines (want 1), want '$want' in:"
        sed 's/^/    /' "$tmp/err"
        fails=$((fails + 1))
    else
        echo "ok:$vars cbvh $*: exit $rc: $(cat "$tmp/err")"
    fi
}

case $group in
listen)
    expect 2 "--listen: bad port '99999' in board address 'tcp:127.0.0.1:99999' (expected a number in 1..65535)" \
        -- board-sim --listen tcp:127.0.0.1:99999
    expect 2 "bad port '0'" -- board-sim --listen tcp:127.0.0.1:0
    expect 2 "bad port 'http'" -- board-sim --listen tcp:127.0.0.1:http
    expect 2 "--listen: bad board address 'foo'" -- board-sim --listen foo
    expect 2 "--listen: bad unix socket path" -- board-sim --listen unix:
    # a valid address that cannot be listened on is a runtime failure, exit 1
    expect 1 "listen on $tmp/no/such/dir.sock" -- board-sim --listen "unix:$tmp/no/such/dir.sock"
    ;;
rx_idle)
    expect 2 "--rx-idle-ms expects an integer in 1..60000, got '5x'" -- board-sim --listen "unix:$tmp/b.sock" --rx-idle-ms 5x
    expect 2 "got '99999999999'" -- board-sim --listen "unix:$tmp/b.sock" --rx-idle-ms 99999999999
    expect 2 "got '0'" -- board-sim --listen "unix:$tmp/b.sock" --rx-idle-ms 0
    expect 2 "got '60001'" -- board-sim --listen "unix:$tmp/b.sock" --rx-idle-ms 60001
    expect 2 "got ''" -- board-sim --listen "unix:$tmp/b.sock" --rx-idle-ms ""
    ;;
host_idle)
    expect 2 "cbvh board-sim: --host-idle-ms expects an integer in 0..3600000, got '5x'" \
        -- board-sim --listen "unix:$tmp/b.sock" --host-idle-ms 5x
    expect 2 "got '-1'" -- board-sim --listen "unix:$tmp/b.sock" --host-idle-ms -1
    expect 2 "got '3600001'" -- board-sim --listen "unix:$tmp/b.sock" --host-idle-ms 3600001
    expect 2 "got ''" -- board-sim --listen "unix:$tmp/b.sock" --host-idle-ms ""
    expect 2 "cbvh board-sim: --host-idle-ms needs a value (an integer in 0..3600000)" -- board-sim --host-idle-ms
    if "$cbvh" board-sim --help | tr '\n' ' ' | grep -q -- "--host-idle-ms N lets a host go .* 0 never (default 10000)"; then
        echo "ok: board-sim --help documents --host-idle-ms and its default"
    else
        echo "FAIL: board-sim --help does not document --host-idle-ms and its default"; fails=$((fails + 1))
    fi
    ;;
faults)
    expect 2 "--faults: fault spec item 'drop=nan': bad value, expected a probability in [0,1]" -- board-sim --listen "unix:$tmp/b.sock" --faults drop=nan
    expect 2 "item 'delay_ms=-5': bad value, expected an integer in 0..10000" -- board-sim --listen "unix:$tmp/b.sock" --faults delay_ms=-5
    expect 2 "item 'delay_ms=10001': bad value" -- board-sim --listen "unix:$tmp/b.sock" --faults delay_ms=10001
    expect 2 "item 'seed=-1': bad value, expected a decimal integer" -- board-sim --listen "unix:$tmp/b.sock" --faults seed=-1
    expect 2 "item 'seed=1e30': bad value" -- board-sim --listen "unix:$tmp/b.sock" --faults seed=1e30
    expect 2 "unknown item 'dorp'" -- board-sim --listen "unix:$tmp/b.sock" --faults dorp=0.1
    expect 2 "rates add up to 3, more than 1" -- board-sim --listen "unix:$tmp/b.sock" --faults all=0.5
    # the same parser for the host's requests (sim: backend)
    expect 2 "CBVH_LINK_FAULTS: fault spec item 'drop=nan': bad value" CBVH_LINK_FAULTS=drop=nan \
        -- vectors check --backend "sim:unix:$tmp/b.sock" "$vec"
    ;;
env)
    expect 2 "cbvh devices: CBVH_USB_VID='zzzz' is not a USB ID (expected 1 to 4 hex digits, optional 0x" \
        CBVH_USB_VID=zzzz -- devices
    expect 2 "CBVH_USB_VID='123456' is not a USB ID" CBVH_USB_VID=123456 -- devices
    expect 2 "CBVH_USB_PID='-1' is not a USB ID" CBVH_USB_PID=-1 -- devices
    expect 2 "cbvh devices: CBVH_LINK_TIMEOUT_MS='5x' is not valid (expected an integer in 1..600000)" \
        CBVH_LINK_TIMEOUT_MS=5x -- devices
    expect 2 "CBVH_LINK_RETRIES='99999999999' is not valid (expected an integer in 0..1000)" \
        CBVH_LINK_RETRIES=99999999999 -- devices
    # --backend auto does not fall back to the model over a bad setting
    expect 2 "CBVH_USB_PID='xyz' is not a USB ID" CBVH_USB_PID=xyz -- vectors check --backend auto "$vec"
    expect 2 "CBVH_LINK_RETRIES='2x' is not valid" CBVH_LINK_RETRIES=2x \
        -- vectors check --backend "sim:unix:$tmp/b.sock" "$vec"
    # the accepted forms still list
    if CBVH_USB_VID=0x1209 CBVH_USB_PID=C0B1 CBVH_LINK_RETRIES= "$cbvh" devices >"$tmp/out" 2>"$tmp/err" &&
        grep -q '1209:c0b1' "$tmp/out"; then
        echo "ok: CBVH_USB_VID=0x1209 CBVH_USB_PID=C0B1 accepted"
    else
        echo "FAIL: valid CBVH_USB_VID/PID refused:"; cat "$tmp/err" "$tmp/out"; fails=$((fails + 1))
    fi
    ;;
devices_sim)
    expect 2 "cbvh devices: --sim: bad board address 'foo' (expected unix:PATH, tcp:HOST:PORT or a PATH with '/')" \
        -- devices --sim foo
    expect 2 "--sim: bad port '99999'" -- devices --sim tcp:127.0.0.1:99999
    expect 2 "cbvh devices: CBVH_SIM_ADDR: bad board address 'foo'" CBVH_SIM_ADDR=foo -- devices
    # and a sim: backend with a bad address says so, without a `board-sim --listen foo` hint
    expect 2 "backend 'sim:foo': bad board address 'foo'" -- vectors check --backend sim:foo "$vec"
    if grep -q "board-sim --listen" "$tmp/err"; then
        echo "FAIL: the error suggests an invalid board-sim command"; fails=$((fails + 1))
    fi
    ;;
gateware)
    expect 2 "cbvh board-sim: --gateware: cannot read '$tmp/none.vvp': No such file or directory" \
        -- board-sim --listen "unix:$tmp/b.sock" --gateware "$tmp/none.vvp"
    # A simulation that ends under the board: the host's check fails, and
    # board-sim stops with one line saying so (exit 1), not a hang.
    printf '#!/bin/sh\nexit 3\n' >"$tmp/dies"
    chmod +x "$tmp/dies"
    "$cbvh" board-sim --listen "unix:$tmp/g.sock" --gateware "$tmp/dies" >/dev/null 2>"$tmp/board.err" &
    bpid=$!
    i=0
    while [ ! -S "$tmp/g.sock" ] && [ $i -lt 250 ]; do sleep 0.02; i=$((i + 1)); done
    CBVH_LINK_RETRIES=0 timeout 20 "$cbvh" vectors check --backend "sim:unix:$tmp/g.sock" --sample 1 \
        "$vec/axis_compress-N6-ms-30.vec" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    i=0
    while kill -0 $bpid 2>/dev/null && [ $i -lt 250 ]; do sleep 0.02; i=$((i + 1)); done
    kill $bpid 2>/dev/null
    wait $bpid
    brc=$?
    if [ "$rc" = 2 ] && [ "$brc" = 1 ] && [ "$(wc -l <"$tmp/board.err")" = 1 ] &&
        grep -q -F "cbvh board-sim: gateware simulation ended (exit status 3)" "$tmp/board.err"; then
        echo "ok: a dying simulation: check exit $rc, board-sim exit $brc: $(cat "$tmp/board.err")"
    else
        echo "FAIL: a dying simulation: check exit $rc (want 2), board-sim exit $brc (want 1), board-sim said:"
        sed 's/^/    /' "$tmp/board.err"; fails=$((fails + 1))
    fi
    ;;
options)
    # one line naming the option, not the usage text; bad input is exit 2
    expect 2 "cbvh board-sim: unknown option '--bogus' (cbvh board-sim --help)" -- board-sim --bogus
    expect 2 "cbvh board-sim: unknown option 'extra' (cbvh board-sim --help)" -- board-sim extra
    expect 2 "cbvh board-sim: --listen needs a value (unix:PATH or tcp:HOST:PORT)" -- board-sim --listen
    expect 2 "cbvh board-sim: --faults needs a value" -- board-sim --listen "unix:$tmp/b.sock" --faults
    expect 2 "cbvh board-sim: --rx-idle-ms needs a value (an integer in 1..60000)" -- board-sim --rx-idle-ms
    expect 2 "cbvh board-sim: --break-unit needs a value" -- board-sim --break-unit
    expect 2 "cbvh board-sim: --gateware needs a value" -- board-sim --gateware
    # a --gateware that cannot be a simulation is bad input too, not a runtime failure
    echo "not a program" >"$tmp/plain"
    expect 2 "cbvh board-sim: --gateware: '$tmp/plain' is neither a vvp script nor executable" \
        -- board-sim --listen "unix:$tmp/b.sock" --gateware "$tmp/plain"
    expect 2 "cbvh board-sim: --gateware: '$tmp' is not a file" -- board-sim --listen "unix:$tmp/b.sock" --gateware "$tmp"
    if "$cbvh" board-sim --help | grep -q "Exit status: 0 .*; 1 .*" && "$cbvh" board-sim --help | grep -q "2 bad options"; then
        echo "ok: board-sim --help documents its exit statuses"
    else
        echo "FAIL: board-sim --help does not document its exit statuses"; fails=$((fails + 1))
    fi
    ;;
backend)
    expect 2 "backend 'model:xyz': the model backend takes no argument (got 'model:xyz'; use 'model')" \
        -- vectors check --backend model:xyz "$vec"
    expect 2 "the model backend takes no argument" -- vectors check --backend model: "$vec"
    # auto checks CBVH_SIM_ADDR as `cbvh devices` does, before probing anything
    expect 2 "backend 'auto': CBVH_SIM_ADDR: bad board address 'foo' (expected unix:PATH, tcp:HOST:PORT or a PATH with '/')" \
        CBVH_SIM_ADDR=foo -- vectors check --backend auto "$vec"
    expect 2 "CBVH_SIM_ADDR: bad port '99999'" CBVH_SIM_ADDR=tcp:127.0.0.1:99999 -- vectors check "$vec"
    expect 2 "sim backend at CBVH_SIM_ADDR=unix:$tmp/b.sock: CBVH_LINK_FAULTS: fault spec item 'drop=nan'" \
        CBVH_SIM_ADDR="unix:$tmp/b.sock" CBVH_LINK_FAULTS=drop=nan -- vectors check "$vec"
    ;;
*)
    echo "unknown group '$group'"; exit 2 ;;
esac
[ "$fails" = 0 ] || { echo "$fails case(s) failed"; exit 1; }
echo "PASS: $group"
