// The board's FPGA for `cbvh board-sim --gateware`: cbvh_board_top driven
// over its SPI pins by transactions read from stdin, one per line,
//     n b0 b1 ... b(n-1)          (decimal count, hex bytes; "0" or EOF ends)
// each clocked out MSB first with CS low around it (SPI mode 0), and answered
// on stdout with the bytes sampled on MISO:
//     @ m0 m1 ... m(n-1)
// The bytes are exactly those the RP2040 port sends (firmware/include/cbvh_fw/
// spi_wire.h); the bridge is firmware/ports/sim/regmap_gateware.c.
// SCK runs at clk / 8: high and low phases of 4 clocks, the slowest clock the
// SPI slave is specified for (gateware/board/spi_slave.v).
//   iverilog -g2005 -P tb_board_link.N=6 -P tb_board_link.E_MIN=-30 \
//       -P tb_board_link.ENCODINGS=3 -o board.vvp gateware/tb/tb_board_link.v \
//       gateware/board/*.v gateware/rtl/*.v       (gateware/scripts/build-board-sim)
// UNITS: bit i set = unit i built (cbvh_board_top's HAS_* flags); default all.
`timescale 1ns / 1ps
module tb_board_link;
    parameter integer N         = 6;
    parameter integer E_MIN     = -30;
    parameter integer ENCODINGS = 3;
    parameter integer UNITS     = 32'h3FE;

    localparam integer CLK_HALF = 5;            // 100 MHz simulated clock; only ratios matter
    localparam integer SCK_HALF = 4 * 2 * CLK_HALF;
    localparam integer MAX_BYTES = 16;
    localparam [31:0] STDOUT = 32'h8000_0001;

    reg clk = 1'b0;
    always #CLK_HALF clk = ~clk;

    reg  sck = 1'b0, cs_n = 1'b1, mosi = 1'b0;
    wire miso;

    cbvh_board_top #(.N(N), .E_MIN(E_MIN), .ENCODINGS(ENCODINGS),
        .HAS_ESTIMATOR(UNITS >> 1 & 1), .HAS_COMPRESSOR(UNITS >> 2 & 1), .HAS_DECODER(UNITS >> 3 & 1),
        .HAS_NP_ENCODER(UNITS >> 4 & 1), .HAS_NP_DECODER(UNITS >> 5 & 1), .HAS_RAY_BOX(UNITS >> 6 & 1),
        .HAS_RAY_TRI(UNITS >> 7 & 1), .HAS_QBVH_STACK(UNITS >> 8 & 1), .HAS_RAY_SPHERE(UNITS >> 9 & 1)) dut (
        .clk(clk), .spi_sck(sck), .spi_cs_n(cs_n), .spi_mosi(mosi), .spi_miso(miso));

    integer fd, rc, n, i, k, b;
    reg [7:0] tx, rx;
    reg [7:0] got [0:MAX_BYTES-1];

    initial begin
        fd = $fopen("/dev/stdin", "r");
        if (fd == 0) $fatal(1, "tb_board_link: cannot open stdin");
        #(40 * 2 * CLK_HALF);   // past the power-on reset
        rc = $fscanf(fd, "%d", n);
        while (rc == 1 && n > 0) begin
            if (n > MAX_BYTES) $fatal(1, "tb_board_link: transaction of %0d bytes (at most %0d)", n, MAX_BYTES);
            cs_n = 1'b0;
            #(SCK_HALF);
            for (i = 0; i < n; i = i + 1) begin
                rc = $fscanf(fd, "%h", b);
                if (rc != 1) $fatal(1, "tb_board_link: malformed transaction on stdin");
                tx = b[7:0];
                for (k = 7; k >= 0; k = k - 1) begin
                    mosi = tx[k];
                    #(SCK_HALF);
                    sck = 1'b1;
                    rx[k] = miso;
                    #(SCK_HALF);
                    sck = 1'b0;
                end
                got[i] = rx;
            end
            #(SCK_HALF);
            cs_n = 1'b1;
            mosi = 1'b0;
            #(2 * SCK_HALF);
            $fwrite(STDOUT, "@");
            for (i = 0; i < n; i = i + 1) $fwrite(STDOUT, " %02x", got[i]);
            $fwrite(STDOUT, "\n");
            $fflush(STDOUT);
            rc = $fscanf(fd, "%d", n);
        end
        $finish;
    end
endmodule
