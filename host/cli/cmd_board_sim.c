/* cbvh board-sim: run the virtual board (firmware core, sim port) on a socket. */
#include <getopt.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cbvh_sim.h"
#include "cli/commands.h"
#include "link/link_fault.h"
#include "link/sim_addr.h"
#include "util/parse_int.h"

static volatile int stop_flag;
static void on_signal(int sig) {
    (void)sig;
    stop_flag = 1;
}

#define RX_IDLE_MS_MAX 60000
#define STR_(x) #x
#define STR(x) STR_(x)

static void usage(FILE *f) {
    fprintf(f, "usage: cbvh board-sim [--listen ADDR] [--gateware PROG] [--faults SPEC] [--rx-idle-ms N]\n"
               "                      [--host-idle-ms N] [--break-unit UNIT] [--verbose]\n"
               "  Runs the virtual board: the firmware core with the bit-exact model as its FPGA,\n"
               "  or with --gateware the board's RTL simulated by Icarus Verilog (PROG from\n"
               "  gateware/scripts/build-board-sim), driven over SPI as on the board;\n"
               "  reachable with --backend sim:ADDR.  ADDR: unix:PATH (default unix:/tmp/cbvh-board-UID.sock)\n"
               "  or tcp:HOST:PORT (PORT 1..65535); a stale unix socket left by a crashed board is replaced.\n"
               "  --faults injects faults into the replies, e.g.\n"
               "  drop=0.01,corrupt=0.01,dup=0.01,trunc=0.01,delay=0.01,disconnect=0.01,delay_ms=150,seed=1\n"
               "  (rates in [0,1] adding up to at most 1, delay_ms 0..10000, seed a non-negative integer).\n"
               "  --rx-idle-ms N: the firmware's inter-byte timeout, 1..60000 (default 20).\n"
               "  One host at a time: another one is refused at once (\"busy: another host is\n"
               "  connected\"); --host-idle-ms N lets a host go that sent nothing for N ms, so that\n"
               "  the next can connect: 0.." STR(CBVH_SIM_HOST_IDLE_MS_MAX) ", 0 never (default "
               STR(CBVH_SIM_HOST_IDLE_MS_DEFAULT) ").\n"
               "  --break-unit UNIT flips bit 0 of the unit's first output word (a test aid that\n"
               "  plays a gateware bug: checks against this board must fail).\n"
               "  Stops on SIGINT/SIGTERM and removes its socket file.\n"
               "  Exit status: 0 stopped by SIGINT/SIGTERM while idle; 1 the board failed (ADDR cannot\n"
               "  be listened on or another board listens there, the gateware simulation ended or hung,\n"
               "  or a stop abandoned a gateware transaction in progress); 2 bad options or values.\n");
}

/* Each option with a value, and what its value is, for the one-line error
 * when it is missing. */
static const struct {
    struct option opt;
    const char *value;
} valued_options[] = {
    {{"listen", required_argument, 0, 'l'}, "unix:PATH or tcp:HOST:PORT"},
    {{"gateware", required_argument, 0, 'g'}, "a program from gateware/scripts/build-board-sim"},
    {{"faults", required_argument, 0, 'f'}, "a fault spec, e.g. drop=0.01,seed=1"},
    {{"rx-idle-ms", required_argument, 0, 'r'}, "an integer in 1..60000"},
    {{"host-idle-ms", required_argument, 0, 'H'}, "an integer in 0.." STR(CBVH_SIM_HOST_IDLE_MS_MAX)},
    {{"break-unit", required_argument, 0, 'u'}, "a unit name, e.g. axis_compress"},
};
#define NVALUED (sizeof valued_options / sizeof valued_options[0])

/* An integer option's value in lo..hi: 0, or -1 after the one-line error. */
static int int_option(const char *opt, const char *val, long lo, long hi, int *out) {
    long v;
    if (cbvh_parse_long(val, lo, hi, &v)) {
        fprintf(stderr, "cbvh board-sim: %s expects an integer in %ld..%ld, got '%s'\n", opt, lo, hi, val);
        return -1;
    }
    *out = (int)v;
    return 0;
}

