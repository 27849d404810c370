#!/bin/sh
# The installed cbvh, from a copy of the installed tree moved elsewhere (the
# data directory is found from the executable, not from where it was built or
# installed): --version, `vectors check` of the installed vectors, and `run`
# with its defaults taken from the moved tree's share/cbvh, from another
# working directory.
#   installed_tool.sh PREFIX WORK VERSION
set -eu
prefix=$1 work=$2 version=$3
rm -rf "$work"
mkdir -p "$work"
cp -a "$prefix" "$work/moved"
cbvh=$work/moved/bin/cbvh
data=$(cd "$work/moved/share/cbvh" && pwd -P)

out=$("$cbvh" --version)
[ "$out" = "cbvh $version" ] || { echo "cbvh --version: '$out', expected 'cbvh $version'"; exit 1; }
echo "$out"

"$cbvh" vectors check --backend model --quiet "$data/vectors"

cd /
out=$("$cbvh" run --backend model) || { echo "$out"; echo "installed cbvh run failed"; exit 1; }
echo "$out" | head -n 3
echo "$out" | grep -q "^== Golden vectors: $data/vectors ==" ||
    { echo "cbvh run did not take its vectors from $data/vectors"; exit 1; }
echo "$out" | grep -q "^== Accuracy vs time: $data/scenes/bunny.scene " ||
    { echo "cbvh run did not take its scene from $data/scenes"; exit 1; }
