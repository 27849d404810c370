/* Where cbvh finds its data: the golden vectors (vectors/) and the bundled
 * scenes (scenes/), the defaults of `cbvh run` and `cbvh study`. */
#ifndef CBVH_CLI_DATA_DIR_H
#define CBVH_CLI_DATA_DIR_H

/* An installed cbvh (PREFIX/bin/cbvh): PREFIX/share/cbvh, found from the
 * executable's own path, so a tree installed with --prefix DIR, or moved,
 * finds its own data.  Any other cbvh (the build tree's): the source tree it
 * was built from.  Never NULL; the same string on every call. */
const char *cbvh_data_dir(void);

#endif
