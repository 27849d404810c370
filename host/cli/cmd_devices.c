/* cbvh devices: boards found by each backend, and why none. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "link/board_link.h"
#include "cbvh_sim.h"
#include "cli/commands.h"

static void usage(void) {
    printf("usage: cbvh devices [--sim ADDR]\n"
           "  Lists boards per backend, in the order --backend auto tries them: usb (libusb bulk),\n"
           "  hid (hidapi), sim (a virtual board at ADDR, also from CBVH_SIM_ADDR, which auto uses)\n"
           "  and the always-present model.  VID:PID from CBVH_USB_VID/PID.\n"
           "  Exit 2 on a bad ADDR or a bad CBVH_USB_VID/PID, CBVH_LINK_TIMEOUT_MS/RETRIES.\n");
}

int cmd_devices(int argc, char **argv) {
    static const struct option lo[] = {{"help", no_argument, 0, 'h'}, {"sim", required_argument, 0, 's'}, {0, 0, 0, 0}};
    const char *sim = getenv("CBVH_SIM_ADDR"), *sim_from = "CBVH_SIM_ADDR";
    int c;
    optind = 0;
    opterr = 0;
    /* "-": an argument that is not an option comes back as 1 (and is refused) */
    while ((c = getopt_long(argc, argv, "-:h", lo, NULL)) != -1) {
        if (c == 'h') {
            usage();
            return 0;
        } else if (c == 's') {
            sim = optarg;
            sim_from = "--sim";
        } else {
            fprintf(stderr, "cbvh devices: unknown or incomplete option '%s'\n", c == 1 ? optarg : argv[optind - 1]);
            return 2;
        }
    }
    if (optind < argc) { /* after "--" */
        fprintf(stderr, "cbvh devices: unknown or incomplete option '%s'\n", argv[optind]);
        return 2;
    }
    /* Bad input is one line and exit 2, before any probing: a listing under a
     * wrong VID:PID or address would only say "none". */
    char err[300];
    uint16_t vid, pid;
    if (cbvh_usb_identity(&vid, &pid, err, sizeof err) || cbvh_link_env_options(NULL, err, sizeof err)) {
        fprintf(stderr, "cbvh devices: %s\n", err);
        return 2;
    }
    /* an empty CBVH_SIM_ADDR means unset; an empty --sim is a bad address */
    if (sim && (*sim || strcmp(sim_from, "--sim") == 0) && cbvh_sim_addr_check(sim, err, sizeof err)) {
        fprintf(stderr, "cbvh devices: %s: %s\n", sim_from, err);
        return 2;
    }
    int boards = cbvh_usb_describe(stdout);
    boards += cbvh_hid_describe(stdout);
    if (sim && *sim) {
        cbvh_backend b;
        char spec[300];
        snprintf(spec, sizeof spec, "sim:%s", sim);
        if (cbvh_backend_open(spec, &b, NULL, err, sizeof err) == 0) {
            cbvh_link *l = cbvh_backend_link(&b);
            printf("sim:   %s, units 0x%08x, max payload %u\n", b.label, l ? (unsigned)l->ident.units : 0u,
                   l ? l->ident.max_payload : 0u);
            cbvh_backend_close(&b);
            boards++;
        } else {
            printf("sim:   none (%s)\n", err);
        }
    } else {
        printf("sim:   not probed (give --sim ADDR or CBVH_SIM_ADDR; start one with `cbvh board-sim`)\n");
    }
    printf("model: libcbvh datapath v%d (always available; --backend auto falls back to it)\n", CBVH_DATAPATH_VERSION);
    return 0;
}
