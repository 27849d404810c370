/* The board as a kernel USB device, for the host's real libusb and
 * hidapi-libusb code paths (umockdev, docs/board.md "The host's libraries").
 *
 *   board_umockdev [--remove-after-urbs N] [--no-permission] -- COMMAND [ARGS...]
 *
 * Makes a umockdev testbed with the board's sysfs entries (bus 1, device 2,
 * its device and configuration descriptors; interface 1 with usbhid bound,
 * its hid device and hidraw0) and two nodes: usbdevfs /dev/bus/usb/001/002,
 * whose ioctl handler serves the URBs, and /dev/hidraw0, whose read, write
 * and ioctl handlers play the kernel's hidraw + usbhid.  Behind both, the board's own
 * USB device stack (firmware/ports/rp2040_ice40/usbd.c, usb_desc.c,
 * usb_link.c) and the firmware core on the model's register map answer
 * them, packet by packet.  COMMAND runs under umockdev's preload library
 * (umockdev-wrapper), so libusb, hidapi-libusb and hidapi-hidraw in it find
 * and open this device through the ordinary sysfs/udev, usbdevfs and hidraw
 * paths.  The exit status is COMMAND's.
 *
 * --remove-after-urbs N  unplugs the device after N data URBs (a board
 *                        pulled out mid-run): every later ioctl fails with
 *                        ENODEV, and the device is gone from sysfs.
 * --no-permission        the node is root's, mode 0600, and COMMAND runs as
 *                        user nobody (as without the udev rule).
 * Bad options: one line on stderr, exit 2. */
#include <errno.h>
#include <glib.h>
#include <glib/gstdio.h>
#include <linux/hidraw.h>
#include <linux/usbdevice_fs.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>
#include <umockdev.h>

#include "cbvh_sim.h"
#include "usb_link.h"
#include "usbd.h"

#define DEVNODE "/dev/bus/usb/001/002"
#define SYSPATH "/sys/devices/pci0000:00/usb1/1-1"
#define HIDRAW_NODE "/dev/hidraw0"
#define MAX_PKTS 512

static const char *me = "board_umockdev";

/* ---- the device: stack + link + firmware core, with a packet-level port ---- */
typedef struct {
    uint8_t data[64];
    uint16_t len;
} packet;
static struct {
    packet q[MAX_PKTS];
    unsigned head, tail;
} inq[16]; /* IN packets the device armed, waiting for an IN URB */
static struct {
    int armed;
    uint8_t *dst;
} outs[16];
typedef struct {
    uint8_t ep;
    uint16_t len;
} completion;
static completion comp[64];
static unsigned ncomp;
static int ep0_stalled;

static usbd_dev dev;
static usb_link lnk;
static cbvh_fw fw;
static cbvh_regmap_model regs;
static cbvh_fw_hal hal;
static gint64 last_rx_us;

static void complete_later(uint8_t ep, uint16_t len) {
    if (ncomp < G_N_ELEMENTS(comp)) comp[ncomp++] = (completion){ep, len};
}
static void pump(void) {
    while (ncomp) {
        uint8_t ep = comp[0].ep;
        uint16_t len = comp[0].len;
        memmove(comp, comp + 1, --ncomp * sizeof comp[0]);
        usbd_xfer_done(&dev, ep, len);
    }
}

