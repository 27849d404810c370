/* Where cbvh finds its data: the golden vectors (vectors/), the bundled
 * scenes (scenes/) and the RTL cost table (gateware/cost/), the defaults of
 * `cbvh run`, `study`, `trace` and `sweep`. */
#ifndef CBVH_CLI_DATA_DIR_H
#define CBVH_CLI_DATA_DIR_H

/* An installed cbvh (PREFIX/bin/cbvh): PREFIX/share/cbvh, found from the
 * executable's own path, so a tree installed with --prefix DIR, or moved,
 * finds its own data.  Any other cbvh (the build tree's): the source tree it
 * was built from.  Never NULL; the same string on every call. */
const char *cbvh_data_dir(void);

/* The RTL cost table's directory (docs/timing_model.md), the default of
 * --cost-table: DATA/gateware/cost, DATA as above. */
const char *cbvh_cost_dir(void);

#endif
