/* Register map of the FPGA datapath as the firmware sees it (32-bit registers,
 * byte addresses).  On a real board these sit behind SPI (ports/rp2040_ice40);
 * in the sim port they are backed by the bit-exact model. */
#ifndef CBVH_FW_REGMAP_H
#define CBVH_FW_REGMAP_H

#define CBVH_REG_ID 0x000u        /* RO: CBVH_REG_ID_VALUE */
#define CBVH_REG_VERSION 0x004u   /* RO: datapath version */
#define CBVH_REG_UNITS 0x008u     /* RO: bit i set = unit id i present */
#define CBVH_REG_CONFIG 0x00Cu    /* RW: [7:0] N (int8), [23:8] min_scale (int16), [24] encoding */
#define CBVH_REG_UNIT_SEL 0x010u  /* RW: unit id */
#define CBVH_REG_SHAPE 0x014u     /* RO: [7:0] n_in, [15:8] n_out of the selected unit under CONFIG */
#define CBVH_REG_CTRL 0x018u      /* WO: CBVH_CTRL_* */
#define CBVH_REG_STATUS 0x01Cu    /* RO: CBVH_STAT_* */
#define CBVH_REG_IN(i) (0x100u + 4u * (unsigned)(i))  /* WO: input word i */
#define CBVH_REG_OUT(i) (0x200u + 4u * (unsigned)(i)) /* RO: output word i */
#define CBVH_REG_WORDS 64u                            /* words in each window */

#define CBVH_REG_ID_VALUE 0x48564243u /* "CBVH" little-endian */
#define CBVH_CTRL_START 1u
#define CBVH_CTRL_RESET 2u
#define CBVH_STAT_BUSY 1u
#define CBVH_STAT_DONE 2u
#define CBVH_STAT_ERROR 4u

#define CBVH_DATAPATH_POLL_LIMIT 1000u /* STATUS reads before a run counts as hung */

#endif
