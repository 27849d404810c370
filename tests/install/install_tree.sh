#!/bin/sh
# `cmake --install BUILD --prefix PREFIX` into an empty PREFIX, then checks what
# it holds (README, "Install"): the tool, libcbvh static and shared with its
# soname, the headers, pkg-config and CMake package files, the vectors with
# their MANIFEST, the scenes, the docs and the udev rules; and that every
# installed header compiles on its own with only PREFIX/include (no private
# header of rtl-model/src behind it).
#   install_tree.sh BUILD PREFIX LIBDIR SOVERSION VERSION CC
set -eu
build=$1 prefix=$2 libdir=$3 soversion=$4 version=$5 cc=$6
rm -rf "$prefix"
cmake --install "$build" --prefix "$prefix" >"$prefix.log" 2>&1 || { cat "$prefix.log"; exit 1; }
bad=0
for f in bin/cbvh \
         "$libdir/libcbvh.a" "$libdir/libcbvh.so" "$libdir/libcbvh.so.$soversion" "$libdir/libcbvh.so.$version" \
         "$libdir/pkgconfig/cbvh.pc" \
         "$libdir/cmake/cbvh/cbvhConfig.cmake" "$libdir/cmake/cbvh/cbvhConfigVersion.cmake" \
         "$libdir/cmake/cbvh/cbvhTargets.cmake" \
         include/cbvh/datapath.h include/cbvh/traversal_units.h \
         share/cbvh/vectors/MANIFEST share/cbvh/scenes/bunny.scene share/cbvh/scenes/bunny-small.obj \
         share/doc/cbvh/README.md share/doc/cbvh/docs/datapath.md \
         lib/udev/rules.d/60-cbvh.rules; do
    [ -e "$prefix/$f" ] || { echo "not installed: $f"; bad=1; }
done
[ -x "$prefix/bin/cbvh" ] || { echo "bin/cbvh is not executable"; bad=1; }
# every vector file of the source tree's MANIFEST is installed
while read -r _ name; do
    [ -f "$prefix/share/cbvh/vectors/$name" ] || { echo "not installed: share/cbvh/vectors/$name"; bad=1; }
done <"$prefix/share/cbvh/vectors/MANIFEST"
soname=$(readelf -d "$prefix/$libdir/libcbvh.so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')
[ "$soname" = "libcbvh.so.$soversion" ] || { echo "soname '$soname', expected libcbvh.so.$soversion"; bad=1; }
for h in "$prefix"/include/cbvh/*.h; do
    printf '#include <cbvh/%s>\n' "$(basename "$h")" |
        "$cc" -std=c11 -Wall -Wextra -Werror -fsyntax-only -I"$prefix/include" -x c - ||
        { echo "installed header does not compile alone: $h"; bad=1; }
done
[ $bad -eq 0 ] || exit 1
echo "installed in $prefix: $(find "$prefix" -type f | wc -l) files, libcbvh.so soname $soname"
