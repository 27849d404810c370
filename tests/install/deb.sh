#!/bin/sh
# The Debian package of the install (cpack -G DEB, README "Install"): built
# from this build tree, then its contents (dpkg-deb -c) and fields checked.
# Skips (77) without dpkg-deb.
#   deb.sh BUILD WORK LIBDIR SOVERSION VERSION
set -eu
build=$1 work=$2 libdir=$3 soversion=$4 version=$5
command -v dpkg-deb >/dev/null 2>&1 || { echo "SKIP: dpkg-deb not installed"; exit 77; }
rm -rf "$work"
cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work" >"$work.log" 2>&1 || { cat "$work.log"; exit 1; }
deb=$(ls "$work"/cbvh_"$version"_*.deb)
dpkg-deb -c "$deb" >"$work/contents.txt"
dpkg-deb -f "$deb" Package Version Depends
bad=0
for f in bin/cbvh "$libdir/libcbvh.so.$soversion" "$libdir/libcbvh.a" "$libdir/pkgconfig/cbvh.pc" \
         "$libdir/cmake/cbvh/cbvhConfig.cmake" include/cbvh/datapath.h share/cbvh/vectors/MANIFEST \
         share/cbvh/scenes/bunny.scene share/doc/cbvh/README.md lib/udev/rules.d/60-cbvh.rules; do
    grep -q " \./usr/$f\( ->\|$\)" "$work/contents.txt" || { echo "not in the package: /usr/$f"; bad=1; }
done
if command -v dpkg-shlibdeps >/dev/null 2>&1; then
    for dep in libusb-1.0-0 libhidapi-libusb0 libssl libcjson libpng libassimp; do
        dpkg-deb -f "$deb" Depends | grep -q "$dep" || { echo "Depends lacks $dep"; bad=1; }
    done
fi
[ $bad -eq 0 ] || exit 1
echo "$deb: $(wc -l <"$work/contents.txt") entries"
