// FPGA top level of the board (RP2040 + iCE40UP5K): the datapath register map
// (datapath_regs.v) behind the SPI slave (spi_slave.v) that the firmware's
// rp2040_ice40 port drives. One design point per bitstream: N, E_MIN,
// ENCODINGS and the HAS_* flags as in cbvh_datapath_regs.
//
// clk is the board's 12 MHz oscillator; SPI SCK must then be <= 1.5 MHz (the
// slave oversamples; see spi_slave.v). There is no reset pin: a power-on
// counter (initial value 0, which yosys for iCE40 and Icarus both honour)
// holds reset for the first 15 clocks.
`default_nettype none

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_board_top #(
    parameter integer N              = 6,
    parameter integer E_MIN          = -30,
    parameter integer ENCODINGS      = 1,
    parameter integer HAS_ESTIMATOR  = 1,
    parameter integer HAS_COMPRESSOR = 1,
    parameter integer HAS_DECODER    = 1,
    parameter integer HAS_NP_ENCODER = 1,
    parameter integer HAS_NP_DECODER = 1,
    parameter integer HAS_RAY_BOX    = 1,
    parameter integer HAS_RAY_TRI    = 1,   // unit 7 (sequential, as the ray box)
    parameter integer HAS_QBVH_STACK = 1,
    parameter integer HAS_RAY_SPHERE = 1   // unit 9 (sequential, as the ray box)
) (
    input  wire clk,
    input  wire spi_sck,
    input  wire spi_cs_n,
    input  wire spi_mosi,
    output wire spi_miso
);
/* verilator lint_on DECLFILENAME */

    reg [3:0] por = 4'd0;
    wire rst = (por != 4'd15);
    always @(posedge clk)
        if (rst) por <= por + 4'd1;

    wire        rd_en, wr_en;
    wire [15:0] rd_addr, wr_addr;
    wire [31:0] rd_data, wr_data;

    cbvh_spi_slave u_spi (
        .clk(clk), .rst(rst), .sck(spi_sck), .cs_n(spi_cs_n), .mosi(spi_mosi), .miso(spi_miso),
        .rd_en(rd_en), .rd_addr(rd_addr), .rd_data(rd_data),
        .wr_en(wr_en), .wr_addr(wr_addr), .wr_data(wr_data));

    cbvh_datapath_regs #(
        .N(N), .E_MIN(E_MIN), .ENCODINGS(ENCODINGS),
        .HAS_ESTIMATOR(HAS_ESTIMATOR), .HAS_COMPRESSOR(HAS_COMPRESSOR),
        .HAS_DECODER(HAS_DECODER), .HAS_NP_ENCODER(HAS_NP_ENCODER),
        .HAS_NP_DECODER(HAS_NP_DECODER), .HAS_RAY_BOX(HAS_RAY_BOX), .HAS_RAY_TRI(HAS_RAY_TRI),
        .HAS_QBVH_STACK(HAS_QBVH_STACK), .HAS_RAY_SPHERE(HAS_RAY_SPHERE)
    ) u_regs (
        .clk(clk), .rst(rst),
        .wr_en(wr_en), .wr_addr(wr_addr), .wr_data(wr_data),
        .rd_en(rd_en), .rd_addr(rd_addr), .rd_data(rd_data));
endmodule

`default_nettype wire
