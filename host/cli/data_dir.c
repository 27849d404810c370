#include "cli/data_dir.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* CBVH_DATA_FROM_BINDIR: the installed data directory relative to the
 * installed executable's ("../share/cbvh"); CBVH_SOURCE_DIR: the source tree
 * (host/CMakeLists.txt). */
const char *cbvh_data_dir(void) {
    static char resolved[PATH_MAX];
    static const char *dir;
    if (dir) return dir;
    dir = CBVH_SOURCE_DIR;
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) return dir;
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    size_t rel = strlen(CBVH_DATA_FROM_BINDIR);
    if (!slash || (size_t)(slash + 1 - exe) + rel >= sizeof exe) return dir;
    memcpy(slash + 1, CBVH_DATA_FROM_BINDIR, rel + 1);
    struct stat st;
    if (realpath(exe, resolved) && stat(resolved, &st) == 0 && S_ISDIR(st.st_mode)) dir = resolved;
    return dir;
}

const char *cbvh_cost_dir(void) {
    static char dir[PATH_MAX + 16];
    if (!dir[0]) snprintf(dir, sizeof dir, "%s/gateware/cost", cbvh_data_dir());
    return dir;
}
