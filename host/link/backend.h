/* One backend interface for every way of running a unit (OpenOCD CMSIS-DAP
 * style): a table of functions per backend, one backend per file, and one
 * table of the backends (cbvh_backends) that `cbvh devices` lists.
 *   backend_model.c   in-process bit-exact model
 *   transport_usb.c   libusb bulk (board)
 *   transport_hid.c   hidapi HID (board)
 *   transport_socket.c  the virtual board (`cbvh board-sim`) on a socket
 * `auto` probes in the order `cbvh devices` lists: usb, hid, then sim when
 * CBVH_SIM_ADDR is set, and falls back to the model with one line (but not
 * over bad CBVH_USB_* / CBVH_LINK_* / CBVH_SIM_ADDR settings: those are an
 * error). */
#ifndef CBVH_HOST_BACKEND_H
#define CBVH_HOST_BACKEND_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "cbvh/unit_table.h"

typedef struct cbvh_backend cbvh_backend;

typedef struct {
    const char *name;
    /* Checks the text after "name:" (NULL when there is none) without
     * opening anything: 0, or CBVH_BACKEND_BAD_INPUT with err set.  NULL:
     * any argument is accepted. */
    int (*check_arg)(const char *arg, char *err, size_t errlen);
    /* Opens the backend; arg is the text after "name:" (or NULL).
     * Returns 0 on success, CBVH_BACKEND_NONE when no device is present,
     * CBVH_BACKEND_BAD_INPUT when arg or a setting is wrong (auto then fails
     * instead of falling back), CBVH_BACKEND_ERROR on any other failure (err
     * says why, one line). */
    int (*open)(cbvh_backend *b, const char *arg, char *err, size_t errlen);
    void (*close)(cbvh_backend *b);
    /* Runs count vectors of unit: in holds count*n_in words, out receives
     * count*n_out words.  0 on success, CBVH_BACKEND_ERROR otherwise. */
    int (*run)(cbvh_backend *b, const cbvh_unit *unit, const cbvh_unit_config *cfg, const uint32_t *in,
               uint32_t *out, size_t count, char *err, size_t errlen);
    /* `cbvh devices`: writes one line (cbvh_backend_list_line) per device
     * the backend finds, or one saying why it finds none, and returns how
     * many it found.  arg as for open: the text after "name:" (the sim
     * backend's address), NULL when not given. */
    int (*list)(const char *arg, FILE *out);
} cbvh_backend_ops;

enum { CBVH_BACKEND_OK = 0, CBVH_BACKEND_NONE = 1, CBVH_BACKEND_ERROR = 2, CBVH_BACKEND_BAD_INPUT = 3 };

struct cbvh_backend {
    const cbvh_backend_ops *ops;
    void *state;
    char label[160]; /* human-readable: "model", "usb 1209:c0b1 serial ..." */
};

extern const cbvh_backend_ops cbvh_backend_model;
extern const cbvh_backend_ops cbvh_backend_usb;
extern const cbvh_backend_ops cbvh_backend_hid;
extern const cbvh_backend_ops cbvh_backend_sim; /* transport_socket.c: "sim:ADDR", the virtual board */

/* Every backend, in the order `--backend auto` probes them and `cbvh devices`
 * lists them: usb, hid, sim, model; NULL-terminated. */
extern const cbvh_backend_ops *const cbvh_backends[];

/* One line of a device listing: "name:" in a 7-column field, then the text. */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
void cbvh_backend_list_line(FILE *out, const cbvh_backend_ops *ops, const char *fmt, ...);

/* Is spec well formed (a known name, an argument its backend takes)?  Opens
 * nothing, so a command can reject it before it prints anything.  0, or -1
 * with err set as cbvh_backend_open would set it. */
int cbvh_backend_spec_check(const char *spec, char *err, size_t errlen);

/* Opens by spec: "auto", "model", "usb[:SERIAL]", "hid[:SERIAL]", "sim:ADDR"
 * ("model:ARG" is refused).  For auto, writes one line to log when no board
 * is found.  0 on success. */
int cbvh_backend_open(const char *spec, cbvh_backend *b, FILE *log, char *err, size_t errlen);
void cbvh_backend_close(cbvh_backend *b);

/* USB identity of the board (pid.codes test VID), overridable with the
 * environment variables CBVH_USB_VID / CBVH_USB_PID (1 to 4 hex digits,
 * optional 0x; unset or empty: the default).  0, or -1 with err naming the
 * variable and the accepted form (*vid, *pid then hold the defaults). */
#define CBVH_USB_VID_DEFAULT 0x1209
#define CBVH_USB_PID_DEFAULT 0xC0B1
int cbvh_usb_identity(uint16_t *vid, uint16_t *pid, char *err, size_t errlen);

#endif