static void p_set_address(void *c, uint8_t a) { (void)c, (void)a; }
static void p_ep_open(void *c, uint8_t ep, uint8_t type, uint16_t mps) { (void)c, (void)ep, (void)type, (void)mps; }
static void p_close_all(void *c) {
    (void)c;
    for (int n = 1; n < 16; n++) {
        outs[n].armed = 0;
        inq[n].head = inq[n].tail = 0;
    }
}
static void p_xfer(void *c, uint8_t ep, uint8_t *data, uint16_t len) {
    (void)c;
    unsigned n = ep & 0xFu;
    if (ep & 0x80u) { /* the host controller takes the packet now; an IN URB collects it */
        if (inq[n].tail - inq[n].head >= MAX_PKTS) return;
        packet *p = &inq[n].q[inq[n].tail++ % MAX_PKTS];
        if (len) memcpy(p->data, data, len);
        p->len = len;
        complete_later(ep, len);
    } else if (n == 0) {
        complete_later(0x00, 0); /* the host's status packet */
    } else {
        outs[n].armed = 1;
        outs[n].dst = data;
    }
}
static void p_abort(void *c, uint8_t ep) { (void)c, (void)ep; }
static void p_stall(void *c, uint8_t ep, int on) {
    (void)c;
    if ((ep & 0xFu) == 0) ep0_stalled = on;
}
static const usbd_port port = {0, p_set_address, p_ep_open, p_close_all, p_xfer, p_abort, p_stall};

static void poll_port(void *c) {
    (void)c;
    pump();
}
static uint32_t now_us(void *c) { return (void)c, (uint32_t)g_get_monotonic_time(); }
static uint32_t rd(void *c, uint32_t a) { return (void)c, cbvh_regmap_model_read(&regs, a); }
static void wr(void *c, uint32_t a, uint32_t v) { (void)c, cbvh_regmap_model_write(&regs, a, v); }

/* The firmware's main loop, run whenever host bytes arrived. */
static void device_step(void) {
    uint8_t buf[64];
    size_t n;
    while ((n = usb_link_take(&lnk, buf, sizeof buf)) > 0) {
        cbvh_fw_rx(&fw, buf, n);
        last_rx_us = g_get_monotonic_time();
    }
    pump();
}

/* One control transfer: the data stage's bytes (IN), or -EPIPE for a STALL. */
static int control(const uint8_t setup[8], uint8_t *in, int cap) {
    ep0_stalled = 0;
    inq[0].head = inq[0].tail = 0;
    usbd_setup(&dev, setup);
    pump();
    if (ep0_stalled) return -EPIPE;
    int got = 0;
    if (!(setup[0] & 0x80u)) return 0;
    while (inq[0].head != inq[0].tail) {
        packet *p = &inq[0].q[inq[0].head++ % MAX_PKTS];
        int k = p->len < cap - got ? p->len : cap - got;
        memcpy(in + got, p->data, (size_t)k);
        got += k;
    }
    return got;
}

static void device_init(void) {
    usb_link_init(&lnk, &dev, poll_port, now_us, 0, 250000);
    usbd_init(&dev, &port, &lnk.cls);
    cbvh_regmap_model_init(&regs);
    hal = (cbvh_fw_hal){&lnk, rd, wr, usb_link_send, "cbvh-rp2040"};
    cbvh_fw_init(&fw, &hal);
    /* what the kernel does on plug-in: reset, address, configuration 1 */
    static const uint8_t set_address[8] = {0x00, 5, 2, 0, 0, 0, 0, 0}, set_config[8] = {0x00, 9, 1, 0, 0, 0, 0, 0};
    uint8_t none[1];
    usbd_bus_reset(&dev);
    control(set_address, none, 0);
    control(set_config, none, 0);
}

/* ---- usbdevfs: URBs ---- */
typedef struct {
    UMockdevIoctlData *urb, *buf;
} urb_rec;
static GList *flying; /* IN URBs waiting for packets */
static GQueue reapable = G_QUEUE_INIT;
static long remove_after = -1, data_urbs;
static int removed;
static UMockdevTestbed *testbed;

static struct usbdevfs_urb *urb_of(urb_rec *r) { return (struct usbdevfs_urb *)r->urb->data; }

static void finish(urb_rec *r, int status, int actual) {
    urb_of(r)->status = status;
    urb_of(r)->actual_length = actual;
    g_queue_push_tail(&reapable, r);
}

