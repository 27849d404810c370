/* cbvh devices: boards found by each backend, and why none. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "link/backend.h"
#include "link/protocol.h"
#include "link/sim_addr.h"
#include "cli/commands.h"

int cmd_devices(int argc, char **argv) {
    const char *sim = getenv("CBVH_SIM_ADDR"), *sim_from = "CBVH_SIM_ADDR";
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            printf("usage: cbvh devices [--sim ADDR]\n"
                   "  Lists boards per backend, in the order --backend auto tries them: usb (libusb bulk),\n"
                   "  hid (hidapi), sim (a virtual board at ADDR, also from CBVH_SIM_ADDR, which auto uses)\n"
                   "  and the always-present model.  VID:PID from CBVH_USB_VID/PID.\n"
                   "  Exit 2 on a bad ADDR or a bad CBVH_USB_VID/PID, CBVH_LINK_TIMEOUT_MS/RETRIES.\n");
            return 0;
        } else if (strcmp(argv[i], "--sim") == 0 && i + 1 < argc) {
            sim = argv[++i];
            sim_from = "--sim";
        } else {
            fprintf(stderr, "cbvh devices: unknown or incomplete option '%s'\n", argv[i]);
            return 2;
        }
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
