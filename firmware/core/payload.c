/* Payload layouts of the board protocol's commands (see cbvh_fw/payload.h). */
#include "cbvh_fw/payload.h"
#include "cbvh_fw/frame.h"

void cbvh_run_hdr_put(uint8_t *p, const cbvh_run_hdr *h) {
    p[0] = h->unit;
    p[1] = (uint8_t)h->quant_bits;
    cbvh_put16(p + 2, (uint16_t)h->min_scale);
    p[4] = h->encoding;
    p[5] = h->n_in;
    p[6] = h->n_out;
    p[7] = 0;
    cbvh_put16(p + 8, h->count);
    cbvh_put16(p + 10, 0);
}

int cbvh_run_hdr_get(const uint8_t *p, size_t len, cbvh_run_hdr *h) {
    if (len < CBVH_RUN_HDR || p[7] != 0 || cbvh_get16(p + 10) != 0) return -1;
    h->unit = p[0];
    h->quant_bits = (int8_t)p[1];
    h->min_scale = (int16_t)cbvh_get16(p + 2);
    h->encoding = p[4];
    h->n_in = p[5];
    h->n_out = p[6];
    h->count = cbvh_get16(p + 8);
    return 0;
}

void cbvh_run_reply_hdr_put(uint8_t *p, const cbvh_run_reply_hdr *h) {
    cbvh_put16(p, h->count);
    p[2] = h->n_out;
    p[3] = h->unit;
}

int cbvh_run_reply_hdr_get(const uint8_t *p, size_t len, cbvh_run_reply_hdr *h) {
    if (len < CBVH_RUN_REPLY_HDR) return -1;
    h->count = cbvh_get16(p);
    h->n_out = p[2];
    h->unit = p[3];
    return 0;
}

void cbvh_identity_put(uint8_t *p, const cbvh_identity *id) {
    for (unsigned i = 0; i < CBVH_IDENTITY_BYTES; i++) p[i] = 0;
    p[0] = id->proto_version;
    p[1] = id->fw_major;
    p[2] = id->fw_minor;
    p[3] = id->fw_patch;
    cbvh_put32(p + 4, id->datapath_version);
    cbvh_put32(p + 8, id->units);
    cbvh_put16(p + 12, id->max_payload);
    p[14] = id->reg_words;
    cbvh_put32(p + 16, id->reg_id);
    for (unsigned i = 0; i < sizeof id->board_name - 1 && id->board_name[i]; i++) p[20 + i] = (uint8_t)id->board_name[i];
}

int cbvh_identity_get(const uint8_t *p, size_t len, cbvh_identity *id) {
    if (len != CBVH_IDENTITY_BYTES) return -1;
    id->proto_version = p[0];
    id->fw_major = p[1];
    id->fw_minor = p[2];
    id->fw_patch = p[3];
    id->datapath_version = cbvh_get32(p + 4);
    id->units = cbvh_get32(p + 8);
    id->max_payload = cbvh_get16(p + 12);
    id->reg_words = p[14];
    id->reg_id = cbvh_get32(p + 16);
    unsigned i = 0;
    for (; i < sizeof id->board_name - 1 && p[20 + i]; i++) id->board_name[i] = (char)p[20 + i];
    for (; i < sizeof id->board_name; i++) id->board_name[i] = '\0';
    return 0;
}