/* Fills waiting IN URBs from the packets the device armed, in order. */
static void serve_in(void) {
    for (GList *l = flying; l;) {
        urb_rec *r = l->data;
        GList *next = l->next;
        struct usbdevfs_urb *u = urb_of(r);
        unsigned n = u->endpoint & 0xFu;
        int got = 0, any = 0;
        while (inq[n].head != inq[n].tail) {
            packet *p = &inq[n].q[inq[n].head % MAX_PKTS];
            if (got + p->len > u->buffer_length) break;
            inq[n].head++;
            any = 1;
            memcpy(r->buf->data + got, p->data, p->len);
            got += p->len;
            if (p->len < 64 || u->type == USBDEVFS_URB_TYPE_INTERRUPT) break; /* a short packet ends a transfer */
        }
        if (any) {
            flying = g_list_delete_link(flying, l);
            finish(r, 0, got);
        }
        l = next;
    }
}

static void host_out(unsigned n, const uint8_t *data, int len) {
    for (int off = 0; off < len; off += 64) {
        if (!outs[n].armed) device_step(); /* the ring was full: let the firmware read it */
        if (!outs[n].armed) return;       /* halted or unconfigured: dropped as a NAKed packet would time out */
        int k = len - off < 64 ? len - off : 64;
        memcpy(outs[n].dst, data + off, (size_t)k);
        outs[n].armed = 0;
        complete_later((uint8_t)n, (uint16_t)k);
        pump();
    }
    device_step();
}

static void unplug(void) {
    removed = 1;
    umockdev_testbed_uevent(testbed, SYSPATH, "remove");
    umockdev_testbed_remove_device(testbed, SYSPATH);
    while (flying) { /* pending URBs end with ENODEV, as the kernel reports them */
        finish(flying->data, -ENODEV, 0);
        flying = g_list_delete_link(flying, flying);
    }
    fprintf(stderr, "%s: device unplugged after %ld data URBs\n", me, data_urbs);
}

static int submit(UMockdevIoctlData *arg) {
    urb_rec *r = g_new0(urb_rec, 1);
    r->urb = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct usbdevfs_urb), NULL);
    if (!r->urb) {
        g_free(r);
        return EFAULT;
    }
    struct usbdevfs_urb *u = urb_of(r);
    if (u->buffer_length < 0 || u->buffer_length > 1 << 20) {
        g_object_unref(r->urb);
        g_free(r);
        return EINVAL;
    }
    r->buf = umockdev_ioctl_data_resolve(r->urb, G_STRUCT_OFFSET(struct usbdevfs_urb, buffer),
                                         (gsize)u->buffer_length, NULL);
    if (u->type == USBDEVFS_URB_TYPE_CONTROL) {
        if (u->buffer_length < 8) return EINVAL;
        int got = control(r->buf->data, r->buf->data + 8, u->buffer_length - 8);
        finish(r, got < 0 ? got : 0, got < 0 ? 0 : got);
        return 0;
    }
    if (u->type != USBDEVFS_URB_TYPE_BULK && u->type != USBDEVFS_URB_TYPE_INTERRUPT) return EINVAL;
    if (remove_after >= 0 && ++data_urbs > remove_after) {
        unplug();
        return ENODEV;
    }
    if (u->endpoint & 0x80u) {
        flying = g_list_append(flying, r);
        serve_in();
    } else {
        host_out(u->endpoint & 0xFu, r->buf->data, u->buffer_length);
        finish(r, 0, u->buffer_length);
    }
    return 0;
}

