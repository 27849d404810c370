// The datapath register map (docs/protocol.md, "Datapath register map";
// firmware/include/cbvh_fw/regmap.h; C reference: firmware/ports/sim/
// regmap_model.c) around the units of gateware/rtl/, for ONE design point.
//
// Addresses here are WORD addresses (byte address / 4), as on the SPI bus:
//   0x00 ID 0x48564243   0x01 VERSION 1   0x02 UNITS (bit i = unit i built)
//   0x03 CONFIG rw: [7:0] N, [23:8] min_scale, [24] encoding (1 relative)
//   0x04 UNIT_SEL rw     0x05 SHAPE ro: [7:0] n_in, [15:8] n_out, or 0 when the
//        selected unit does not accept CONFIG
//   0x06 CTRL wo: bit 0 start, bit 1 reset (reset first when both are set)
//   0x07 STATUS ro: bit 0 busy, bit 1 done, bit 2 error
//   0x40 + i IN[i] wo    0x80 + i OUT[i] ro    (i < 64)
// Unknown addresses read 0; writes to them (and to IN words no built unit
// reads) are ignored. CONFIG and UNIT_SEL keep all 32 bits, as the C model.
//
// A unit accepts CONFIG when it is built and, for units 1-5, CONFIG's N and
// min_scale equal the parameters N and E_MIN; for units 3-5 the encoding of
// CONFIG[24] must also be built (ENCODINGS bit 0 modulo, bit 1 relative).
// Units 6 (ray box), 7 (ray triangle), 8 (QBVH stack) and 9 (ray sphere)
// accept any CONFIG.
//
// Start of a combinational unit: STATUS = done and OUT latches the unit's
// outputs one clock after the CTRL write, then keeps re-latching them for
// RECAPTURE more clocks. The units close at only 5-12 MHz on the iCE40UP5K
// (docs/results.md), i.e. take up to ~3 periods of a 12 MHz clock, notably
// after a CTRL write of reset+start, where IN is zeroed one clock before the
// start; the last capture, 9 clocks after the write, is settled. IN,
// UNIT_SEL and CONFIG cannot change in that window: the next SPI write ends
// at least 56 SCK periods (>= 448 clk) later. So the paths IN -> unit -> OUT
// are multicycle paths, and the design's nextpnr fmax (which counts them as
// single-cycle) understates what it runs at.
// Start of a sequential unit (6 ray box, 7 ray triangle, 9 ray sphere): its
// start is pulsed
// and which unit runs is latched, STATUS = busy until that unit's done, then
// OUT latches its (registered) outputs and STATUS = done. A UNIT_SEL write
// during the run does not change what OUT captures; CTRL reset aborts the run.
`default_nettype none

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_datapath_regs #(
    parameter integer N              = 6,    // quant_bits, 3..10
    parameter integer E_MIN          = -30,  // min_scale, -126..126
    parameter integer ENCODINGS      = 1,    // bit 0: modulo instances, bit 1: relative
    parameter integer HAS_ESTIMATOR  = 1,    // unit 1 scale_estimate
    parameter integer HAS_COMPRESSOR = 1,    // unit 2 axis_compress
    parameter integer HAS_DECODER    = 1,    // unit 3 axis_decode
    parameter integer HAS_NP_ENCODER = 1,    // unit 4 nodepair_encode
    parameter integer HAS_NP_DECODER = 1,    // unit 5 nodepair_decode
    parameter integer HAS_RAY_BOX    = 1,    // unit 6 ray_box
    parameter integer HAS_RAY_TRI    = 1,    // unit 7 ray_triangle
    parameter integer HAS_QBVH_STACK = 1,    // unit 8 qbvh_stack
    parameter integer HAS_RAY_SPHERE = 1     // unit 9 ray_sphere
) (
    input  wire        clk,
    input  wire        rst,      // synchronous, active high
    input  wire        wr_en,
    input  wire [15:0] wr_addr,  // word address
    input  wire [31:0] wr_data,
    input  wire        rd_en,
    input  wire [15:0] rd_addr,  // word address
    output reg  [31:0] rd_data   // valid from the clock after rd_en until the next rd_en
);
/* verilator lint_on DECLFILENAME */

    // ------------------------------------------------------------ design point
    localparam integer ENC_MOD = ENCODINGS % 2;
    localparam integer ENC_REL = (ENCODINGS / 2) % 2;
    // built units (an encoding unit with no encoding built is not built)
    localparam integer B1 = (HAS_ESTIMATOR != 0) ? 1 : 0;
    localparam integer B2 = (HAS_COMPRESSOR != 0) ? 1 : 0;
    localparam integer B3 = (HAS_DECODER != 0 && (ENC_MOD + ENC_REL) != 0) ? 1 : 0;
    localparam integer B4 = (HAS_NP_ENCODER != 0 && (ENC_MOD + ENC_REL) != 0) ? 1 : 0;
    localparam integer B5 = (HAS_NP_DECODER != 0 && (ENC_MOD + ENC_REL) != 0) ? 1 : 0;
    localparam integer B6 = (HAS_RAY_BOX != 0) ? 1 : 0;
    localparam integer B7 = (HAS_RAY_TRI != 0) ? 1 : 0;
    localparam integer B8 = (HAS_QBVH_STACK != 0) ? 1 : 0;
    localparam integer B9 = (HAS_RAY_SPHERE != 0) ? 1 : 0;
    localparam [31:0] UNITS_MASK = (B1 << 1) | (B2 << 2) | (B3 << 3) | (B4 << 4) |
                                   (B5 << 5) | (B6 << 6) | (B7 << 7) | (B8 << 8) | (B9 << 9);

    // shapes (rtl-model/src/units/unit_table.c): input and output words per unit
    localparam integer NIN1 = 2,  NOUT1 = 2;
    localparam integer NIN2 = 4,  NOUT2 = 6;
    localparam integer NIN3 = 6,  NOUT3 = 6;
    localparam integer NIN4 = 28, NOUT4 = (N <= 6) ? 5 : 7;
    localparam integer NIN5 = (N <= 6) ? 16 : 18, NOUT5 = 35;
    localparam integer NIN6 = 21, NOUT6 = 4;
    localparam integer NIN7 = 15, NOUT7 = 5;
    localparam integer NIN8 = 8,  NOUT8 = 6;
    localparam integer NIN9 = 12, NOUT9 = 2;

    function integer max2;
        input integer a, b;
        max2 = (a > b) ? a : b;
    endfunction
    // IN words stored, OUT words latched: the largest over the built units
    // (at least one, so that no vector has width zero)
    localparam integer IN_WORDS =
        max2(1, max2(max2(max2(B1 * NIN1, B2 * NIN2), max2(B3 * NIN3, B4 * NIN4)),
                     max2(max2(B5 * NIN5, B6 * NIN6), max2(B7 * NIN7, max2(B8 * NIN8, B9 * NIN9)))));
    localparam integer OUT_WORDS =
        max2(1, max2(max2(max2(B1 * NOUT1, B2 * NOUT2), max2(B3 * NOUT3, B4 * NOUT4)),
                     max2(max2(B5 * NOUT5, B6 * NOUT6), max2(B7 * NOUT7, max2(B8 * NOUT8, B9 * NOUT9)))));

    localparam [31:0] N_W = N;          // 32-bit copies to take the field bits from
    localparam [31:0] E_MIN_W = E_MIN;

    // ---------------------------------------------------------- word addresses
    localparam [15:0] A_ID = 16'h0000, A_VERSION = 16'h0001, A_UNITS = 16'h0002,
                      A_CONFIG = 16'h0003, A_UNIT_SEL = 16'h0004, A_SHAPE = 16'h0005,
                      A_CTRL = 16'h0006, A_STATUS = 16'h0007;
    localparam [9:0]  A_IN_HI = 10'h001, A_OUT_HI = 10'h002;  // addr[15:6] of IN[i], OUT[i]
    localparam [31:0] ID_VALUE = 32'h48564243, VERSION = 32'd1;
    localparam [2:0]  ST_BUSY = 3'b001, ST_DONE = 3'b010, ST_ERROR = 3'b100;
    localparam [3:0]  RECAPTURE = 4'd8;

    // ---------------------------------------------------------------- registers
    reg  [31:0]             config_r, unit_sel;
    reg  [2:0]              status;
    // IN[i] = in_w[32i +: 32]. A word is stored as written; the bits above
    // its field's width are read by no unit (the unit testbenches truncate
    // the same way), and synthesis removes them.
    /* verilator lint_off UNUSEDSIGNAL */
    reg  [IN_WORDS*32-1:0] in_w;
    /* verilator lint_on UNUSEDSIGNAL */
    reg  [OUT_WORDS*32-1:0] out_w;      // OUT[i] = out_w[32i +: 32]
    reg                     start_req;  // a CTRL start, handled the clock after the write
    reg  [3:0]              recap;      // re-captures of a combinational unit still to do
    // the sequential unit that runs (one-hot), latched at its start so that a
    // UNIT_SEL write during the run cannot redirect the capture
    reg                     run6, run7, run9;

    wire ctrl_wr    = wr_en && (wr_addr == A_CTRL);
    wire ctrl_reset = ctrl_wr && wr_data[1];

    // ------------------------------------------------------------ acceptance
    wire cfg_ok = (config_r[7:0] == N_W[7:0]) && (config_r[23:8] == E_MIN_W[15:0]);
    wire rel    = config_r[24];
    wire enc_ok = rel ? (ENC_REL != 0) : (ENC_MOD != 0);
    // UNIT_SEL decoded when written (one id at a time; 0 for any other value)
    reg  sel1, sel2, sel3, sel4, sel5, sel6, sel7, sel8, sel9;
    wire acc1 = (B1 != 0) && cfg_ok;
    wire acc2 = (B2 != 0) && cfg_ok;
    wire acc3 = (B3 != 0) && cfg_ok && enc_ok;
    wire acc4 = (B4 != 0) && cfg_ok && enc_ok;
    wire acc5 = (B5 != 0) && cfg_ok && enc_ok;
    wire acc6 = (B6 != 0);
    wire acc7 = (B7 != 0);
    wire acc8 = (B8 != 0);
    wire acc9 = (B9 != 0);
    wire sel_acc = (sel1 && acc1) || (sel2 && acc2) || (sel3 && acc3) || (sel4 && acc4) ||
                   (sel5 && acc5) || (sel6 && acc6) || (sel7 && acc7) || (sel8 && acc8) || (sel9 && acc9);
    // a built sequential unit is selected
    wire sel_seq = (sel6 && acc6) || (sel7 && acc7) || (sel9 && acc9);

    // {n_out, n_in} of each unit, as 32-bit constants
    localparam [31:0] SH1 = NOUT1 * 256 + NIN1, SH2 = NOUT2 * 256 + NIN2,
                      SH3 = NOUT3 * 256 + NIN3, SH4 = NOUT4 * 256 + NIN4,
                      SH5 = NOUT5 * 256 + NIN5, SH6 = NOUT6 * 256 + NIN6,
                      SH7 = NOUT7 * 256 + NIN7, SH8 = NOUT8 * 256 + NIN8,
                      SH9 = NOUT9 * 256 + NIN9;
    wire [31:0] shape_u = ({32{sel1}} & SH1) | ({32{sel2}} & SH2) | ({32{sel3}} & SH3) |
                          ({32{sel4}} & SH4) | ({32{sel5}} & SH5) | ({32{sel6}} & SH6) |
                          ({32{sel7}} & SH7) | ({32{sel8}} & SH8) | ({32{sel9}} & SH9);
    wire [31:0] shape = sel_acc ? shape_u : 32'd0;

    // ------------------------------------------------------------------- units
    // Each built unit's outputs as OUT_WORDS zero-extended words; unbuilt: zero.
    wire [OUT_WORDS*32-1:0] u1_bus, u2_bus, u3_bus, u4_bus, u5_bus, u8_bus;
    wire [OUT_WORDS*32-1:0] rb_bus, rt_bus, rs_bus;
    wire                    rb_done, rt_done, rs_done;

    // a start is handled the clock after its CTRL write, after the reset of
    // the same write has zeroed IN (as the C model: reset, then start); a
    // start while busy is ignored
    wire start_go = start_req && !status[0];

    generate
        if (B1 != 0) begin : g_est
            wire [7:0] scale;
            wire [6:0] st;
            cbvh_scale_estimator #(.N(N), .E_MIN(E_MIN)) u_est (
                .lb(in_w[0*32 +: 32]), .ub(in_w[1*32 +: 32]), .scale(scale), .status(st));
            wire [NOUT1*32-1:0] o = {{25'd0, st}, {24'd0, scale}};
            cbvh_board_pad #(.NW(NOUT1), .OW(OUT_WORDS)) u_pad (.o(o), .bus(u1_bus));
        end else begin : g_no_est
            assign u1_bus = {OUT_WORDS*32{1'b0}};
        end

        if (B2 != 0) begin : g_cmp
            wire [N-1:0] lm, um;
            wire [7:0]   cs;
            wire [31:0]  clb, cub;
            wire [7:0]   st;
            cbvh_axis_compressor #(.N(N), .E_MIN(E_MIN)) u_cmp (
                .lb(in_w[0*32 +: 32]), .ub(in_w[1*32 +: 32]), .scale(in_w[2*32 +: 8]),
                .node_clb(in_w[3*32 +: 32]),
                .lb_mod(lm), .ub_mod(um), .child_scale(cs), .clb(clb), .cub(cub), .status(st));
            wire [NOUT2*32-1:0] o = {{24'd0, st}, cub, clb, {24'd0, cs},
                                     {{(32-N){1'b0}}, um}, {{(32-N){1'b0}}, lm}};
            cbvh_board_pad #(.NW(NOUT2), .OW(OUT_WORDS)) u_pad (.o(o), .bus(u2_bus));
        end else begin : g_no_cmp
            assign u2_bus = {OUT_WORDS*32{1'b0}};
        end

        // units with an encoding: one instance per built encoding, CONFIG[24]
        // picks (enc_ok has rejected an encoding that is not built)
        if (B3 != 0) begin : g_dec
            wire [NOUT3*32-1:0] o;
            cbvh_board_encoded #(.UNIT(3), .N(N), .E_MIN(E_MIN), .ENCODINGS(ENCODINGS),
                                 .NIN(NIN3), .NOUT(NOUT3)) u_enc (
                .in_w(in_w[0 +: NIN3*32]), .rel(rel), .o(o));
            cbvh_board_pad #(.NW(NOUT3), .OW(OUT_WORDS)) u_pad (.o(o), .bus(u3_bus));
        end else begin : g_no_dec
            assign u3_bus = {OUT_WORDS*32{1'b0}};
        end

        if (B4 != 0) begin : g_npe
            wire [NOUT4*32-1:0] o;
            cbvh_board_encoded #(.UNIT(4), .N(N), .E_MIN(E_MIN), .ENCODINGS(ENCODINGS),
                                 .NIN(NIN4), .NOUT(NOUT4)) u_enc (
                .in_w(in_w[0 +: NIN4*32]), .rel(rel), .o(o));
            cbvh_board_pad #(.NW(NOUT4), .OW(OUT_WORDS)) u_pad (.o(o), .bus(u4_bus));
        end else begin : g_no_npe
            assign u4_bus = {OUT_WORDS*32{1'b0}};
        end

        if (B5 != 0) begin : g_npd
            wire [NOUT5*32-1:0] o;
            cbvh_board_encoded #(.UNIT(5), .N(N), .E_MIN(E_MIN), .ENCODINGS(ENCODINGS),
                                 .NIN(NIN5), .NOUT(NOUT5)) u_enc (
                .in_w(in_w[0 +: NIN5*32]), .rel(rel), .o(o));
            cbvh_board_pad #(.NW(NOUT5), .OW(OUT_WORDS)) u_pad (.o(o), .bus(u5_bus));
        end else begin : g_no_npd
            assign u5_bus = {OUT_WORDS*32{1'b0}};
        end

        if (B6 != 0) begin : g_rb
            wire        busy_unused;  // STATUS.busy is kept here, from start to done
            wire        rb_start = start_go && sel6 && acc6;
            wire        rb_rst   = rst || ctrl_reset;   // CTRL reset aborts a run
            wire        hit;
            wire [31:0] t_near, t_far;
            wire [7:0]  st;
            cbvh_ray_box u_rb (
                .clk(clk), .rst(rb_rst), .start(rb_start), .busy(busy_unused), .done(rb_done),
                .ox(in_w[0*32 +: 32]), .oy(in_w[1*32 +: 32]), .oz(in_w[2*32 +: 32]),
                .dx(in_w[3*32 +: 32]), .dy(in_w[4*32 +: 32]), .dz(in_w[5*32 +: 32]),
                .tmin(in_w[6*32 +: 32]), .tmax(in_w[7*32 +: 32]), .mant(in_w[8*32 +: 8]),
                .x_u(in_w[9*32 +: 32]),  .x_scale(in_w[10*32 +: 8]), .x_r(in_w[11*32 +: 12]), .x_s(in_w[12*32 +: 12]),
                .y_u(in_w[13*32 +: 32]), .y_scale(in_w[14*32 +: 8]), .y_r(in_w[15*32 +: 12]), .y_s(in_w[16*32 +: 12]),
                .z_u(in_w[17*32 +: 32]), .z_scale(in_w[18*32 +: 8]), .z_r(in_w[19*32 +: 12]), .z_s(in_w[20*32 +: 12]),
                .hit(hit), .t_near(t_near), .t_far(t_far), .status(st));
            wire [NOUT6*32-1:0] o = {{24'd0, st}, t_far, t_near, {31'd0, hit}};
            cbvh_board_pad #(.NW(NOUT6), .OW(OUT_WORDS)) u_pad (.o(o), .bus(rb_bus));
        end else begin : g_no_rb
            assign rb_bus  = {OUT_WORDS*32{1'b0}};
            assign rb_done = 1'b0;
        end

        if (B7 != 0) begin : g_rt
            wire        busy_unused;  // STATUS.busy is kept here, from start to done
            wire        rt_start = start_go && sel7 && acc7;
            wire        rt_rst   = rst || ctrl_reset;   // CTRL reset aborts a run
            wire        hit;
            wire [31:0] t, b1, b2;
            wire [7:0]  st;
            cbvh_ray_triangle u_rt (
                .clk(clk), .rst(rt_rst), .start(rt_start), .busy(busy_unused), .done(rt_done),
                .ox(in_w[0*32 +: 32]), .oy(in_w[1*32 +: 32]), .oz(in_w[2*32 +: 32]),
                .dx(in_w[3*32 +: 32]), .dy(in_w[4*32 +: 32]), .dz(in_w[5*32 +: 32]),
                .v0x(in_w[6*32 +: 32]), .v0y(in_w[7*32 +: 32]), .v0z(in_w[8*32 +: 32]),
                .v1x(in_w[9*32 +: 32]), .v1y(in_w[10*32 +: 32]), .v1z(in_w[11*32 +: 32]),
                .v2x(in_w[12*32 +: 32]), .v2y(in_w[13*32 +: 32]), .v2z(in_w[14*32 +: 32]),
                .hit(hit), .t(t), .b1(b1), .b2(b2), .status(st));
            wire [NOUT7*32-1:0] o = {{24'd0, st}, b2, b1, t, {31'd0, hit}};
            cbvh_board_pad #(.NW(NOUT7), .OW(OUT_WORDS)) u_pad (.o(o), .bus(rt_bus));
        end else begin : g_no_rt
            assign rt_bus  = {OUT_WORDS*32{1'b0}};
            assign rt_done = 1'b0;
        end

        if (B8 != 0) begin : g_qbvh
            wire [31:0] node, next_entry;
            wire        write;
            wire [7:0]  order, st;
            wire [3:0]  nhit;
            cbvh_qbvh_stack u_qbvh (
                .op(in_w[0*32 +: 4]), .first(in_w[1*32 +: 32]), .hit_mask(in_w[2*32 +: 4]),
                .t0(in_w[3*32 +: 32]), .t1(in_w[4*32 +: 32]), .t2(in_w[5*32 +: 32]),
                .t3(in_w[6*32 +: 32]), .entry(in_w[7*32 +: 32]),
                .node(node), .next_entry(next_entry), .write(write), .order(order),
                .nhit(nhit), .status(st));
            wire [NOUT8*32-1:0] o = {{24'd0, st}, {28'd0, nhit}, {24'd0, order}, {31'd0, write},
                                     next_entry, node};
            cbvh_board_pad #(.NW(NOUT8), .OW(OUT_WORDS)) u_pad (.o(o), .bus(u8_bus));
        end else begin : g_no_qbvh
            assign u8_bus = {OUT_WORDS*32{1'b0}};
        end

        if (B9 != 0) begin : g_rs
            wire        busy_unused;  // STATUS.busy is kept here, from start to done
            wire        rs_start = start_go && sel9 && acc9;
            wire        rs_rst   = rst || ctrl_reset;   // CTRL reset aborts a run
            wire        hit;
            wire [7:0]  st;
            cbvh_ray_sphere u_rs (
                .clk(clk), .rst(rs_rst), .start(rs_start), .busy(busy_unused), .done(rs_done),
                .ox(in_w[0*32 +: 32]), .oy(in_w[1*32 +: 32]), .oz(in_w[2*32 +: 32]),
                .dx(in_w[3*32 +: 32]), .dy(in_w[4*32 +: 32]), .dz(in_w[5*32 +: 32]),
                .tmin(in_w[6*32 +: 32]), .tmax(in_w[7*32 +: 32]),
                .cx(in_w[8*32 +: 32]), .cy(in_w[9*32 +: 32]), .cz(in_w[10*32 +: 32]),
                .r(in_w[11*32 +: 32]),
                .hit(hit), .status(st));
            wire [NOUT9*32-1:0] o = {{24'd0, st}, {31'd0, hit}};
            cbvh_board_pad #(.NW(NOUT9), .OW(OUT_WORDS)) u_pad (.o(o), .bus(rs_bus));
        end else begin : g_no_rs
            assign rs_bus  = {OUT_WORDS*32{1'b0}};
            assign rs_done = 1'b0;
        end
    endgenerate

    // the selected combinational unit's outputs (UNIT_SEL is one id at a time)
    localparam integer OB = OUT_WORDS * 32;
    wire [OB-1:0] comb_bus = ({OB{sel1}} & u1_bus) | ({OB{sel2}} & u2_bus) | ({OB{sel3}} & u3_bus) |
                             ({OB{sel4}} & u4_bus) | ({OB{sel5}} & u5_bus) | ({OB{sel8}} & u8_bus);

    // ------------------------------------------------------------ IN writes
    // Bits of IN words that no unit reads have no load and are removed by
    // synthesis, so only the used bits are stored.
    integer i;
    always @(posedge clk) begin
        if (rst || ctrl_reset)
            in_w <= {IN_WORDS*32{1'b0}};
        else if (wr_en && wr_addr[15:6] == A_IN_HI)
            for (i = 0; i < IN_WORDS; i = i + 1)
                if ({26'd0, wr_addr[5:0]} == i)
                    in_w[32*i +: 32] <= wr_data;
    end

    // ------------------------------------------- CONFIG, UNIT_SEL, CTRL, STATUS
    always @(posedge clk) begin
        if (rst) begin
            config_r <= 32'd0;
            unit_sel <= 32'd0;
            {sel1, sel2, sel3, sel4, sel5, sel6, sel7, sel8, sel9} <= 9'd0;
        end else if (wr_en) begin
            if (wr_addr == A_CONFIG) config_r <= wr_data;
            if (wr_addr == A_UNIT_SEL) begin
                unit_sel <= wr_data;
                sel1 <= (wr_data == 32'd1);
                sel2 <= (wr_data == 32'd2);
                sel3 <= (wr_data == 32'd3);
                sel4 <= (wr_data == 32'd4);
                sel5 <= (wr_data == 32'd5);
                sel6 <= (wr_data == 32'd6);
                sel7 <= (wr_data == 32'd7);
                sel8 <= (wr_data == 32'd8);
                sel9 <= (wr_data == 32'd9);
            end
        end
    end

    // OUT latches a combinational unit's outputs (start, then re-captures)
    // or, when its done pulses, those of the sequential unit that was started
    wire cap_seq  = (run6 && rb_done) || (run7 && rt_done) || (run9 && rs_done);
    wire cap_comb = (start_go && sel_acc && !sel_seq) || (recap != 4'd0);
    wire [OB-1:0] seq_bus = ({OB{run6}} & rb_bus) | ({OB{run7}} & rt_bus) | ({OB{run9}} & rs_bus);

    always @(posedge clk) begin
        start_req <= !rst && ctrl_wr && wr_data[0];
        if (rst || ctrl_reset) begin
            status <= 3'd0;
            recap  <= 4'd0;
            run6   <= 1'b0;
            run7   <= 1'b0;
            run9   <= 1'b0;
        end else begin
            if (recap != 4'd0)
                recap <= recap - 4'd1;
            if (cap_seq) begin
                status <= ST_DONE;
                run6   <= 1'b0;
                run7   <= 1'b0;
                run9   <= 1'b0;
            end
            if (start_go) begin
                if (!sel_acc) begin
                    status <= ST_DONE | ST_ERROR;  // OUT unchanged, as the C model
                end else if (sel_seq) begin
                    status <= ST_BUSY;             // the unit's start pulses now
                    run6   <= sel6;
                    run7   <= sel7;
                    run9   <= sel9;
                end else begin
                    status <= ST_DONE;
                    recap  <= RECAPTURE;
                end
            end
        end
    end

    // OUT: one enable, so that each bit is a flip-flop with enable and reset
    always @(posedge clk) begin
        if (rst || ctrl_reset)
            out_w <= {OUT_WORDS*32{1'b0}};
        else if (cap_seq || cap_comb)
            out_w <= cap_seq ? seq_bus : comb_bus;
    end

    // ----------------------------------------------------------------- reads
    reg [31:0] rd_val;
    integer j;
    always @* begin
        rd_val = 32'd0;
        case (rd_addr)
            A_ID:       rd_val = ID_VALUE;
            A_VERSION:  rd_val = VERSION;
            A_UNITS:    rd_val = UNITS_MASK;
            A_CONFIG:   rd_val = config_r;
            A_UNIT_SEL: rd_val = unit_sel;
            A_SHAPE:    rd_val = shape;
            A_STATUS:   rd_val = {29'd0, status};
            default:
                if (rd_addr[15:6] == A_OUT_HI)
                    for (j = 0; j < OUT_WORDS; j = j + 1)
                        if ({26'd0, rd_addr[5:0]} == j)
                            rd_val = out_w[32*j +: 32];
        endcase
    end

    always @(posedge clk) begin
        if (rst)
            rd_data <= 32'd0;
        else if (rd_en)
            rd_data <= rd_val;
    end
endmodule

// A unit's NW output words, zero-padded to the OW words of the OUT buffer.
module cbvh_board_pad #(
    parameter integer NW = 1,
    parameter integer OW = 1
) (
    input  wire [NW*32-1:0] o,
    output wire [OW*32-1:0] bus
);
    genvar k;
    generate
        for (k = 0; k < OW; k = k + 1) begin : g_w
            if (k < NW) begin : g_u assign bus[32*k +: 32] = o[32*k +: 32]; end
            else begin : g_z assign bus[32*k +: 32] = 32'd0; end
        end
    endgenerate
endmodule

// A unit with an encoding (3 axis decoder, 4 node-pair encoder, 5 node-pair
// decoder): one instance per built encoding (ENCODINGS bit 0 modulo, bit 1
// relative); rel picks.
module cbvh_board_encoded #(
    parameter integer UNIT      = 3,
    parameter integer N         = 6,
    parameter integer E_MIN     = -30,
    parameter integer ENCODINGS = 1,
    parameter integer NIN       = 6,
    parameter integer NOUT      = 6
) (
    input  wire [NIN*32-1:0]  in_w,
    input  wire               rel,
    output wire [NOUT*32-1:0] o
);
    localparam integer W = NOUT * 32;
    wire [2*W-1:0] o_enc;  // [W +: W] modulo, [0 +: W] relative
    genvar m;
    generate
        for (m = 0; m < 2; m = m + 1) begin : g_enc
            if ((ENCODINGS >> (1 - m)) % 2 == 0) begin : g_off
                assign o_enc[m*W +: W] = {W{1'b0}};
            end else if (UNIT == 3) begin : g_dec
                cbvh_board_axis_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(m)) u (.in_w(in_w), .o(o_enc[m*W +: W]));
            end else if (UNIT == 4) begin : g_npe
                cbvh_board_np_encoder #(.N(N), .E_MIN(E_MIN), .MODULO(m), .NOUT(NOUT)) u (
                    .in_w(in_w), .o(o_enc[m*W +: W]));
            end else begin : g_npd
                cbvh_board_np_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(m), .NIN(NIN)) u (
                    .in_w(in_w), .o(o_enc[m*W +: W]));
            end
        end
    endgenerate
    assign o = rel ? o_enc[0 +: W] : o_enc[W +: W];
endmodule

// Unit 3 on IN/OUT words (fields in the vector file's order, outputs
// zero-extended): parent_scale scale node_lb_mod node_clb lb_code ub_code ->
// lb_mod ub_mod child_scale clb cub status.
module cbvh_board_axis_decoder #(
    parameter integer N = 6, parameter integer E_MIN = -30, parameter integer MODULO = 1
) (
    /* verilator lint_off UNUSEDSIGNAL */ // bits above each field's width
    input  wire [6*32-1:0] in_w,
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [6*32-1:0] o
);
    wire [N-1:0] lm, um;
    wire [7:0]   cs;
    wire [31:0]  clb, cub;
    wire [6:0]   st;
    cbvh_axis_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) u (
        .parent_scale(in_w[0*32 +: 8]), .scale(in_w[1*32 +: 8]), .node_lb_mod(in_w[2*32 +: 12]),
        .node_clb(in_w[3*32 +: 32]), .lb_code(in_w[4*32 +: 12]), .ub_code(in_w[5*32 +: 12]),
        .lb_mod(lm), .ub_mod(um), .child_scale(cs), .clb(clb), .cub(cub), .status(st));
    assign o = {{25'd0, st}, cub, clb, {24'd0, cs}, {{(32-N){1'b0}}, um}, {{(32-N){1'b0}}, lm}};
endmodule

// Unit 4 on IN/OUT words: the 12 context fields (x, y, z: parent_scale scale
// node_lb_mod node_clb), then per child lo_x hi_x lo_y hi_y lo_z hi_z flags
// ptr -> word0..word3 (N <= 6) or word0..word5 (N >= 7), status.
module cbvh_board_np_encoder #(
    parameter integer N = 6, parameter integer E_MIN = -30, parameter integer MODULO = 1,
    parameter integer NOUT = 5
) (
    /* verilator lint_off UNUSEDSIGNAL */ // bits above each field's width
    input  wire [28*32-1:0]   in_w,
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [NOUT*32-1:0] o
);
    wire [31:0] w0, w1, w2, w3, w4, w5;
    wire [7:0]  st;
    cbvh_nodepair_encoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) u (
        .x_parent_scale(in_w[0*32 +: 8]), .x_scale(in_w[1*32 +: 8]),
        .x_node_lb_mod(in_w[2*32 +: 12]), .x_node_clb(in_w[3*32 +: 32]),
        .y_parent_scale(in_w[4*32 +: 8]), .y_scale(in_w[5*32 +: 8]),
        .y_node_lb_mod(in_w[6*32 +: 12]), .y_node_clb(in_w[7*32 +: 32]),
        .z_parent_scale(in_w[8*32 +: 8]), .z_scale(in_w[9*32 +: 8]),
        .z_node_lb_mod(in_w[10*32 +: 12]), .z_node_clb(in_w[11*32 +: 32]),
        .c0_lo_x(in_w[12*32 +: 32]), .c0_hi_x(in_w[13*32 +: 32]),
        .c0_lo_y(in_w[14*32 +: 32]), .c0_hi_y(in_w[15*32 +: 32]),
        .c0_lo_z(in_w[16*32 +: 32]), .c0_hi_z(in_w[17*32 +: 32]),
        .c0_flags(in_w[18*32 +: 4]), .c0_ptr(in_w[19*32 +: 32]),
        .c1_lo_x(in_w[20*32 +: 32]), .c1_hi_x(in_w[21*32 +: 32]),
        .c1_lo_y(in_w[22*32 +: 32]), .c1_hi_y(in_w[23*32 +: 32]),
        .c1_lo_z(in_w[24*32 +: 32]), .c1_hi_z(in_w[25*32 +: 32]),
        .c1_flags(in_w[26*32 +: 4]), .c1_ptr(in_w[27*32 +: 32]),
        .word0(w0), .word1(w1), .word2(w2), .word3(w3), .word4(w4), .word5(w5), .status(st));
    generate
        if (N <= 6) begin : g_w4
            // a 16-byte pair: word4 and word5 are zero and not output words
            /* verilator lint_off UNUSEDSIGNAL */
            wire [63:0] unused_w45 = {w5, w4};
            /* verilator lint_on UNUSEDSIGNAL */
            assign o = {{24'd0, st}, w3, w2, w1, w0};
        end else begin : g_w6
            assign o = {{24'd0, st}, w5, w4, w3, w2, w1, w0};
        end
    endgenerate
endmodule

// Unit 5 on IN/OUT words: the 12 context fields, word0..word3 (N <= 6) or
// word0..word5 (N >= 7) -> per child c0, c1: flags ptr, then per axis x, y, z
// lb_mod ub_mod child_scale clb cub; status (35 words).
module cbvh_board_np_decoder #(
    parameter integer N = 6, parameter integer E_MIN = -30, parameter integer MODULO = 1,
    parameter integer NIN = 16
) (
    /* verilator lint_off UNUSEDSIGNAL */ // bits above each field's width
    input  wire [NIN*32-1:0] in_w,
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [35*32-1:0]  o
);
    wire [31:0] w4, w5;
    generate
        if (N <= 6) begin : g_w4
            assign w4 = 32'd0;
            assign w5 = 32'd0;
        end else begin : g_w6
            assign w4 = in_w[16*32 +: 32];
            assign w5 = in_w[17*32 +: 32];
        end
    endgenerate

    wire [1:0]   f0, f1;
    wire [31:0]  p0, p1;
    wire [N-1:0] lm [0:5];
    wire [N-1:0] um [0:5];
    wire [7:0]   cs [0:5];
    wire [31:0]  lb [0:5];
    wire [31:0]  ub [0:5];
    wire [6:0]   st;
    cbvh_nodepair_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) u (
        .x_parent_scale(in_w[0*32 +: 8]), .x_scale(in_w[1*32 +: 8]),
        .x_node_lb_mod(in_w[2*32 +: 12]), .x_node_clb(in_w[3*32 +: 32]),
        .y_parent_scale(in_w[4*32 +: 8]), .y_scale(in_w[5*32 +: 8]),
        .y_node_lb_mod(in_w[6*32 +: 12]), .y_node_clb(in_w[7*32 +: 32]),
        .z_parent_scale(in_w[8*32 +: 8]), .z_scale(in_w[9*32 +: 8]),
        .z_node_lb_mod(in_w[10*32 +: 12]), .z_node_clb(in_w[11*32 +: 32]),
        .word0(in_w[12*32 +: 32]), .word1(in_w[13*32 +: 32]),
        .word2(in_w[14*32 +: 32]), .word3(in_w[15*32 +: 32]), .word4(w4), .word5(w5),
        .c0_flags(f0), .c0_ptr(p0),
        .c0_x_lb_mod(lm[0]), .c0_x_ub_mod(um[0]), .c0_x_child_scale(cs[0]), .c0_x_clb(lb[0]), .c0_x_cub(ub[0]),
        .c0_y_lb_mod(lm[1]), .c0_y_ub_mod(um[1]), .c0_y_child_scale(cs[1]), .c0_y_clb(lb[1]), .c0_y_cub(ub[1]),
        .c0_z_lb_mod(lm[2]), .c0_z_ub_mod(um[2]), .c0_z_child_scale(cs[2]), .c0_z_clb(lb[2]), .c0_z_cub(ub[2]),
        .c1_flags(f1), .c1_ptr(p1),
        .c1_x_lb_mod(lm[3]), .c1_x_ub_mod(um[3]), .c1_x_child_scale(cs[3]), .c1_x_clb(lb[3]), .c1_x_cub(ub[3]),
        .c1_y_lb_mod(lm[4]), .c1_y_ub_mod(um[4]), .c1_y_child_scale(cs[4]), .c1_y_clb(lb[4]), .c1_y_cub(ub[4]),
        .c1_z_lb_mod(lm[5]), .c1_z_ub_mod(um[5]), .c1_z_child_scale(cs[5]), .c1_z_clb(lb[5]), .c1_z_cub(ub[5]),
        .status(st));

    // per child: flags, ptr, then 5 words for each of its three axes (17 words)
    genvar a;
    generate
        for (a = 0; a < 6; a = a + 1) begin : g_ax
            localparam integer W = (a < 3) ? (2 + 5 * a) : (17 + 2 + 5 * (a - 3));
            assign o[(W + 0)*32 +: 32] = {{(32-N){1'b0}}, lm[a]};
            assign o[(W + 1)*32 +: 32] = {{(32-N){1'b0}}, um[a]};
            assign o[(W + 2)*32 +: 32] = {24'd0, cs[a]};
            assign o[(W + 3)*32 +: 32] = lb[a];
            assign o[(W + 4)*32 +: 32] = ub[a];
        end
    endgenerate
    assign o[0*32 +: 32]  = {30'd0, f0};
    assign o[1*32 +: 32]  = p0;
    assign o[17*32 +: 32] = {30'd0, f1};
    assign o[18*32 +: 32] = p1;
    assign o[34*32 +: 32] = {25'd0, st};
endmodule

`default_nettype wire
