/* Addresses of the virtual board (see sim_addr.h): parsing, listening (with
 * a stale unix socket file replaced), connecting. */
#define _GNU_SOURCE
#include "link/sim_addr.h"

#include <errno.h>
#include <netdb.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

typedef struct {
    int unix_sock;
    char path[sizeof(((struct sockaddr_un *)0)->sun_path)];
    char host[128], port[16];
} sim_addr;

static int parse_addr(const char *addr, sim_addr *a, char *err, size_t errlen) {
    memset(a, 0, sizeof *a);
    const char *path = NULL;
    if (strncmp(addr, "unix:", 5) == 0) path = addr + 5;
    else if (strncmp(addr, "tcp:", 4) != 0 && strchr(addr, '/')) path = addr;
    if (path) {
        if (!*path || strlen(path) >= sizeof a->path) {
            snprintf(err, errlen, "bad unix socket path '%s' (empty or longer than %zu bytes)", path,
                     sizeof a->path - 1);
            return -1;
        }
        a->unix_sock = 1;
        strcpy(a->path, path);
        return 0;
    }
    const char *hp = strncmp(addr, "tcp:", 4) == 0 ? addr + 4 : addr;
    const char *colon = strrchr(hp, ':');
    if (!colon || colon == hp || !colon[1] || (size_t)(colon - hp) >= sizeof a->host || strlen(colon + 1) >= sizeof a->port) {
        snprintf(err, errlen, "bad board address '%s' (expected unix:PATH, tcp:HOST:PORT or a PATH with '/')", addr);
        return -1;
    }
    /* A decimal port in range: getaddrinfo would take "99999" modulo 65536,
     * "0" as "any free port" and "http" as a service name. */
    const char *port = colon + 1;
    char *end;
    errno = 0;
    long pn = *port >= '0' && *port <= '9' ? strtol(port, &end, 10) : -1;
    if (pn < 1 || pn > 65535 || *end || errno) {
        snprintf(err, errlen, "bad port '%s' in board address '%s' (expected a number in 1..65535)", port, addr);
        return -1;
    }
    memcpy(a->host, hp, (size_t)(colon - hp));
    strcpy(a->port, port);
    return 0;
}

int cbvh_sim_addr_check(const char *addr, char *err, size_t errlen) {
    sim_addr a;
    return parse_addr(addr, &a, err, errlen);
}

/* A unix socket path that bind() finds taken: a board left behind by a crash
 * (SIGKILL leaves the file; nobody accepts on it) or a live one.  Returns 1
 * when the stale file was removed and bind may be tried again, else 0 with
 * err saying why the path cannot be used. */
static int clear_stale_socket(const struct sockaddr_un *sa, char *err, size_t errlen) {
    struct stat st;
    if (lstat(sa->sun_path, &st) != 0 || !S_ISSOCK(st.st_mode)) {
        snprintf(err, errlen, "listen on %s: the path exists and is not a socket", sa->sun_path);
        return 0;
    }
    int probe = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0); /* a full backlog must not block */
    if (probe < 0) {
        snprintf(err, errlen, "socket: %s", strerror(errno));
        return 0;
    }
    int live = connect(probe, (const struct sockaddr *)sa, sizeof *sa) == 0;
    int why = errno;
    close(probe);
    if (live) {
        snprintf(err, errlen, "another board is already listening on %s", sa->sun_path);
        return 0;
    }
    if (why != ECONNREFUSED) { /* e.g. a full backlog: someone may be there */
        snprintf(err, errlen, "listen on %s: address in use and not answering (%s)", sa->sun_path, strerror(why));
        return 0;
    }
    if (unlink(sa->sun_path) != 0) {
        snprintf(err, errlen, "listen on %s: cannot remove the stale socket: %s", sa->sun_path, strerror(errno));
        return 0;
    }
    return 1;
}

static int open_addr(const char *addr, int listening, char *err, size_t errlen) {
    sim_addr a;
    if (parse_addr(addr, &a, err, errlen)) return CBVH_SIM_BAD_ADDR;
    if (a.unix_sock) {
        int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        if (fd < 0) {
            snprintf(err, errlen, "socket: %s", strerror(errno));
            return -1;
        }
        struct sockaddr_un sa = {0};
        sa.sun_family = AF_UNIX;
        strcpy(sa.sun_path, a.path);
        int rc = listening ? bind(fd, (struct sockaddr *)&sa, sizeof sa) : connect(fd, (struct sockaddr *)&sa, sizeof sa);
        if (rc != 0 && listening && errno == EADDRINUSE) {
            if (!clear_stale_socket(&sa, err, errlen)) {
                close(fd);
                return -1;
            }
            rc = bind(fd, (struct sockaddr *)&sa, sizeof sa);
        }
        if (rc == 0 && listening) rc = listen(fd, 4);
        if (rc != 0) {
            snprintf(err, errlen, "%s %s: %s", listening ? "listen on" : "connect to", a.path, strerror(errno));
            close(fd);
            return -1;
        }
        return fd;
    }
    struct addrinfo hints = {0}, *res = NULL;
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_NUMERICSERV | (listening ? AI_PASSIVE : 0);
    int g = getaddrinfo(a.host, a.port, &hints, &res);
    if (g != 0) {
        snprintf(err, errlen, "address %s:%s: %s", a.host, a.port, gai_strerror(g));
        /* a host name that does not exist is bad input; a DNS failure is not */
        return g == EAI_NONAME ? CBVH_SIM_BAD_ADDR : -1;
    }
    int fd = -1;
    for (struct addrinfo *r = res; r; r = r->ai_next) {
        fd = socket(r->ai_family, r->ai_socktype | SOCK_CLOEXEC, r->ai_protocol);
        if (fd < 0) continue;
        int one = 1;
        if (listening) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        int rc = listening ? bind(fd, r->ai_addr, r->ai_addrlen) : connect(fd, r->ai_addr, r->ai_addrlen);
        if (rc == 0 && listening) rc = listen(fd, 4);
        if (rc == 0) break;
        snprintf(err, errlen, "%s %s:%s: %s", listening ? "listen on" : "connect to", a.host, a.port, strerror(errno));
        close(fd);
        fd = -1;
    }
    freeaddrinfo(res);
    return fd;
}

int cbvh_sim_listen(const char *addr, char *err, size_t errlen) { return open_addr(addr, 1, err, errlen); }
int cbvh_sim_connect(const char *addr, char *err, size_t errlen) { return open_addr(addr, 0, err, errlen); }

void cbvh_sim_unlink(const char *addr) {
    sim_addr a;
    char err[8];
    if (parse_addr(addr, &a, err, sizeof err) == 0 && a.unix_sock) unlink(a.path);
}