static gboolean handle_ioctl(UMockdevIoctlBase *h, UMockdevIoctlClient *client, gpointer user) {
    (void)h, (void)user;
    gulong req = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData *arg = umockdev_ioctl_client_get_arg(client);
    int err = 0;
    if (removed && req != USBDEVFS_REAPURBNDELAY && req != USBDEVFS_REAPURB) {
        umockdev_ioctl_client_complete(client, -1, ENODEV);
        return TRUE;
    }
    switch (req) {
    case USBDEVFS_GET_CAPABILITIES: {
        UMockdevIoctlData *d = umockdev_ioctl_data_resolve(arg, 0, sizeof(guint32), NULL);
        *(guint32 *)d->data = USBDEVFS_CAP_ZERO_PACKET | USBDEVFS_CAP_BULK_CONTINUATION |
                              USBDEVFS_CAP_NO_PACKET_SIZE_LIM | USBDEVFS_CAP_REAP_AFTER_DISCONNECT;
        g_object_unref(d);
        break;
    }
    case USBDEVFS_CONNECTINFO: {
        UMockdevIoctlData *d = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct usbdevfs_connectinfo), NULL);
        ((struct usbdevfs_connectinfo *)d->data)->devnum = 2;
        ((struct usbdevfs_connectinfo *)d->data)->slow = 0;
        g_object_unref(d);
        break;
    }
    case USBDEVFS_CLAIMINTERFACE:
    case USBDEVFS_RELEASEINTERFACE:
    case USBDEVFS_SETINTERFACE:
    case USBDEVFS_SETCONFIGURATION:
    case USBDEVFS_CLEAR_HALT:
    case USBDEVFS_RESETEP:
    case USBDEVFS_RESET:
    case USBDEVFS_DISCONNECT_CLAIM:
        break;
    case USBDEVFS_GETDRIVER:
    case USBDEVFS_IOCTL:
        err = ENODATA; /* no kernel driver bound */
        break;
    case USBDEVFS_SUBMITURB:
        err = submit(arg);
        break;
    case USBDEVFS_DISCARDURB: {
        gulong addr = *(gulong *)arg->data;
        err = EINVAL;
        for (GList *l = flying; l; l = l->next) {
            urb_rec *r = l->data;
            if (r->urb->client_addr != addr) continue;
            flying = g_list_delete_link(flying, l);
            finish(r, -ENOENT, 0);
            err = 0;
            break;
        }
        break;
    }
    case USBDEVFS_REAPURB:
    case USBDEVFS_REAPURBNDELAY: {
        serve_in();
        urb_rec *r = g_queue_pop_head(&reapable);
        if (!r) {
            err = removed ? ENODEV : EAGAIN;
            break;
        }
        UMockdevIoctlData *p = umockdev_ioctl_data_resolve(arg, 0, sizeof(gpointer), NULL);
        umockdev_ioctl_data_set_ptr(p, 0, r->urb);
        umockdev_ioctl_client_complete(client, 0, 0);
        g_object_unref(p);
        g_object_unref(r->buf);
        g_object_unref(r->urb);
        g_free(r);
        return TRUE;
    }
    default:
        fprintf(stderr, "%s: ioctl 0x%lx not emulated\n", me, req);
        err = ENOTTY;
    }
    umockdev_ioctl_client_complete(client, err ? -1 : 0, err);
    return TRUE;
}

/* ---- hidraw: the kernel's usbhid between the node and the interrupt pipes ---- */

/* umockdev backs the node with a pty and emulates read()/write() through the
 * handler, but a poll() sees the pty: a newline is kept in it while input
 * reports are waiting, so poll(POLLIN) works as on a real hidraw node. */
static int hidraw_pty = -1;
static void hidraw_readiness(void) {
    if (hidraw_pty < 0) return;
    if (inq[2].head != inq[2].tail) {
        int pending = 0;
        if (ioctl(hidraw_pty, TIOCOUTQ, &pending) == 0 && pending == 0 && write(hidraw_pty, "\n", 1) != 1)
            fprintf(stderr, "%s: cannot signal the hidraw node\n", me);
    } else {
        tcflush(hidraw_pty, TCOFLUSH);
    }
}

/* After an unplug every call on the node fails with ENODEV: TRUE when so. */
static gboolean gone(UMockdevIoctlClient *client) {
    if (removed) umockdev_ioctl_client_complete(client, -1, ENODEV);
    return removed != 0;
}

