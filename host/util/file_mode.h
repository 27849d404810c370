/* mkstemp creates files with mode 0600; an output file that replaces its
 * temporary by rename should get the usual 0666 & ~umask instead. */
#ifndef CBVH_HOST_FILE_MODE_H
#define CBVH_HOST_FILE_MODE_H

#include <sys/stat.h>

static inline int cbvh_fd_default_mode(int fd) {
    mode_t mask = umask(0);
    umask(mask);
    return fchmod(fd, 0666 & ~mask);
}

#endif
