#!/bin/sh
# sh closed_pipe.sh CBVH WORKDIR ARGS...
# Runs `cbvh ARGS` with its standard output a pipe whose reader has already
# closed it (as `cbvh ... | head -1` after head is done): the output cannot be
# written, so exit 2 with one line saying so -- not death by SIGPIPE (exit
# 141, no message).
cbvh=$1 work=$2
shift 2
rm -rf "$work" && mkdir -p "$work" || exit 1
# The writer starts only once the reader has closed its end.
(
    while [ ! -e "$work/closed" ]; do sleep 0.05; done
    "$cbvh" "$@" 2>"$work/err"
    echo $? >"$work/rc"
) | (
    exec 0<&-
    : >"$work/closed"
)
rc=$(cat "$work/rc")
err=$(cat "$work/err")
lines=$(wc -l <"$work/err")
if [ "$rc" != 2 ] || [ "$lines" != 1 ] ||
    [ "$err" != "cbvh: cannot write the output to standard output: Broken pipe" ]; then
    echo "cbvh $*: into a closed pipe: exit $rc (expected 2), stderr ($lines lines, expected 1):"
    cat "$work/err"
    exit 1
fi
echo "ok: cbvh $*: exit 2, one line"
