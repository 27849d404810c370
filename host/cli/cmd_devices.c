/* cbvh devices: boards found by each backend, and why none. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "link/backend.h"
#include "link/protocol.h"
#include "link/sim_addr.h"
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
    /* Every backend in the table, in its order; --sim is the sim backend's argument. */
    for (const cbvh_backend_ops *const *o = cbvh_backends; *o; o++)
        (*o)->list(*o == &cbvh_backend_sim && sim && *sim ? sim : NULL, stdout);
    return 0;
}
