/* Out of memory in the library (cbvh/oom.h): an allocation that must fail
 * (16 GiB asked for under a 2 GiB address-space cap) reaches the handler the
 * application set, with a name for what was being allocated; without one,
 * or when the handler returns, one line on stderr and SIGABRT. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "cbvh/bvh.h"
#include "cbvh/oom.h"

/* ASan aborts on a failed allocation unless told to return NULL like malloc
 * (sanitize preset); a build without ASan never calls this. */
const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "allocator_may_return_null=1"; }

#define HUGE_BYTES (((size_t)UINT32_MAX + 1) * sizeof(uint32_t)) /* the post-order stack below */

static struct rlimit saved;

/* Cap the address space so that HUGE_BYTES cannot be had, whatever the
 * machine's memory and overcommit policy.  0, or -1 with why on stderr. */
static int cap_memory(void) {
    if (getrlimit(RLIMIT_AS, &saved)) {
        perror("test_oom: getrlimit");
        return -1;
    }
    struct rlimit cap = saved;
    /* ASan's reserved shadow already exceeds the cap: then only new
     * mappings fail, which is all this needs */
    cap.rlim_cur = (rlim_t)2 << 30;
    if (saved.rlim_max != RLIM_INFINITY && saved.rlim_max < cap.rlim_cur) cap.rlim_cur = saved.rlim_max;
    if (setrlimit(RLIMIT_AS, &cap)) {
        perror("test_oom: setrlimit");
        return -1;
    }
    void *probe = malloc(HUGE_BYTES);
    if (probe) {
        free(probe);
        fprintf(stderr, "test_oom: a %zu-byte allocation succeeded under the cap: cannot test\n", HUGE_BYTES);
        return -1;
    }
    return 0;
}

static void uncap_memory(void) { setrlimit(RLIMIT_AS, &saved); }

/* cbvh_bvh_postorder allocates (nnodes + 1) entries before reading a node:
 * with nnodes = 2^32 - 1 that is HUGE_BYTES, and it has no error return. */
static void exhaust(void) {
    cbvh_bvh b;
    memset(&b, 0, sizeof b);
    b.nnodes = UINT32_MAX;
    uint32_t order[1];
    cbvh_bvh_postorder(&b, order);
}

static jmp_buf back;
static char what_seen[128];

static void catching_handler(const char *what) {
    snprintf(what_seen, sizeof what_seen, "%s", what ? what : "(null)");
    longjmp(back, 1);
}

/* A handler that (wrongly) returns: cbvh_out_of_memory must not. */
static void returning_handler(const char *what) { fprintf(stderr, "handler returned (%s)\n", what); }

/* The application's handler: called once, with a non-empty name. */
static int test_handler_called(void) {
    if (cap_memory()) return 1;
    cbvh_oom_handler old = cbvh_set_oom_handler(catching_handler);
    int jumped = setjmp(back);
    if (!jumped) exhaust();
    uncap_memory();
    cbvh_set_oom_handler(old);
    if (!jumped) {
        fprintf(stderr, "FAIL handler: the allocation failure did not reach the handler\n");
        return 1;
    }
    if (strcmp(what_seen, "post-order stack") != 0) {
        fprintf(stderr, "FAIL handler: called with '%s', expected 'post-order stack'\n", what_seen);
        return 1;
    }
    if (old != NULL) {
        fprintf(stderr, "FAIL handler: a handler was set before the test set one\n");
        return 1;
    }
    printf("ok handler: called with '%s'\n", what_seen);
    return 0;
}

/* In a child: stderr into a pipe, handler h, exhaust.  Expects SIGABRT and
 * stderr exactly `want`. */
static int test_aborts(const char *name, cbvh_oom_handler h, const char *want) {
    int fds[2];
    if (pipe(fds)) {
        perror("test_oom: pipe");
        return 1;
    }
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0) {
        perror("test_oom: fork");
        return 1;
    }
    if (pid == 0) {
        close(fds[0]);
        dup2(fds[1], 2);
        signal(SIGABRT, SIG_DFL);
        if (cap_memory()) _exit(3);
        cbvh_set_oom_handler(h);
        exhaust();
        _exit(4); /* not reached unless cbvh_out_of_memory returned */
    }
    close(fds[1]);
    char buf[512];
    size_t n = 0;
    ssize_t k;
    while (n < sizeof buf - 1 && (k = read(fds[0], buf + n, sizeof buf - 1 - n)) > 0) n += (size_t)k;
    buf[n] = 0;
    close(fds[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {
    }
    if (!WIFSIGNALED(status) || WTERMSIG(status) != SIGABRT) {
        fprintf(stderr, "FAIL %s: child ended with status 0x%x, not SIGABRT; stderr:\n%s", name, status, buf);
        return 1;
    }
    if (strcmp(buf, want) != 0) {
        fprintf(stderr, "FAIL %s: stderr was '%s', expected '%s'\n", name, buf, want);
        return 1;
    }
    printf("ok %s: SIGABRT after the expected stderr\n", name);
    return 0;
}

int main(void) {
    int bad = test_handler_called();
    bad |= test_aborts("default", NULL, "cbvh: out of memory (post-order stack)\n");
    bad |= test_aborts("handler returns", returning_handler,
                       "handler returned (post-order stack)\ncbvh: out of memory (post-order stack)\n");
    return bad;
}
