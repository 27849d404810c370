/* Firmware core: parse frames, dispatch commands, stream batches through the
 * datapath.  Every malformed frame gets an error reply; the core never stops. */
#include "cbvh_fw/fw.h"
#include "cbvh_fw/payload.h"
#include "cbvh_fw/regmap.h"

void cbvh_fw_init(cbvh_fw *fw, const cbvh_fw_hal *hal) {
    fw->hal = hal;
    cbvh_parser_init(&fw->rx);
    cbvh_fw_counters zero = {0};
    fw->n = zero;
    hal->reg_write(hal->ctx, CBVH_REG_CTRL, CBVH_CTRL_RESET);
}

static void reply(cbvh_fw *fw, uint8_t cmd, uint8_t status, uint16_t seq, uint16_t len) {
    if (status != CBVH_E_OK) fw->n.error_replies++;
    size_t n = cbvh_frame_seal(fw->tx, (uint8_t)(cmd | CBVH_REPLY), status, seq, len);
    fw->hal->send(fw->hal->ctx, fw->tx, n);
}

static void reply_error(cbvh_fw *fw, uint8_t cmd, uint8_t status, uint16_t seq) { reply(fw, cmd, status, seq, 0); }

static void do_identify(cbvh_fw *fw, uint16_t seq) {
    const cbvh_fw_hal *h = fw->hal;
    cbvh_identity id = {0};
    id.proto_version = CBVH_PROTO_VERSION;
    id.fw_major = CBVH_FW_VERSION_MAJOR;
    id.fw_minor = CBVH_FW_VERSION_MINOR;
    id.fw_patch = CBVH_FW_VERSION_PATCH;
    /* one statement each: the register reads go out in this order */
    id.datapath_version = h->reg_read(h->ctx, CBVH_REG_VERSION);
    id.units = h->reg_read(h->ctx, CBVH_REG_UNITS);
    id.max_payload = CBVH_FRAME_MAX_PAYLOAD;
    id.reg_words = CBVH_REG_WORDS;
    id.reg_id = h->reg_read(h->ctx, CBVH_REG_ID);
    const char *name = h->board_name ? h->board_name : "";
    for (unsigned i = 0; i < sizeof id.board_name - 1 && name[i]; i++) id.board_name[i] = name[i];
    cbvh_identity_put(fw->tx + CBVH_FRAME_HDR, &id);
    reply(fw, CBVH_CMD_IDENTIFY, CBVH_E_OK, seq, CBVH_IDENTITY_BYTES);
}

static void do_status(cbvh_fw *fw, uint16_t seq) {
    /* listed field by field: indexing past &n.frames_ok would be undefined
     * (pointer arithmetic outside one member), adjacent fields or not */
    const cbvh_fw_counters *n = &fw->n;
    const uint32_t c[CBVH_FW_COUNTERS] = {n->frames_ok,     n->error_replies, n->crc_errors,
                                          n->sync_errors,   n->header_errors, n->rx_timeouts,
                                          n->vectors,       n->batches,       n->datapath_errors};
    for (unsigned i = 0; i < CBVH_FW_COUNTERS; i++) cbvh_put32(fw->tx + CBVH_FRAME_HDR + 4 * i, c[i]);
    reply(fw, CBVH_CMD_STATUS, CBVH_E_OK, seq, 4 * CBVH_FW_COUNTERS);
}

