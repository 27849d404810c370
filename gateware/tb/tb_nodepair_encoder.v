// Testbench for cbvh_nodepair_encoder: runs a golden vector file (docs/vectors.md).
//   iverilog -g2005 -P tb_nodepair_encoder.N=6 -P tb_nodepair_encoder.E_MIN=-30 \
//       -P tb_nodepair_encoder.MODULO=1 -s tb_nodepair_encoder -o tb \
//       gateware/tb/tb_nodepair_encoder.v gateware/rtl/*.v
//   vvp tb +vec=vectors/nodepair_encode-N6-ms-30-modulo.vec
module tb_nodepair_encoder;
    parameter integer N      = 6;
    parameter integer E_MIN  = -30;
    parameter integer MODULO = 1;
    localparam integer NWO = (N <= 6) ? 4 : 6;       // output words in the file
    localparam integer NIN = 28;                     // input fields

    reg  [7:0] x_parent_scale;
    reg  [7:0] x_scale;
    reg  [11:0] x_node_lb_mod;
    reg  [31:0] x_node_clb;
    reg  [7:0] y_parent_scale;
    reg  [7:0] y_scale;
    reg  [11:0] y_node_lb_mod;
    reg  [31:0] y_node_clb;
    reg  [7:0] z_parent_scale;
    reg  [7:0] z_scale;
    reg  [11:0] z_node_lb_mod;
    reg  [31:0] z_node_clb;
    reg  [31:0] c0_lo_x;
    reg  [31:0] c0_hi_x;
    reg  [31:0] c0_lo_y;
    reg  [31:0] c0_hi_y;
    reg  [31:0] c0_lo_z;
    reg  [31:0] c0_hi_z;
    reg  [3:0] c0_flags;
    reg  [31:0] c0_ptr;
    reg  [31:0] c1_lo_x;
    reg  [31:0] c1_hi_x;
    reg  [31:0] c1_lo_y;
    reg  [31:0] c1_hi_y;
    reg  [31:0] c1_lo_z;
    reg  [31:0] c1_hi_z;
    reg  [3:0] c1_flags;
    reg  [31:0] c1_ptr;
    wire [31:0] word0, word1, word2, word3, word4, word5;
    wire [7:0]  status;

    cbvh_nodepair_encoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) dut (
        .x_parent_scale(x_parent_scale),
        .x_scale(x_scale),
        .x_node_lb_mod(x_node_lb_mod),
        .x_node_clb(x_node_clb),
        .y_parent_scale(y_parent_scale),
        .y_scale(y_scale),
        .y_node_lb_mod(y_node_lb_mod),
        .y_node_clb(y_node_clb),
        .z_parent_scale(z_parent_scale),
        .z_scale(z_scale),
        .z_node_lb_mod(z_node_lb_mod),
        .z_node_clb(z_node_clb),
        .c0_lo_x(c0_lo_x),
        .c0_hi_x(c0_hi_x),
        .c0_lo_y(c0_lo_y),
        .c0_hi_y(c0_hi_y),
        .c0_lo_z(c0_lo_z),
        .c0_hi_z(c0_hi_z),
        .c0_flags(c0_flags),
        .c0_ptr(c0_ptr),
        .c1_lo_x(c1_lo_x),
        .c1_hi_x(c1_hi_x),
        .c1_lo_y(c1_lo_y),
        .c1_hi_y(c1_hi_y),
        .c1_lo_z(c1_lo_z),
        .c1_hi_z(c1_hi_z),
        .c1_flags(c1_flags),
        .c1_ptr(c1_ptr),
        .word0(word0), .word1(word1), .word2(word2), .word3(word3),
        .word4(word4), .word5(word5), .status(status));

    localparam [8*24-1:0] VF_TB = "tb_nodepair_encoder", VF_UNIT = "nodepair_encode";
    localparam integer VF_ENC = 1, VF_MODULO = MODULO;
    `include "vecfile.vh"
    reg [31:0]       v [0:35];                       // the fields of one vector line
    reg [31:0]       got [0:5];
    integer j, bad;

    initial begin
        vf_open;

        // vectors: 28 input fields, then NWO words and status
        vf_read_line;
        while (vf_rc != 0) begin
            // NIN + NWO + 1 hex fields (inputs, words, status), no more (vf_read_line split them)
            for (j = 0; j < 36; j = j + 1) v[j] = (j < vf_nw) ? vf_w[j] : 32'd0;
            if (vf_nw != NIN + NWO + 1)
                $fatal(1, "tb_nodepair_encoder: %0s:%0d: malformed vector line (%0d fields)", vf_path, vf_lineno, vf_nw);
            x_parent_scale = v[0][7:0];
            x_scale = v[1][7:0];
            x_node_lb_mod = v[2][11:0];
            x_node_clb = v[3][31:0];
            y_parent_scale = v[4][7:0];
            y_scale = v[5][7:0];
            y_node_lb_mod = v[6][11:0];
            y_node_clb = v[7][31:0];
            z_parent_scale = v[8][7:0];
            z_scale = v[9][7:0];
            z_node_lb_mod = v[10][11:0];
            z_node_clb = v[11][31:0];
            c0_lo_x = v[12][31:0];
            c0_hi_x = v[13][31:0];
            c0_lo_y = v[14][31:0];
            c0_hi_y = v[15][31:0];
            c0_lo_z = v[16][31:0];
            c0_hi_z = v[17][31:0];
            c0_flags = v[18][3:0];
            c0_ptr = v[19][31:0];
            c1_lo_x = v[20][31:0];
            c1_hi_x = v[21][31:0];
            c1_lo_y = v[22][31:0];
            c1_hi_y = v[23][31:0];
            c1_lo_z = v[24][31:0];
            c1_hi_z = v[25][31:0];
            c1_flags = v[26][3:0];
            c1_ptr = v[27][31:0];
            #1;
            vf_nvec = vf_nvec + 1;
            got[0] = word0; got[1] = word1; got[2] = word2;
            got[3] = word3; got[4] = word4; got[5] = word5;
            bad = 0;
            for (j = 0; j < 6; j = j + 1)
                if (j < NWO) begin
                    if (got[j] !== v[NIN + j]) bad = 1;
                end else begin
                    if (got[j] !== 32'd0) bad = 1;   // unused words must stay zero
                end
            if (v[NIN + NWO] !== {24'd0, status}) bad = 1;
            if (bad) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10) begin
                    $display("mismatch line %0d: inputs %02h %02h %03h %08h %02h %02h %03h %08h %02h %02h %03h %08h %08h %08h %08h %08h %08h %08h %01h %08h %08h %08h %08h %08h %08h %08h %01h %08h",
                             vf_lineno, v[0][7:0], v[1][7:0], v[2][11:0], v[3][31:0], v[4][7:0], v[5][7:0], v[6][11:0], v[7][31:0], v[8][7:0], v[9][7:0], v[10][11:0], v[11][31:0], v[12][31:0], v[13][31:0], v[14][31:0], v[15][31:0], v[16][31:0], v[17][31:0], v[18][3:0], v[19][31:0], v[20][31:0], v[21][31:0], v[22][31:0], v[23][31:0], v[24][31:0], v[25][31:0], v[26][3:0], v[27][31:0]);
                    $display("    expected words %08h %08h %08h %08h %08h %08h status %02h",
                             v[NIN], v[NIN + 1], v[NIN + 2], v[NIN + 3],
                             (NWO == 6) ? v[NIN + 4] : 32'd0, (NWO == 6) ? v[NIN + 5] : 32'd0,
                             v[NIN + NWO][7:0]);
                    $display("    got      words %08h %08h %08h %08h %08h %08h status %02h",
                             word0, word1, word2, word3, word4, word5, status);
                end
            end
            vf_read_line;
        end
        vf_finish;
    end
endmodule
