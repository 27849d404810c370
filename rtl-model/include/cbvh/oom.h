/* Out of memory where the library has no error path to return through (the
 * builders' and compressors' scratch buffers, void helpers): one place that
 * reports it, instead of a silent abort().  Functions that already return an
 * error on a failed allocation keep doing so. */
#ifndef CBVH_OOM_H
#define CBVH_OOM_H

/* Called with a short noun naming what could not be allocated ("SAH build
 * buffers").  Must not return (exit, _exit, longjmp); if it does,
 * cbvh_out_of_memory aborts anyway. */
typedef void (*cbvh_oom_handler)(const char *what);

/* Install the handler for the whole process (NULL: the default, which prints
 * "cbvh: out of memory (WHAT)" to stderr and aborts).  Returns the previous
 * one.  Not thread-safe: set it once, at start-up. */
cbvh_oom_handler cbvh_set_oom_handler(cbvh_oom_handler h);

/* Report an allocation failure: the handler, else the default. */
_Noreturn void cbvh_out_of_memory(const char *what);

/* scripts/lint: cppcheck 2.10 does not take _Noreturn from a declaration and
 * would see a null dereference after every check; to it the call is what it
 * stands for. */
#if defined(__CPPCHECK__)
#include <stdlib.h>
#define cbvh_out_of_memory(what) abort()
#endif

#endif
