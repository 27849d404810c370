/* The board's USB descriptors (docs/board.md lists them): device 1209:C0B1,
 * one configuration with interface 0 = vendor class, bulk OUT 0x01 / IN 0x81,
 * and interface 1 = HID, interrupt IN 0x82 / OUT 0x02, 64-byte reports
 * without report IDs, vendor usage page. */
#include "usbd.h"

#define LO(x) ((uint8_t)((x) & 0xFFu))
#define HI(x) ((uint8_t)((x) >> 8))

static const uint8_t device_desc[18] = {
    18, USBD_DESC_DEVICE, 0x00, 0x02, /* USB 2.0 */
    0x00, 0x00, 0x00,                 /* class per interface */
    USBD_MPS, LO(USBD_VID), HI(USBD_VID), LO(USBD_PID), HI(USBD_PID), LO(USBD_BCD_DEVICE), HI(USBD_BCD_DEVICE),
    1, 2, 3, /* manufacturer, product, serial strings */
    1,       /* configurations */
};

static const uint8_t hid_report_desc[] = {
    0x06, 0x00, 0xFF, /* usage page: vendor 0xFF00 */
    0x09, 0x01,       /* usage 1 */
    0xA1, 0x01,       /* collection (application) */
    0x09, 0x02, 0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08, 0x95, USBD_HID_REPORT, 0x81, 0x02, /* input: 64 bytes */
    0x09, 0x03, 0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08, 0x95, USBD_HID_REPORT, 0x91, 0x02, /* output: 64 bytes */
    0xC0, /* end collection */
};

#define CONFIG_LEN (9 + 9 + 7 + 7 + 9 + 9 + 7 + 7)
#define HID_DESC_AT (9 + 9 + 7 + 7 + 9)
static const uint8_t config_desc[CONFIG_LEN] = {
    9, USBD_DESC_CONFIG, LO(CONFIG_LEN), HI(CONFIG_LEN), 2, 1, 0, 0x80, 50, /* 2 interfaces, bus powered, 100 mA */
    /* interface 0: vendor class, the bulk link */
    9, 4, USBD_IFACE_VENDOR, 0, 2, 0xFF, 0x00, 0x00, 4,
    7, 5, USBD_EP_BULK_OUT, USBD_XFER_BULK, USBD_MPS, 0, 0,
    7, 5, USBD_EP_BULK_IN, USBD_XFER_BULK, USBD_MPS, 0, 0,
    /* interface 1: HID, the report link */
    9, 4, USBD_IFACE_HID, 0, 2, 0x03, 0x00, 0x00, 5,
    9, USBD_DESC_HID, 0x11, 0x01, 0x00, 1, USBD_DESC_HID_REPORT, LO(sizeof hid_report_desc), HI(sizeof hid_report_desc),
    7, 5, USBD_EP_HID_IN, USBD_XFER_INTERRUPT, USBD_MPS, 0, 1,
    7, 5, USBD_EP_HID_OUT, USBD_XFER_INTERRUPT, USBD_MPS, 0, 1,
};

static const char *const strings[] = {0, "cbvh", "cbvh board", "0001", "cbvh bulk link", "cbvh hid link"};
#define N_STRINGS (sizeof strings / sizeof strings[0])

size_t usbd_descriptor(uint8_t type, uint8_t index, uint8_t *scratch, const uint8_t **out) {
    switch (type) {
    case USBD_DESC_DEVICE:
        if (index) return 0;
        *out = device_desc;
        return sizeof device_desc;
    case USBD_DESC_CONFIG:
        if (index) return 0;
        *out = config_desc;
        return sizeof config_desc;
    case USBD_DESC_HID:
        if (index) return 0;
        *out = config_desc + HID_DESC_AT;
        return 9;
    case USBD_DESC_HID_REPORT:
        if (index) return 0;
        *out = hid_report_desc;
        return sizeof hid_report_desc;
    case USBD_DESC_STRING: {
        if (index >= N_STRINGS) return 0;
        size_t n = 2;
        if (index == 0) { /* supported languages: en-US */
            scratch[n++] = 0x09;
            scratch[n++] = 0x04;
        } else {
            for (const char *s = strings[index]; *s && n + 2 <= USBD_MPS; s++) {
                scratch[n++] = (uint8_t)*s; /* ASCII as UTF-16LE */
                scratch[n++] = 0;
            }
        }
        scratch[0] = (uint8_t)n;
        scratch[1] = USBD_DESC_STRING;
        *out = scratch;
        return n;
    }
    default:
        return 0; /* device qualifier, other speed: a full-speed-only device has none */
    }
}