int cmd_board_sim(int argc, char **argv) {
    char def[128];
    snprintf(def, sizeof def, "unix:/tmp/cbvh-board-%u.sock", (unsigned)getuid());
    const char *addr = def, *faults = NULL, *gateware = NULL;
    int idle = 20, host_idle = CBVH_SIM_HOST_IDLE_MS_DEFAULT, verbose = 0, broken = 0;
    struct option lo[NVALUED + 3] = {{"help", no_argument, 0, 'h'}, {"verbose", no_argument, 0, 'v'}};
    for (size_t k = 0; k < NVALUED; k++) lo[2 + k] = valued_options[k].opt;
    int c;
    const cbvh_unit *u;
    optind = 0;
    opterr = 0;
    /* "-": an argument that is not an option comes back as 1 (and is refused);
     * ":": a missing value is ':' */
    while ((c = getopt_long(argc, argv, "-:h", lo, NULL)) != -1) {
        switch (c) {
        case 'h': usage(stdout); return 0;
        case 'v': verbose = 1; break;
        case 'l': addr = optarg; break;
        case 'g': gateware = optarg; break;
        case 'f': faults = optarg; break;
        case 'r':
            if (int_option("--rx-idle-ms", optarg, 1, RX_IDLE_MS_MAX, &idle)) return 2;
            break;
        case 'H':
            if (int_option("--host-idle-ms", optarg, 0, CBVH_SIM_HOST_IDLE_MS_MAX, &host_idle)) return 2;
            break;
        case 'u':
            if (!(u = cbvh_unit_find(optarg))) {
                fprintf(stderr, "cbvh board-sim: --break-unit: unknown unit '%s'\n", optarg);
                return 2;
            }
            broken = u->id;
            break;
        case ':':
            for (size_t k = 0; k < NVALUED; k++)
                if (valued_options[k].opt.val == optopt)
                    fprintf(stderr, "cbvh board-sim: --%s needs a value (%s)\n", valued_options[k].opt.name,
                            valued_options[k].value);
            return 2;
        default: /* an unknown option, or an argument (1) */
            fprintf(stderr, "cbvh board-sim: unknown option '%s' (cbvh board-sim --help)\n",
                    c == 1 ? optarg : argv[optind - 1]);
            return 2;
        }
    }
    if (optind < argc) { /* after "--" */
        fprintf(stderr, "cbvh board-sim: unknown option '%s' (cbvh board-sim --help)\n", argv[optind]);
        return 2;
    }
    char err[256];
    cbvh_link_fault fl;
    if (faults && cbvh_link_fault_parse(&fl, faults, err, sizeof err)) {
        fprintf(stderr, "cbvh board-sim: --faults: %s\n", err);
        return 2;
    }
    if (cbvh_sim_addr_check(addr, err, sizeof err)) {
        fprintf(stderr, "cbvh board-sim: --listen: %s\n", err);
        return 2;
    }
    cbvh_gateware *gw = NULL;
    if (gateware && cbvh_gateware_check(gateware, err, sizeof err)) { /* bad input: exit 2, as a bad address */
        fprintf(stderr, "cbvh board-sim: --gateware: %s\n", err);
        return 2;
    }
    if (gateware && !(gw = cbvh_gateware_start(gateware, broken, err, sizeof err))) {
        fprintf(stderr, "cbvh board-sim: --gateware: %s\n", err);
        return 1;
    }
    int fd = cbvh_sim_listen(addr, err, sizeof err);
    if (fd < 0) {
        fprintf(stderr, "cbvh board-sim: %s%s\n", fd == CBVH_SIM_BAD_ADDR ? "--listen: " : "", err);
        cbvh_gateware_stop(gw);
        return fd == CBVH_SIM_BAD_ADDR ? 2 : 1; /* bad input, or the socket could not be opened */
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    printf("cbvh board-sim: listening on %s\n", addr);
    fflush(stdout);
    cbvh_sim_board_opts o = {fd, &stop_flag, idle, faults ? &fl : NULL, verbose, broken, gw, host_idle};
    int rc = cbvh_sim_board_serve(&o);
    close(fd);
    cbvh_sim_unlink(addr);
    if (gw) {
        if (cbvh_gateware_error(gw)) fprintf(stderr, "cbvh board-sim: %s\n", cbvh_gateware_error(gw));
        else if (verbose)
            fprintf(stderr, "cbvh board-sim: %llu SPI transactions\n",
                    (unsigned long long)cbvh_gateware_transactions(gw));
        cbvh_gateware_stop(gw);
    }
    if (faults) {
        fprintf(stderr, "cbvh board-sim: reply frames %llu, faults injected:", (unsigned long long)fl.frames);
        for (int k = 0; k < CBVH_FAULT_KINDS; k++)
            fprintf(stderr, " %s %llu", cbvh_fault_names[k], (unsigned long long)fl.injected[k]);
        fprintf(stderr, "\n");
    }
    return rc ? 1 : 0;
}
