#!/bin/sh
# Builds tests/install/consumer/consumer.c against an installed libcbvh as an
# outside project would, then runs it on the installed golden vectors.
#   consumer.sh cmake|pkgconfig shared|static PREFIX WORK SRC VERSION CC CFLAGS LDFLAGS
# cmake:     find_package(cbvh VERSION), cbvh::cbvh or cbvh::cbvh_static;
# pkgconfig: cc with `pkg-config cbvh` (shared), or the archive and
#            `pkg-config --static --libs` (static).
# CC, CFLAGS, LDFLAGS: the build's (a sanitizer build's library needs them).
# Also checks how the program was linked (NEEDED libcbvh.so.<SOVERSION> or not).
set -eu
mode=$1 link=$2 prefix=$3 work=$4 src=$5 version=$6 cc=$7 cflags=$8 ldflags=$9
rm -rf "$work"
mkdir -p "$work"
case $mode in
cmake)
    cmake -S "$src" -B "$work" -DCMAKE_PREFIX_PATH="$prefix" -DCBVH_LINK="$link" -DCBVH_VERSION="$version" \
        -DCMAKE_C_COMPILER="$cc" -DCMAKE_C_FLAGS="$cflags" -DCMAKE_EXE_LINKER_FLAGS="$ldflags" >"$work/configure.log" ||
        { cat "$work/configure.log"; exit 1; }
    cmake --build "$work" >"$work/build.log" || { cat "$work/build.log"; exit 1; }
    vectors=$(cat "$work/vectors_dir.txt")
    ;;
pkgconfig)
    export PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name cbvh.pc | head -n 1)")"
    got=$(pkg-config --modversion cbvh)
    [ "$got" = "$version" ] || { echo "pkg-config --modversion cbvh: $got, expected $version"; exit 1; }
    libdir=$(pkg-config --variable=libdir cbvh)
    vectors=$(pkg-config --variable=vectorsdir cbvh)
    # shellcheck disable=SC2086,SC2046
    if [ "$link" = static ]; then
        set -x
        $cc $cflags -std=c11 -Wall -Wextra -Werror $(pkg-config --cflags cbvh) "$src/consumer.c" \
            "$libdir/libcbvh.a" $(pkg-config --static --libs-only-l cbvh | sed 's/-lcbvh\b//') \
            $ldflags -o "$work/consumer"
    else
        set -x
        $cc $cflags -std=c11 -Wall -Wextra -Werror $(pkg-config --cflags cbvh) "$src/consumer.c" \
            $(pkg-config --libs cbvh) -Wl,-rpath,"$libdir" $ldflags -o "$work/consumer"
    fi
    set +x
    ;;
*) echo "consumer.sh: mode cmake or pkgconfig, not '$mode'"; exit 2 ;;
esac

needed=$(readelf -d "$work/consumer" | sed -n 's/.*(NEEDED).*\[\(libcbvh[^]]*\)\].*/\1/p')
if [ "$link" = static ]; then
    [ -z "$needed" ] || { echo "static link, but the program needs $needed"; exit 1; }
else
    case $needed in
    libcbvh.so.*) ;;
    *) echo "shared link, but the program does not need libcbvh.so.* (NEEDED: '$needed')"; exit 1 ;;
    esac
fi
echo "consumer ($mode, $link${needed:+, needs $needed}) on $vectors"
"$work/consumer" "$vectors"
