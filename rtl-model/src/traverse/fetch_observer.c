/* The traversals' memory-read observer (cbvh/traverse.h): one global, read
 * by trav_observe (traverse_common.h) on every counted read. */
#include "cbvh/traverse.h"

const cbvh_fetch_observer *cbvh_trav_observer = NULL;

void cbvh_trav_set_observer(const cbvh_fetch_observer *o) { cbvh_trav_observer = o; }
