// Smoke test of cbvh_board_top through its SPI pins (Icarus, self-checking):
// the testbench is the SPI master of firmware/ports/rp2040_ice40/spi_regmap.c
// (mode 0, byte addresses sent as addr >> 10, addr >> 2) at SCK = clk / 8,
// the fastest SCK the slave supports (high and low phases of 4 clk), with its
// edges offset from clk's. It checks ID, VERSION, UNITS, CONFIG and UNIT_SEL
// readback, SHAPE of every unit id, the first vector lines of
// axis_compress / ray_box / qbvh_stack / ray_sphere / ray_triangle -N6-ms-30.vec (plus their
// second lines) through IN, CTRL, STATUS and OUT, that OUT is latched, CTRL
// reset (also aborting a sequential unit), that a UNIT_SEL write while the
// ray sphere runs does not change what OUT captures, start on an unbuilt or
// unaccepted unit, unknown addresses, a bad command byte, and transactions
// cut short by CS high or run past 7 bytes. $fatal on any mismatch;
// "tb_board_smoke: PASS" at the end.
//   iverilog -g2005 -s tb_board_smoke -o tb.vvp gateware/board/*.v gateware/rtl/*.v && vvp tb.vvp
//   (-P tb_board_smoke.HAS_RAY_BOX=0 etc.: unbuilt units vanish from UNITS and SHAPE)
`default_nettype none

module tb_board_smoke;
    parameter integer ENCODINGS      = 1;
    parameter integer HAS_ESTIMATOR  = 1;
    parameter integer HAS_COMPRESSOR = 1;
    parameter integer HAS_DECODER    = 1;
    parameter integer HAS_NP_ENCODER = 1;
    parameter integer HAS_NP_DECODER = 1;
    parameter integer HAS_RAY_BOX    = 1;
    parameter integer HAS_RAY_TRI    = 1;
    parameter integer HAS_QBVH_STACK = 1;
    parameter integer HAS_RAY_SPHERE = 1;
    parameter integer HALF           = 40;   // SCK half period; clk period 10
    parameter integer PHASE          = 3;    // SCK edges this far after a clk edge

    // byte addresses (firmware/include/cbvh_fw/regmap.h)
    localparam [31:0] R_ID = 32'h000, R_VERSION = 32'h004, R_UNITS = 32'h008, R_CONFIG = 32'h00C,
                      R_UNIT_SEL = 32'h010, R_SHAPE = 32'h014, R_CTRL = 32'h018, R_STATUS = 32'h01C;
    localparam [31:0] CFG_GOOD = 32'h00FFE206;   // N 6, min_scale -30, modulo
    localparam [31:0] CFG_REL  = 32'h01FFE206;   // relative
    localparam [31:0] CFG_N7   = 32'h00FFE207;   // wrong N
    localparam [31:0] CFG_MS   = 32'h00FFE306;   // wrong min_scale (-29)

    localparam integer ENC_MOD = ENCODINGS % 2, ENC_REL = (ENCODINGS / 2) % 2;
    localparam integer B1 = HAS_ESTIMATOR != 0, B2 = HAS_COMPRESSOR != 0,
                       B3 = HAS_DECODER != 0 && ENCODINGS % 4 != 0,
                       B4 = HAS_NP_ENCODER != 0 && ENCODINGS % 4 != 0,
                       B5 = HAS_NP_DECODER != 0 && ENCODINGS % 4 != 0,
                       B6 = HAS_RAY_BOX != 0, B7 = HAS_RAY_TRI != 0, B8 = HAS_QBVH_STACK != 0,
                       B9 = HAS_RAY_SPHERE != 0;
    localparam [31:0] UNITS_EXP = (B1 << 1) | (B2 << 2) | (B3 << 3) | (B4 << 4) | (B5 << 5) |
                                  (B6 << 6) | (B7 << 7) | (B8 << 8) | (B9 << 9);

    reg  clk = 1'b0;
    always #5 clk = ~clk;
    reg  sck = 1'b0, cs_n = 1'b1, mosi = 1'b0;
    wire miso;

    cbvh_board_top #(
        .N(6), .E_MIN(-30), .ENCODINGS(ENCODINGS),
        .HAS_ESTIMATOR(HAS_ESTIMATOR), .HAS_COMPRESSOR(HAS_COMPRESSOR), .HAS_DECODER(HAS_DECODER),
        .HAS_NP_ENCODER(HAS_NP_ENCODER), .HAS_NP_DECODER(HAS_NP_DECODER),
        .HAS_RAY_BOX(HAS_RAY_BOX), .HAS_RAY_TRI(HAS_RAY_TRI), .HAS_QBVH_STACK(HAS_QBVH_STACK),
        .HAS_RAY_SPHERE(HAS_RAY_SPHERE)
    ) dut (.clk(clk), .spi_sck(sck), .spi_cs_n(cs_n), .spi_mosi(mosi), .spi_miso(miso));

    // reference: the compressor on all-zero inputs (for CTRL = reset | start)
    wire [5:0]  z_lm, z_um;
    wire [7:0]  z_cs;
    wire [31:0] z_clb, z_cub;
    wire [7:0]  z_st;
    cbvh_axis_compressor #(.N(6), .E_MIN(-30)) ref_cmp (
        .lb(32'd0), .ub(32'd0), .scale(8'd0), .node_clb(32'd0), .lb_mod(z_lm), .ub_mod(z_um),
        .child_scale(z_cs), .clb(z_clb), .cub(z_cub), .status(z_st));

    integer nchecks = 0;
    task check;
        input [8*40-1:0] what;
        input [31:0] got, exp;
        begin
            nchecks = nchecks + 1;
            if (got !== exp)
                $fatal(1, "tb_board_smoke: %0s: got %08h, expected %08h", what, got, exp);
        end
    endtask

    // ------------------------------------------------------------ SPI master
    // mode 0: MOSI set while SCK is low, both sides sample on the rising edge
    task spi_byte;
        input  [7:0] tx;
        output [7:0] rx;
        integer b;
        begin
            for (b = 7; b >= 0; b = b - 1) begin
                mosi = tx[b];
                #(HALF) sck = 1'b1;
                rx[b] = miso;
                #(HALF) sck = 1'b0;
            end
        end
    endtask

    task cs_low;
        begin
            @(posedge clk);
            #(PHASE) cs_n = 1'b0;
            #(HALF);
        end
    endtask

    task cs_high;
        begin
            cs_n = 1'b1;
            #(2 * HALF);
        end
    endtask

    // the first nbytes of a transaction (cmd, address, 4 data bytes, then
    // zeros), then CS high; MISO must stay 0 (no read data)
    task spi_raw;
        input [7:0]  cmd;
        input [31:0] addr;   // byte address
        input [31:0] data;
        input integer nbytes;
        reg [7:0] bytes [0:8];
        reg [7:0] rx;
        integer k;
        begin
            bytes[0] = cmd; bytes[1] = addr[17:10]; bytes[2] = addr[9:2];
            bytes[3] = data[7:0]; bytes[4] = data[15:8]; bytes[5] = data[23:16]; bytes[6] = data[31:24];
            bytes[7] = 8'h5A; bytes[8] = 8'hA5;
            cs_low;
            for (k = 0; k < nbytes; k = k + 1) begin
                spi_byte(bytes[k], rx);
                check("MISO outside read data", {24'd0, rx}, 32'd0);
            end
            cs_high;
        end
    endtask

    task reg_write;
        input [31:0] addr;
        input [31:0] data;
        begin
            spi_raw(8'h00, addr, data, 7);
        end
    endtask

    task reg_read;
        input  [31:0] addr;
        output [31:0] data;
        reg [7:0] rx;
        integer k;
        begin
            cs_low;
            spi_byte(8'h80, rx);        check("MISO in read cmd", {24'd0, rx}, 32'd0);
            spi_byte(addr[17:10], rx);  check("MISO in read addr", {24'd0, rx}, 32'd0);
            spi_byte(addr[9:2], rx);    check("MISO in read addr", {24'd0, rx}, 32'd0);
            spi_byte(8'h00, rx);        check("MISO in turnaround", {24'd0, rx}, 32'd0);
            data = 32'd0;
            for (k = 0; k < 4; k = k + 1) begin
                spi_byte(8'h00, rx);
                data = data | ({24'd0, rx} << (8 * k));
            end
            // slots past the data: MISO 0
            spi_byte(8'h00, rx);        check("MISO after read data", {24'd0, rx}, 32'd0);
            cs_high;
        end
    endtask

    task expect_reg;
        input [8*40-1:0] what;
        input [31:0] addr;
        input [31:0] exp;
        reg [31:0] v;
        begin
            reg_read(addr, v);
            check(what, v, exp);
        end
    endtask

    // start the selected unit, wait until not busy, expect STATUS = st
    task run;
        input [31:0] st;
        reg [31:0] v;
        integer polls;
        begin
            reg_write(R_CTRL, 32'd1);
            polls = 0;
            reg_read(R_STATUS, v);
            while (v[0] && polls < 1000) begin
                polls = polls + 1;
                reg_read(R_STATUS, v);
            end
            check("STATUS after start", v, st);
        end
    endtask

    // ------------------------------------------------------------- vectors
    reg [31:0] vin  [0:20];
    reg [31:0] vout [0:5];
    integer i, nin, nout, u, npolls;
    reg [31:0] v, shp;

    task run_vector;   // IN[0..nin) = vin, start, OUT[0..nout) == vout, OUT[nout..] 0
        begin
            for (i = 0; i < nin; i = i + 1) reg_write(32'h100 + 4 * i, vin[i]);
            run(32'd2);
            for (i = 0; i < nout; i = i + 1) expect_reg("OUT word", 32'h200 + 4 * i, vout[i]);
            expect_reg("OUT past n_out", 32'h200 + 4 * nout, 32'd0);
            expect_reg("OUT[63]", 32'h2FC, 32'd0);
        end
    endtask

    function [31:0] shape_exp;   // SHAPE of unit id uu under CONFIG cfg
        input integer uu;
        input [31:0] cfg;
        reg ok, enc;
        begin
            ok  = (cfg[23:0] == CFG_GOOD[23:0]);
            enc = cfg[24] ? (ENC_REL != 0) : (ENC_MOD != 0);
            case (uu)
                1: shape_exp = (B1 && ok) ? 32'h0202 : 0;
                2: shape_exp = (B2 && ok) ? 32'h0604 : 0;
                3: shape_exp = (B3 && ok && enc) ? 32'h0606 : 0;
                4: shape_exp = (B4 && ok && enc) ? 32'h051C : 0;
                5: shape_exp = (B5 && ok && enc) ? 32'h2310 : 0;
                6: shape_exp = B6 ? 32'h0415 : 0;
                7: shape_exp = B7 ? 32'h050F : 0;
                8: shape_exp = B8 ? 32'h0608 : 0;
                9: shape_exp = B9 ? 32'h020C : 0;
                default: shape_exp = 0;
            endcase
        end
    endfunction

    task check_shapes;
        input [31:0] cfg;
        begin
            reg_write(R_CONFIG, cfg);
            for (u = 0; u <= 10; u = u + 1) begin
                reg_write(R_UNIT_SEL, u);
                expect_reg("SHAPE", R_SHAPE, shape_exp(u, cfg));
            end
        end
    endtask

    initial begin
        #(200);   // past the power-on reset

        // identification
        expect_reg("ID", R_ID, 32'h48564243);
        expect_reg("VERSION", R_VERSION, 32'd1);
        expect_reg("UNITS", R_UNITS, UNITS_EXP);
        if (ENCODINGS == 1 && HAS_ESTIMATOR && HAS_COMPRESSOR && HAS_DECODER && HAS_NP_ENCODER &&
            HAS_NP_DECODER && HAS_RAY_BOX && HAS_RAY_TRI && HAS_QBVH_STACK && HAS_RAY_SPHERE)
            check("UNITS, all built", UNITS_EXP, 32'h3FE);
        expect_reg("STATUS after power-on", R_STATUS, 32'd0);

        // rw registers keep all 32 bits; read-only and unknown addresses
        reg_write(R_CONFIG, 32'hA5C3_1E0F);
        expect_reg("CONFIG readback", R_CONFIG, 32'hA5C3_1E0F);
        reg_write(R_UNIT_SEL, 32'h8000_0106);
        expect_reg("UNIT_SEL readback", R_UNIT_SEL, 32'h8000_0106);
        expect_reg("SHAPE, no such unit", R_SHAPE, 32'd0);
        reg_write(R_ID, 32'h1234_5678);
        expect_reg("ID after a write", R_ID, 32'h48564243);
        expect_reg("CTRL reads 0", R_CTRL, 32'd0);
        expect_reg("unknown 0x020", 32'h020, 32'd0);
        expect_reg("unknown 0x0FC", 32'h0FC, 32'd0);
        expect_reg("IN[0] reads 0", 32'h100, 32'd0);
        expect_reg("unknown 0x300", 32'h300, 32'd0);
        expect_reg("unknown 0x10000 (word 0x4000)", 32'h10000, 32'd0);
        expect_reg("unknown 0x3FFFC", 32'h3FFFC, 32'd0);

        // SHAPE of every id under the design point, relative, wrong N, wrong min_scale
        check_shapes(CFG_GOOD);
        check_shapes(CFG_REL);
        check_shapes(CFG_N7);
        check_shapes(CFG_MS);

        // a start on an unaccepted or unbuilt unit: done | error
        reg_write(R_CONFIG, CFG_N7);
        reg_write(R_UNIT_SEL, 32'd2);
        run(32'd6);
        reg_write(R_CONFIG, CFG_GOOD);
        reg_write(R_UNIT_SEL, 32'd10);
        run(32'd6);
        reg_write(R_UNIT_SEL, 32'h102);
        run(32'd6);
        reg_write(R_UNIT_SEL, 32'd0);
        run(32'd6);

        // axis_compress-N6-ms-30.vec, line 1
        reg_write(R_UNIT_SEL, 32'd2);
        if (B2) begin
            nin = 4; nout = 6;
            vin[0] = 32'h00000000; vin[1] = 32'h00000000; vin[2] = 32'hE2; vin[3] = 32'h00000000;
            vout[0] = 32'h000; vout[1] = 32'h001; vout[2] = 32'hE2;
            vout[3] = 32'h00000000; vout[4] = 32'h30800000; vout[5] = 32'h00;
            run_vector;
            // line 2 (same inputs but scale E3): OUT changes
            vin[2] = 32'hE3;
            vout[2] = 32'hE2; vout[4] = 32'h31000000;
            run_vector;
            // OUT is latched: a later IN write does not change it
            reg_write(32'h108, 32'hE2);
            expect_reg("OUT latched", 32'h210, 32'h31000000);
            // CTRL reset zeroes STATUS and OUT
            reg_write(R_CTRL, 32'd2);
            expect_reg("STATUS after reset", R_STATUS, 32'd0);
            for (i = 0; i < 6; i = i + 1) expect_reg("OUT after reset", 32'h200 + 4 * i, 32'd0);
            // reset | start: IN zeroed first, then the unit runs on zeros
            reg_write(32'h100, 32'h3F800000);
            reg_write(32'h104, 32'h40000000);
            reg_write(32'h108, 32'h01);
            reg_write(R_CTRL, 32'd3);
            expect_reg("STATUS after reset|start", R_STATUS, 32'd2);
            expect_reg("OUT0 on zeros", 32'h200, {26'd0, z_lm});
            expect_reg("OUT1 on zeros", 32'h204, {26'd0, z_um});
            expect_reg("OUT2 on zeros", 32'h208, {24'd0, z_cs});
            expect_reg("OUT3 on zeros", 32'h20C, z_clb);
            expect_reg("OUT4 on zeros", 32'h210, z_cub);
            expect_reg("OUT5 on zeros", 32'h214, {24'd0, z_st});
        end else begin
            run(32'd6);
        end

        // ray_box-N6-ms-30.vec, lines 1 (a miss) and 2 (a hit)
        reg_write(R_CTRL, 32'd2);
        reg_write(R_UNIT_SEL, 32'd6);
        if (B6) begin
            nin = 21; nout = 4;
            vin[0] = 32'hBF800000; vin[1] = 32'h3F000000; vin[2] = 32'h3F000000;
            vin[3] = 32'h3F800000; vin[4] = 32'hBF800000; vin[5] = 32'h80000000;
            vin[6] = 32'h00000000; vin[7] = 32'h7F800000; vin[8] = 32'h03;
            for (i = 0; i < 3; i = i + 1) begin
                vin[9 + 4 * i] = 32'h00000000; vin[10 + 4 * i] = 32'hFD;
                vin[11 + 4 * i] = 32'h000;     vin[12 + 4 * i] = 32'h008;
            end
            vout[0] = 32'd0; vout[1] = 32'h00000000; vout[2] = 32'h00000000; vout[3] = 32'h00;
            run_vector;
            vin[1] = 32'h3F800000; vin[7] = 32'h4B800000;
            vout[0] = 32'd1; vout[1] = 32'h3F800000; vout[2] = 32'h3F800000; vout[3] = 32'h00;
            // STATUS busy right after the start (looked at inside: an SPI read is slower)
            for (i = 0; i < nin; i = i + 1) reg_write(32'h100 + 4 * i, vin[i]);
            reg_write(R_CTRL, 32'd1);
            check("STATUS busy after ray-box start", {29'd0, dut.u_regs.status}, 32'd1);
            run_vector;
            // CTRL reset aborts a run: STATUS 0, OUT 0
            reg_write(R_CTRL, 32'd1);
            reg_write(R_CTRL, 32'd2);
            expect_reg("STATUS after abort", R_STATUS, 32'd0);
            expect_reg("OUT0 after abort", 32'h200, 32'd0);
            expect_reg("OUT1 after abort", 32'h204, 32'd0);
        end else begin
            run(32'd6);
        end

        // qbvh_stack-N6-ms-30.vec, lines 1 and 2
        reg_write(R_UNIT_SEL, 32'd8);
        reg_write(R_CONFIG, CFG_N7);   // the stack accepts any CONFIG
        if (B8) begin
            nin = 8; nout = 6;
            vin[0] = 32'h0; vin[1] = 32'h00000005; vin[2] = 32'h0; vin[3] = 32'h3F800000;
            vin[4] = 32'h40000000; vin[5] = 32'h40400000; vin[6] = 32'h40800000; vin[7] = 32'h00000000;
            vout[0] = 32'h00000000; vout[1] = 32'h00000000; vout[2] = 32'h0; vout[3] = 32'hE4;
            vout[4] = 32'h0; vout[5] = 32'h00;
            run_vector;
            vin[2] = 32'h1;
            vout[0] = 32'h00000005; vout[4] = 32'h1;
            run_vector;
        end else begin
            run(32'd6);
        end

        // ray_sphere-N6-ms-30.vec, lines 1 (a hit) and 2 (a miss); CONFIG is
        // still the wrong N: the sphere accepts any CONFIG
        reg_write(R_CTRL, 32'd2);
        reg_write(R_UNIT_SEL, 32'd9);
        if (B9) begin
            nin = 12; nout = 2;
            vin[0] = 32'hC0A00000; vin[1] = 32'h00000000; vin[2] = 32'h00000000;
            vin[3] = 32'h3F800000; vin[4] = 32'h00000000; vin[5] = 32'h00000000;
            vin[6] = 32'h00000000; vin[7] = 32'h7F800000;
            vin[8] = 32'h00000000; vin[9] = 32'h00000000; vin[10] = 32'h00000000;
            vin[11] = 32'h3F800000;
            vout[0] = 32'd1; vout[1] = 32'h00;
            for (i = 0; i < nin; i = i + 1) reg_write(32'h100 + 4 * i, vin[i]);
            reg_write(R_CTRL, 32'd1);
            check("STATUS busy after ray-sphere start", {29'd0, dut.u_regs.status}, 32'd1);
            run_vector;
            vin[3] = 32'hBF800000;
            vout[0] = 32'd0;
            run_vector;
            // line 745 takes 722 clocks, longer than the SPI write of UNIT_SEL
            // = 6 that follows its start: OUT still captures the sphere's hit
            vin[0] = 32'h0000B600; vin[1] = 32'h00018A00; vin[2] = 32'h00023000;
            vin[3] = 32'h2C000000; vin[4] = 32'h2C400000; vin[5] = 32'h2CC00000;
            vin[6] = 32'h00000000; vin[7] = 32'h0E400000;
            vin[8] = 32'h0000C800; vin[9] = 32'h00019000; vin[10] = 32'h00025800;
            vin[11] = 32'h00000E00;
            for (i = 0; i < nin; i = i + 1) reg_write(32'h100 + 4 * i, vin[i]);
            reg_write(R_CTRL, 32'd1);
            reg_write(R_UNIT_SEL, 32'd6);
            check("STATUS busy after UNIT_SEL write", {29'd0, dut.u_regs.status}, 32'd1);
            npolls = 0;
            reg_read(R_STATUS, v);
            while (v[0] && npolls < 1000) begin
                npolls = npolls + 1;
                reg_read(R_STATUS, v);
            end
            check("STATUS after a re-selected run", v, 32'd2);
            expect_reg("OUT0 after re-select (hit)", 32'h200, 32'd1);
            expect_reg("OUT1 after re-select (status)", 32'h204, 32'd0);
            expect_reg("OUT2 after re-select", 32'h208, 32'd0);
            expect_reg("OUT3 after re-select", 32'h20C, 32'd0);
            // CTRL reset aborts a sphere run: STATUS 0, OUT 0; then it runs again
            reg_write(R_UNIT_SEL, 32'd9);
            for (i = 0; i < nin; i = i + 1) reg_write(32'h100 + 4 * i, vin[i]);
            reg_write(R_CTRL, 32'd1);
            check("STATUS busy before the abort", {29'd0, dut.u_regs.status}, 32'd1);
            reg_write(R_CTRL, 32'd2);
            expect_reg("STATUS after sphere abort", R_STATUS, 32'd0);
            expect_reg("OUT0 after sphere abort", 32'h200, 32'd0);
            vout[0] = 32'd1; vout[1] = 32'h00;
            run_vector;
        end else begin
            run(32'd6);
        end

        // ray_triangle-N6-ms-30.vec, lines 1 (a hit) and 2 (a miss); any CONFIG
        reg_write(R_CONFIG, CFG_N7);
        reg_write(R_UNIT_SEL, 32'd7);
        if (B7) begin
            nin = 15; nout = 5;
            vin[0] = 32'h00000000; vin[1] = 32'h00000000; vin[2] = 32'h40000000;
            vin[3] = 32'h00000000; vin[4] = 32'h80000000; vin[5] = 32'hBF800000;
            vin[6] = 32'h00000000; vin[7] = 32'h00000000; vin[8] = 32'h00000000;
            vin[9] = 32'h3F800000; vin[10] = 32'h00000000; vin[11] = 32'h00000000;
            vin[12] = 32'h00000000; vin[13] = 32'h3F800000; vin[14] = 32'h00000000;
            vout[0] = 32'd1; vout[1] = 32'h40000000; vout[2] = 32'h0; vout[3] = 32'h0; vout[4] = 32'h00;
            run_vector;
            vin[3] = 32'h3EAAAAAB; vin[4] = 32'hBE800000;
            vout[0] = 32'd0; vout[1] = 32'h0;
            run_vector;
        end else begin
            run(32'd6);
        end

        // transactions cut short by CS high write nothing; a bad command
        // byte ignores the transaction; bytes past the 7th are ignored
        reg_write(R_CONFIG, CFG_GOOD);
        for (i = 0; i < 7; i = i + 1) spi_raw(8'h00, R_CONFIG, 32'h0000_0BAD, i);
        expect_reg("CONFIG after cut-short writes", R_CONFIG, CFG_GOOD);
        spi_raw(8'h01, R_CONFIG, 32'h0000_0BAD, 7);
        spi_raw(8'h40, R_CONFIG, 32'h0000_0BAD, 9);
        spi_raw(8'hFF, R_CONFIG, 32'h0000_0BAD, 9);
        expect_reg("CONFIG after bad commands", R_CONFIG, CFG_GOOD);
        spi_raw(8'h80, R_CONFIG, 32'h0000_0BAD, 2);   // read cut short
        expect_reg("CONFIG after a cut-short read", R_CONFIG, CFG_GOOD);
        spi_raw(8'h00, R_UNIT_SEL, 32'h0000_0003, 9);  // 2 extra bytes
        expect_reg("UNIT_SEL after a 9-byte write", R_UNIT_SEL, 32'd3);

        $display("tb_board_smoke: PASS (%0d checks; UNITS %03h, ENCODINGS %0d, SCK half period %0d, clk period 10)",
                 nchecks, UNITS_EXP[11:0], ENCODINGS, HALF);
        $finish;
    end

    initial begin
        #(50_000_000);
        $fatal(1, "tb_board_smoke: timeout");
    end
endmodule

`default_nettype wire
