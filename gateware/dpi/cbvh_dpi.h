/* The C model behind a Verilator testbench, through DPI-C, for any unit of
 * the unit table (docs/gateware.md, "DPI-C scoreboard").
 *
 * A testbench opens a unit by its name and design point, asks for random
 * input words (cbvh_dpi_stimulus), drives its DUT with them and compares the
 * DUT's output words with the model's (cbvh_dpi_eval).  Words are the unit
 * table's (one 32-bit word per field, in cbvh_layout order), the same as in
 * a vector file.  The SystemVerilog side imports these functions as declared
 * in gateware/dpi/cbvh_dpi.svh (a bit [31:0] w [0:39] array arrives as a
 * pointer to 40 words). */
#ifndef CBVH_DPI_H
#define CBVH_DPI_H

#include <stdint.h>

#define CBVH_DPI_WORDS 40 /* CBVH_MAX_FIELDS */

#ifdef __cplusplus
extern "C" {
#endif

/* A handle (>= 0) for unit `unit` at N = quant_bits, min scale, encoding
 * (modulo: 1 modulo, 0 relative); `pins` fixes input fields for the stimulus,
 * "name=value,name=value" (e.g. "mant=8,texp=8": a hardware instance built
 * for one M).  -1 and a line on stderr for an unknown unit, a bad design
 * point or a pin that names no input field. */
int cbvh_dpi_open(const char *unit, int quant_bits, int min_scale, int modulo, const char *pins, int seed);
int cbvh_dpi_n_in(int h);
int cbvh_dpi_n_out(int h);
/* Name of input (out = 0) or output (out = 1) field i. */
const char *cbvh_dpi_field(int h, int out, int i);
/* The next random input words: the unit's own stimulus where it has one
 * (ray_box_incr: chains of boxes, shaped random inputs and raw words), else
 * a generic mix per field (tests/board/gen_inputs.h); pins applied last. */
void cbvh_dpi_stimulus(int h, uint32_t *in);
/* The model's output words for these input words. */
void cbvh_dpi_eval(int h, const uint32_t *in, uint32_t *out);

#ifdef __cplusplus
}
#endif

#endif