/* read(): one 64-byte input report (no report IDs), or EAGAIN when none. */
static gboolean hidraw_read(UMockdevIoctlBase *h, UMockdevIoctlClient *client, gpointer user) {
    (void)h, (void)user;
    UMockdevIoctlData *arg = umockdev_ioctl_client_get_arg(client);
    if (gone(client)) return TRUE;
    if (inq[2].head == inq[2].tail) {
        umockdev_ioctl_client_complete(client, -1, EAGAIN);
        return TRUE;
    }
    packet *p = &inq[2].q[inq[2].head++ % MAX_PKTS];
    int k = p->len < arg->data_len ? p->len : arg->data_len;
    umockdev_ioctl_data_update(arg, 0, p->data, k); /* written back to the reader */
    umockdev_ioctl_client_complete(client, k, 0);
    hidraw_readiness();
    return TRUE;
}

/* write(): report number 0 then the 64-byte output report, sent on the
 * interrupt OUT pipe as usbhid does. */
static gboolean hidraw_write(UMockdevIoctlBase *h, UMockdevIoctlClient *client, gpointer user) {
    (void)h, (void)user;
    UMockdevIoctlData *arg = umockdev_ioctl_client_get_arg(client);
    if (gone(client)) return TRUE;
    if (arg->data_len < 1 || arg->data[0] != 0 || arg->data_len - 1 > 64) {
        umockdev_ioctl_client_complete(client, -1, EINVAL);
        return TRUE;
    }
    host_out(2, arg->data + 1, arg->data_len - 1);
    umockdev_ioctl_client_complete(client, arg->data_len, 0);
    hidraw_readiness();
    return TRUE;
}

static gboolean hidraw_ioctl(UMockdevIoctlBase *h, UMockdevIoctlClient *client, gpointer user) {
    (void)h, (void)user;
    gulong req = umockdev_ioctl_client_get_request(client);
    UMockdevIoctlData *arg = umockdev_ioctl_client_get_arg(client);
    const uint8_t *rd;
    uint8_t scratch[64];
    size_t n = usbd_descriptor(USBD_DESC_HID_REPORT, 0, scratch, &rd);
    int err = 0;
    if (req == HIDIOCGRDESCSIZE) {
        UMockdevIoctlData *d = umockdev_ioctl_data_resolve(arg, 0, sizeof(int), NULL);
        *(int *)d->data = (int)n;
        g_object_unref(d);
    } else if (req == HIDIOCGRDESC) {
        UMockdevIoctlData *d = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct hidraw_report_descriptor), NULL);
        struct hidraw_report_descriptor *r = (struct hidraw_report_descriptor *)d->data;
        r->size = (unsigned)n;
        memcpy(r->value, rd, n);
        g_object_unref(d);
    } else if (req == HIDIOCGRAWINFO) {
        UMockdevIoctlData *d = umockdev_ioctl_data_resolve(arg, 0, sizeof(struct hidraw_devinfo), NULL);
        struct hidraw_devinfo *i = (struct hidraw_devinfo *)d->data;
        i->bustype = 3; /* BUS_USB */
        i->vendor = (__s16)USBD_VID;
        i->product = (__s16)USBD_PID;
        g_object_unref(d);
    } else {
        fprintf(stderr, "%s: hidraw ioctl 0x%lx not emulated\n", me, req);
        err = ENOTTY;
    }
    umockdev_ioctl_client_complete(client, err ? -1 : 0, err);
    return TRUE;
}

/* The firmware's inter-byte timeout (20 ms), checked every 10 ms. */
static gboolean idle_tick(gpointer user) {
    (void)user;
    if (cbvh_fw_rx_partial(&fw) && g_get_monotonic_time() - last_rx_us > 20000) {
        cbvh_fw_rx_idle(&fw);
        pump();
        hidraw_readiness();
    }
    return G_SOURCE_CONTINUE;
}

/* ---- the testbed ---- */
static char *descriptors_hex(void) {
    const uint8_t *d;
    uint8_t scratch[64];
    GString *s = g_string_new(NULL);
    size_t n = usbd_descriptor(USBD_DESC_DEVICE, 0, scratch, &d);
    for (size_t i = 0; i < n; i++) g_string_append_printf(s, "%02x", d[i]);
    n = usbd_descriptor(USBD_DESC_CONFIG, 0, scratch, &d);
    for (size_t i = 0; i < n; i++) g_string_append_printf(s, "%02x", d[i]);
    return g_string_free(s, FALSE);
}

