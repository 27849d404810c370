/* Internal: whether the traversal units' fast paths run.  They only ever
 * give what the exact paths give (docs/traversal.md §9); a build with
 * -DCBVH_NO_FAST_PATHS turns them all off, so that
 * tests/traversal/test_fast_invisible.c can compare the two builds. */
#ifndef CBVH_FAST_PATHS_H
#define CBVH_FAST_PATHS_H

#ifdef CBVH_NO_FAST_PATHS
#define CBVH_FAST_PATHS 0
#else
#define CBVH_FAST_PATHS 1
#endif

#endif