/* RUN: layouts in cbvh_fw/payload.h. */
static void do_run(cbvh_fw *fw, const cbvh_frame *f) {
    const uint8_t *p = f->payload;
    cbvh_run_hdr h;
    if (cbvh_run_hdr_get(p, f->len, &h) || h.encoding > 1) {
        reply_error(fw, CBVH_CMD_RUN, CBVH_E_PAYLOAD, f->seq);
        return;
    }
    cbvh_fw_config cfg = {h.quant_bits, h.min_scale, h.encoding};
    unsigned n_in = h.n_in, n_out = h.n_out, count = h.count;
    uint32_t shape = 0;
    int sel = cbvh_dp_select(fw->hal, h.unit, &cfg, &shape);
    if (sel != CBVH_E_OK) {
        reply_error(fw, CBVH_CMD_RUN, (uint8_t)sel, f->seq);
        return;
    }
    if ((shape & 0xFFu) != n_in || (shape >> 8) != n_out || n_in > CBVH_REG_WORDS || n_out > CBVH_REG_WORDS ||
        n_in == 0) {
        reply_error(fw, CBVH_CMD_RUN, CBVH_E_SHAPE, f->seq);
        return;
    }
    unsigned long in_bytes = 4ul * n_in * count, out_bytes = 4ul * n_out * count;
    if (CBVH_RUN_REPLY_HDR + out_bytes > CBVH_FRAME_MAX_PAYLOAD) {
        reply_error(fw, CBVH_CMD_RUN, CBVH_E_TOO_BIG, f->seq);
        return;
    }
    if (f->len != CBVH_RUN_HDR + in_bytes) {
        reply_error(fw, CBVH_CMD_RUN, CBVH_E_PAYLOAD, f->seq);
        return;
    }
    uint8_t *o = fw->tx + CBVH_FRAME_HDR;
    cbvh_run_reply_hdr rh = {h.count, h.n_out, h.unit};
    cbvh_run_reply_hdr_put(o, &rh);
    for (unsigned v = 0; v < count; v++) {
        if (cbvh_dp_run_one(fw->hal, p + CBVH_RUN_HDR + 4ul * n_in * v, n_in, o + CBVH_RUN_REPLY_HDR + 4ul * n_out * v,
                            n_out)) {
            fw->n.datapath_errors++;
            fw->hal->reg_write(fw->hal->ctx, CBVH_REG_CTRL, CBVH_CTRL_RESET);
            reply_error(fw, CBVH_CMD_RUN, CBVH_E_DATAPATH, f->seq);
            return;
        }
        fw->n.vectors++;
    }
    fw->n.batches++;
    reply(fw, CBVH_CMD_RUN, CBVH_E_OK, f->seq, (uint16_t)(CBVH_RUN_REPLY_HDR + out_bytes));
}

static void dispatch(cbvh_fw *fw, const cbvh_frame *f) {
    if (f->status != 0 || (f->cmd & CBVH_REPLY)) {
        fw->n.header_errors++;
        reply_error(fw, (uint8_t)(f->cmd & 0x7Fu), CBVH_E_HEADER, f->seq);
        return;
    }
    fw->n.frames_ok++;
    switch (f->cmd) {
    case CBVH_CMD_IDENTIFY:
        if (f->len) reply_error(fw, f->cmd, CBVH_E_PAYLOAD, f->seq);
        else do_identify(fw, f->seq);
        break;
    case CBVH_CMD_RESET:
        if (f->len) {
            reply_error(fw, f->cmd, CBVH_E_PAYLOAD, f->seq);
            break;
        }
        fw->hal->reg_write(fw->hal->ctx, CBVH_REG_CTRL, CBVH_CTRL_RESET);
        {
            cbvh_fw_counters zero = {0};
            fw->n = zero;
        }
        reply(fw, f->cmd, CBVH_E_OK, f->seq, 0);
        break;
    case CBVH_CMD_RUN:
        do_run(fw, f);
        break;
    case CBVH_CMD_LOOPBACK:
        for (unsigned i = 0; i < f->len; i++) fw->tx[CBVH_FRAME_HDR + i] = f->payload[i];
        reply(fw, f->cmd, CBVH_E_OK, f->seq, f->len);
        break;
    case CBVH_CMD_STATUS:
        if (f->len) reply_error(fw, f->cmd, CBVH_E_PAYLOAD, f->seq);
        else do_status(fw, f->seq);
        break;
    default:
        reply_error(fw, f->cmd, CBVH_E_COMMAND, f->seq);
    }
}

static void parse_error(cbvh_fw *fw, const cbvh_parse_error *e) {
    switch (e->code) {
    case CBVH_E_CRC: fw->n.crc_errors++; break;
    case CBVH_E_SYNC: fw->n.sync_errors++; break;
    case CBVH_E_TIMEOUT: fw->n.rx_timeouts++; break;
    default: fw->n.header_errors++; break;
    }
    reply_error(fw, (uint8_t)(e->cmd & 0x7Fu), e->code, e->seq);
}

void cbvh_fw_rx(cbvh_fw *fw, const uint8_t *data, size_t n) {
    while (n > 0 || cbvh_parser_busy(&fw->rx)) {
        size_t used = 0;
        cbvh_frame f;
        cbvh_parse_error e;
        int ev = cbvh_parser_push(&fw->rx, data, n, &used, &f, &e);
        if (used) { /* data may be NULL when only rescanning */
            data += used;
            n -= used;
        }
        if (ev == CBVH_PARSE_FRAME) dispatch(fw, &f);
        else if (ev == CBVH_PARSE_ERROR) parse_error(fw, &e);
    }
}

void cbvh_fw_rx_idle(cbvh_fw *fw) {
    cbvh_parse_error e;
    if (cbvh_parser_timeout(&fw->rx, &e)) {
        parse_error(fw, &e);
        cbvh_fw_rx(fw, NULL, 0); /* rescan the dropped bytes */
    }
}