static GMainLoop *loop;
static int child_status = 1;
static void child_done(GPid pid, gint status, gpointer user) {
    (void)user;
    g_spawn_close_pid(pid);
    child_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    g_main_loop_quit(loop);
}

int main(int argc, char **argv) {
    int no_permission = 0, i = 1;
    for (; i < argc && strcmp(argv[i], "--"); i++) {
        if (!strcmp(argv[i], "--no-permission")) {
            no_permission = 1;
        } else if (!strcmp(argv[i], "--remove-after-urbs") && i + 1 < argc) {
            char *end;
            remove_after = strtol(argv[++i], &end, 10);
            if (*end || remove_after < 0) {
                fprintf(stderr, "%s: --remove-after-urbs expects a count, got '%s'\n", me, argv[i]);
                return 2;
            }
        } else {
            fprintf(stderr, "%s: unknown option '%s' (usage in board_umockdev.c)\n", me, argv[i]);
            return 2;
        }
    }
    if (i + 1 >= argc) {
        fprintf(stderr, "%s: expected -- COMMAND [ARGS...]\n", me);
        return 2;
    }
    device_init();
    testbed = umockdev_testbed_new();
    UMockdevIoctlBase *handler = umockdev_ioctl_base_new();
    g_signal_connect(handler, "handle-ioctl", G_CALLBACK(handle_ioctl), NULL);
    GError *error = NULL;
    if (!umockdev_testbed_attach_ioctl(testbed, DEVNODE, handler, &error)) {
        fprintf(stderr, "%s: cannot attach %s: %s\n", me, DEVNODE, error->message);
        return 1;
    }
    char *hex = descriptors_hex();
    char *dev = g_strdup_printf("P: /devices/pci0000:00/usb1/1-1\nN: bus/usb/001/002\nE: SUBSYSTEM=usb\n"
                                "E: DEVTYPE=usb_device\nE: DRIVER=usb\nE: BUSNUM=001\nE: DEVNUM=002\n"
                                "E: DEVNAME=" DEVNODE "\nE: PRODUCT=1209/c0b1/10\n"
                                "A: busnum=1\\n\nA: devnum=2\\n\nA: speed=12\\n\nA: bConfigurationValue=1\\n\n"
                                "A: idVendor=1209\\n\nA: idProduct=c0b1\\n\nA: manufacturer=cbvh\\n\n"
                                "A: product=cbvh board\\n\nA: serial=0001\\n\nH: descriptors=%s\n",
                                hex);
    if (!umockdev_testbed_add_from_string(testbed, dev, &error)) {
        fprintf(stderr, "%s: cannot add the device: %s\n", me, error->message);
        return 1;
    }
    g_free(dev);
    g_free(hex);
    /* interface 1 with usbhid bound, its hid device and the hidraw node */
    UMockdevIoctlBase *hidraw = umockdev_ioctl_base_new();
    g_signal_connect(hidraw, "handle-ioctl", G_CALLBACK(hidraw_ioctl), NULL);
    g_signal_connect(hidraw, "handle-read", G_CALLBACK(hidraw_read), NULL);
    g_signal_connect(hidraw, "handle-write", G_CALLBACK(hidraw_write), NULL);
    if (!umockdev_testbed_attach_ioctl(testbed, HIDRAW_NODE, hidraw, &error)) {
        fprintf(stderr, "%s: cannot attach %s: %s\n", me, HIDRAW_NODE, error->message);
        return 1;
    }
    GString *rdesc = g_string_new(NULL);
    {
        const uint8_t *rd;
        uint8_t scratch[64];
        size_t n = usbd_descriptor(USBD_DESC_HID_REPORT, 0, scratch, &rd);
        for (size_t k = 0; k < n; k++) g_string_append_printf(rdesc, "%02x", rd[k]);
    }
    char *hid = g_strdup_printf(
        "P: /devices/pci0000:00/usb1/1-1/1-1:1.1\nE: SUBSYSTEM=usb\nE: DEVTYPE=usb_interface\nE: DRIVER=usbhid\n"
        "A: bInterfaceNumber=01\\n\nA: bInterfaceClass=03\\n\n\n"
        "P: /devices/pci0000:00/usb1/1-1/1-1:1.1/0003:1209:C0B1.0001\nE: SUBSYSTEM=hid\nE: DRIVER=hid-generic\n"
        "E: HID_ID=0003:00001209:0000C0B1\nE: HID_NAME=cbvh cbvh board\nE: HID_PHYS=usb-0000:00:00.0-1/input1\n"
        "E: HID_UNIQ=0001\nH: report_descriptor=%s\n\n"
        "P: /devices/pci0000:00/usb1/1-1/1-1:1.1/0003:1209:C0B1.0001/hidraw/hidraw0\nN: hidraw0\n"
        "E: SUBSYSTEM=hidraw\nE: DEVNAME=" HIDRAW_NODE "\nE: MAJOR=240\nE: MINOR=0\n",
        rdesc->str);
    g_string_free(rdesc, TRUE);
    if (!umockdev_testbed_add_from_string(testbed, hid, &error)) {
        fprintf(stderr, "%s: cannot add the hidraw device: %s\n", me, error->message);
        return 1;
    }
    g_free(hid);
    hidraw_pty = umockdev_testbed_get_dev_fd(testbed, HIDRAW_NODE);
    /* hidraw0/device -> the hid device, as the kernel links it (hidapi reads uevent and
     * report_descriptor through it) */
    umockdev_testbed_set_attribute_link(testbed, SYSPATH "/1-1:1.1/0003:1209:C0B1.0001/hidraw/hidraw0", "device",
                                        "../..");
    char *root = umockdev_testbed_get_root_dir(testbed);
    GPtrArray *cmd = g_ptr_array_new();
    if (no_permission) { /* as a user the udev rule did not let in */
        char *node = g_strconcat(root, DEVNODE, NULL);
        /* umockdev's own sockets stay open to everyone: only the node is closed */
        char *sock_default = g_strconcat(root, "/ioctl/_default", NULL), *sock = g_strconcat(root, "/ioctl" DEVNODE, NULL);
        if (g_chmod(node, 0600) != 0 || chown(node, 0, 0) != 0 || g_chmod(root, 01777) != 0 ||
            g_chmod(sock_default, 0777) != 0 || g_chmod(sock, 0777) != 0) {
            fprintf(stderr, "%s: cannot set the permissions under %s: %s\n", me, root, strerror(errno));
            return 1;
        }
        g_free(node);
        g_free(sock_default);
        g_free(sock);
        g_ptr_array_add(cmd, "setpriv");
        g_ptr_array_add(cmd, "--reuid=nobody");
        g_ptr_array_add(cmd, "--regid=nogroup");
        g_ptr_array_add(cmd, "--clear-groups");
        g_ptr_array_add(cmd, "--");
    }
    g_ptr_array_add(cmd, "umockdev-wrapper");
    for (int k = i + 1; k < argc; k++) g_ptr_array_add(cmd, argv[k]);
    g_ptr_array_add(cmd, NULL);
    GPid pid;
    if (!g_spawn_async(NULL, (char **)cmd->pdata, NULL, G_SPAWN_SEARCH_PATH | G_SPAWN_DO_NOT_REAP_CHILD, NULL, NULL,
                       &pid, &error)) {
        fprintf(stderr, "%s: cannot run %s: %s\n", me, argv[i + 1], error->message);
        return 1;
    }
    loop = g_main_loop_new(NULL, FALSE);
    g_child_watch_add(pid, child_done, NULL);
    g_timeout_add(10, idle_tick, NULL);
    g_main_loop_run(loop);
    g_ptr_array_free(cmd, TRUE);
    g_free(root);
    g_object_unref(handler);
    g_object_unref(hidraw);
    g_object_unref(testbed);
    return child_status;
}
