// The C model through DPI-C (gateware/dpi/cbvh_dpi.h; docs/gateware.md,
// "DPI-C scoreboard"): any unit of the unit table, by name, as 32-bit words.
import "DPI-C" function int cbvh_dpi_open(input string unit, input int quant_bits, input int min_scale,
                                          input int modulo, input string pins, input int seed);
import "DPI-C" function int cbvh_dpi_n_in(input int h);
import "DPI-C" function int cbvh_dpi_n_out(input int h);
import "DPI-C" function string cbvh_dpi_field(input int h, input int out, input int i);
import "DPI-C" function void cbvh_dpi_stimulus(input int h, output bit [31:0] in_w [0:39]);
import "DPI-C" function void cbvh_dpi_eval(input int h, input bit [31:0] in_w [0:39], output bit [31:0] out_w [0:39]);
