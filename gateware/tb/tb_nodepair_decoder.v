// Testbench for cbvh_nodepair_decoder (unit 4, decode direction): runs a golden
// vector file (docs/vectors.md, unit nodepair_decode) given by +vec=PATH. The
// file's header must match the parameters N, E_MIN and MODULO; every output
// field is compared. Inputs: the three axis contexts and the pair's words
// (word0..word3 for N <= 6, word0..word5 for N >= 7).
//   iverilog -g2005 -P tb_nodepair_decoder.N=6 -P tb_nodepair_decoder.E_MIN=-30 \
//     -P tb_nodepair_decoder.MODULO=1 -s tb_nodepair_decoder -o tb.vvp \
//     gateware/tb/tb_nodepair_decoder.v gateware/rtl/*.v \
//     && vvp tb.vvp +vec=vectors/nodepair_decode-N6-ms-30-modulo.vec
module tb_nodepair_decoder;
    parameter integer N      = 6;
    parameter integer E_MIN  = -30;
    parameter integer MODULO = 1;


    reg  [7:0]    x_parent_scale;
    reg  [7:0]    x_scale;
    reg  [11:0]   x_node_lb_mod;
    reg  [31:0]   x_node_clb;
    reg  [7:0]    y_parent_scale;
    reg  [7:0]    y_scale;
    reg  [11:0]   y_node_lb_mod;
    reg  [31:0]   y_node_clb;
    reg  [7:0]    z_parent_scale;
    reg  [7:0]    z_scale;
    reg  [11:0]   z_node_lb_mod;
    reg  [31:0]   z_node_clb;
    reg  [31:0]  word0, word1, word2, word3, word4, word5;
    wire [1:0]    c0_flags;
    wire [31:0]   c0_ptr;
    wire [N-1:0]  c0_x_lb_mod;
    wire [N-1:0]  c0_x_ub_mod;
    wire [7:0]    c0_x_child_scale;
    wire [31:0]   c0_x_clb;
    wire [31:0]   c0_x_cub;
    wire [N-1:0]  c0_y_lb_mod;
    wire [N-1:0]  c0_y_ub_mod;
    wire [7:0]    c0_y_child_scale;
    wire [31:0]   c0_y_clb;
    wire [31:0]   c0_y_cub;
    wire [N-1:0]  c0_z_lb_mod;
    wire [N-1:0]  c0_z_ub_mod;
    wire [7:0]    c0_z_child_scale;
    wire [31:0]   c0_z_clb;
    wire [31:0]   c0_z_cub;
    wire [1:0]    c1_flags;
    wire [31:0]   c1_ptr;
    wire [N-1:0]  c1_x_lb_mod;
    wire [N-1:0]  c1_x_ub_mod;
    wire [7:0]    c1_x_child_scale;
    wire [31:0]   c1_x_clb;
    wire [31:0]   c1_x_cub;
    wire [N-1:0]  c1_y_lb_mod;
    wire [N-1:0]  c1_y_ub_mod;
    wire [7:0]    c1_y_child_scale;
    wire [31:0]   c1_y_clb;
    wire [31:0]   c1_y_cub;
    wire [N-1:0]  c1_z_lb_mod;
    wire [N-1:0]  c1_z_ub_mod;
    wire [7:0]    c1_z_child_scale;
    wire [31:0]   c1_z_clb;
    wire [31:0]   c1_z_cub;
    wire [6:0]    status;

    cbvh_nodepair_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) dut (
        .x_parent_scale(x_parent_scale), .x_scale(x_scale), .x_node_lb_mod(x_node_lb_mod),
        .x_node_clb(x_node_clb), .y_parent_scale(y_parent_scale), .y_scale(y_scale),
        .y_node_lb_mod(y_node_lb_mod), .y_node_clb(y_node_clb),
        .z_parent_scale(z_parent_scale), .z_scale(z_scale), .z_node_lb_mod(z_node_lb_mod),
        .z_node_clb(z_node_clb), .word0(word0), .word1(word1), .word2(word2), .word3(word3),
        .word4(word4), .word5(word5), .c0_flags(c0_flags), .c0_ptr(c0_ptr),
        .c0_x_lb_mod(c0_x_lb_mod), .c0_x_ub_mod(c0_x_ub_mod),
        .c0_x_child_scale(c0_x_child_scale), .c0_x_clb(c0_x_clb), .c0_x_cub(c0_x_cub),
        .c0_y_lb_mod(c0_y_lb_mod), .c0_y_ub_mod(c0_y_ub_mod),
        .c0_y_child_scale(c0_y_child_scale), .c0_y_clb(c0_y_clb), .c0_y_cub(c0_y_cub),
        .c0_z_lb_mod(c0_z_lb_mod), .c0_z_ub_mod(c0_z_ub_mod),
        .c0_z_child_scale(c0_z_child_scale), .c0_z_clb(c0_z_clb), .c0_z_cub(c0_z_cub),
        .c1_flags(c1_flags), .c1_ptr(c1_ptr), .c1_x_lb_mod(c1_x_lb_mod),
        .c1_x_ub_mod(c1_x_ub_mod), .c1_x_child_scale(c1_x_child_scale), .c1_x_clb(c1_x_clb),
        .c1_x_cub(c1_x_cub), .c1_y_lb_mod(c1_y_lb_mod), .c1_y_ub_mod(c1_y_ub_mod),
        .c1_y_child_scale(c1_y_child_scale), .c1_y_clb(c1_y_clb), .c1_y_cub(c1_y_cub),
        .c1_z_lb_mod(c1_z_lb_mod), .c1_z_ub_mod(c1_z_ub_mod),
        .c1_z_child_scale(c1_z_child_scale), .c1_z_clb(c1_z_clb), .c1_z_cub(c1_z_cub),
        .status(status));

    localparam [8*24-1:0] VF_TB = "tb_nodepair_decoder", VF_UNIT = "nodepair_decode";
    localparam integer VF_ENC = 1, VF_MODULO = MODULO;
    `include "vecfile.vh"

    integer k;
    reg bad;
    // fields as read (file fields can be wider than the ports: compare as read)
    reg [31:0] i_x_parent_scale, i_x_scale, i_x_node_lb_mod, i_x_node_clb, i_y_parent_scale, i_y_scale, i_y_node_lb_mod, i_y_node_clb, i_z_parent_scale, i_z_scale, i_z_node_lb_mod, i_z_node_clb;
    reg [31:0] i_word0, i_word1, i_word2, i_word3, i_word4, i_word5;
    reg [31:0] e_c0_flags, e_c0_ptr, e_c0_x_lb_mod, e_c0_x_ub_mod, e_c0_x_child_scale, e_c0_x_clb;
    reg [31:0] e_c0_x_cub, e_c0_y_lb_mod, e_c0_y_ub_mod, e_c0_y_child_scale, e_c0_y_clb, e_c0_y_cub;
    reg [31:0] e_c0_z_lb_mod, e_c0_z_ub_mod, e_c0_z_child_scale, e_c0_z_clb, e_c0_z_cub, e_c1_flags;
    reg [31:0] e_c1_ptr, e_c1_x_lb_mod, e_c1_x_ub_mod, e_c1_x_child_scale, e_c1_x_clb, e_c1_x_cub;
    reg [31:0] e_c1_y_lb_mod, e_c1_y_ub_mod, e_c1_y_child_scale, e_c1_y_clb, e_c1_y_cub, e_c1_z_lb_mod;
    reg [31:0] e_c1_z_ub_mod, e_c1_z_child_scale, e_c1_z_clb, e_c1_z_cub, e_status;

    // one output field: got (zero-extended port) against expected (as read)
    task check;
        input [8*20-1:0] name;
        input [31:0] got;
        input [31:0] exp;
        begin
            if (got !== exp) begin
                if (!bad) begin
                    vf_nfail = vf_nfail + 1;
                    if (vf_nfail <= 10)
                        $display("mismatch line %0d: inputs %02h %02h %03h %08h %02h %02h %03h %08h %02h %02h %03h %08h words %08h %08h %08h %08h %08h %08h",
                                 vf_lineno, i_x_parent_scale[7:0], i_x_scale[7:0], i_x_node_lb_mod[11:0], i_x_node_clb,
                                 i_y_parent_scale[7:0], i_y_scale[7:0], i_y_node_lb_mod[11:0], i_y_node_clb,
                                 i_z_parent_scale[7:0], i_z_scale[7:0], i_z_node_lb_mod[11:0], i_z_node_clb,
                                 i_word0, i_word1, i_word2, i_word3, i_word4, i_word5);
                end
                bad = 1'b1;
                if (vf_nfail <= 10)
                    $display("  %0s expected %08h got %08h", name, exp, got);
            end
        end
    endtask

    initial begin
        vf_open;

        // vectors
        vf_read_line;
        while (vf_rc != 0) begin
            i_word4 = 0; i_word5 = 0;
            // 12 context fields, 4 (N <= 6) or 6 (N >= 7) words, 35 outputs, no more
            {i_x_parent_scale, i_x_scale, i_x_node_lb_mod, i_x_node_clb, i_y_parent_scale, i_y_scale,
                i_y_node_lb_mod, i_y_node_clb, i_z_parent_scale, i_z_scale, i_z_node_lb_mod, i_z_node_clb} =
                {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4], vf_w[5], vf_w[6], vf_w[7], vf_w[8], vf_w[9],
                vf_w[10], vf_w[11]};
            {i_word0, i_word1, i_word2, i_word3} = {vf_w[12], vf_w[13], vf_w[14], vf_w[15]};
            if (N > 6) {i_word4, i_word5} = {vf_w[16], vf_w[17]};
            k = N <= 6 ? 16 : 18;  // the first output field
            {e_c0_flags, e_c0_ptr, e_c0_x_lb_mod, e_c0_x_ub_mod, e_c0_x_child_scale, e_c0_x_clb, e_c0_x_cub,
                e_c0_y_lb_mod, e_c0_y_ub_mod, e_c0_y_child_scale, e_c0_y_clb, e_c0_y_cub, e_c0_z_lb_mod,
                e_c0_z_ub_mod, e_c0_z_child_scale, e_c0_z_clb, e_c0_z_cub, e_c1_flags, e_c1_ptr,
                e_c1_x_lb_mod, e_c1_x_ub_mod, e_c1_x_child_scale, e_c1_x_clb, e_c1_x_cub, e_c1_y_lb_mod,
                e_c1_y_ub_mod, e_c1_y_child_scale, e_c1_y_clb, e_c1_y_cub, e_c1_z_lb_mod, e_c1_z_ub_mod,
                e_c1_z_child_scale, e_c1_z_clb, e_c1_z_cub, e_status} =
                {vf_w[k + 0], vf_w[k + 1], vf_w[k + 2], vf_w[k + 3], vf_w[k + 4], vf_w[k + 5], vf_w[k + 6],
                vf_w[k + 7], vf_w[k + 8], vf_w[k + 9], vf_w[k + 10], vf_w[k + 11], vf_w[k + 12],
                vf_w[k + 13], vf_w[k + 14], vf_w[k + 15], vf_w[k + 16], vf_w[k + 17], vf_w[k + 18],
                vf_w[k + 19], vf_w[k + 20], vf_w[k + 21], vf_w[k + 22], vf_w[k + 23], vf_w[k + 24],
                vf_w[k + 25], vf_w[k + 26], vf_w[k + 27], vf_w[k + 28], vf_w[k + 29], vf_w[k + 30],
                vf_w[k + 31], vf_w[k + 32], vf_w[k + 33], vf_w[k + 34]};
            if (vf_nw != (N <= 6 ? 51 : 53))
                $fatal(1, "tb_nodepair_decoder: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            x_parent_scale   = i_x_parent_scale[7:0];
            x_scale          = i_x_scale[7:0];
            x_node_lb_mod    = i_x_node_lb_mod[11:0];
            x_node_clb       = i_x_node_clb[31:0];
            y_parent_scale   = i_y_parent_scale[7:0];
            y_scale          = i_y_scale[7:0];
            y_node_lb_mod    = i_y_node_lb_mod[11:0];
            y_node_clb       = i_y_node_clb[31:0];
            z_parent_scale   = i_z_parent_scale[7:0];
            z_scale          = i_z_scale[7:0];
            z_node_lb_mod    = i_z_node_lb_mod[11:0];
            z_node_clb       = i_z_node_clb[31:0];
            word0            = i_word0;
            word1            = i_word1;
            word2            = i_word2;
            word3            = i_word3;
            word4            = i_word4;
            word5            = i_word5;
            #1;
            vf_nvec = vf_nvec + 1;
            bad = 1'b0;
            check("c0_flags", {30'd0, c0_flags}, e_c0_flags);
            check("c0_ptr", c0_ptr, e_c0_ptr);
            check("c0_x_lb_mod", {{(32 - N){1'b0}}, c0_x_lb_mod}, e_c0_x_lb_mod);
            check("c0_x_ub_mod", {{(32 - N){1'b0}}, c0_x_ub_mod}, e_c0_x_ub_mod);
            check("c0_x_child_scale", {24'd0, c0_x_child_scale}, e_c0_x_child_scale);
            check("c0_x_clb", c0_x_clb, e_c0_x_clb);
            check("c0_x_cub", c0_x_cub, e_c0_x_cub);
            check("c0_y_lb_mod", {{(32 - N){1'b0}}, c0_y_lb_mod}, e_c0_y_lb_mod);
            check("c0_y_ub_mod", {{(32 - N){1'b0}}, c0_y_ub_mod}, e_c0_y_ub_mod);
            check("c0_y_child_scale", {24'd0, c0_y_child_scale}, e_c0_y_child_scale);
            check("c0_y_clb", c0_y_clb, e_c0_y_clb);
            check("c0_y_cub", c0_y_cub, e_c0_y_cub);
            check("c0_z_lb_mod", {{(32 - N){1'b0}}, c0_z_lb_mod}, e_c0_z_lb_mod);
            check("c0_z_ub_mod", {{(32 - N){1'b0}}, c0_z_ub_mod}, e_c0_z_ub_mod);
            check("c0_z_child_scale", {24'd0, c0_z_child_scale}, e_c0_z_child_scale);
            check("c0_z_clb", c0_z_clb, e_c0_z_clb);
            check("c0_z_cub", c0_z_cub, e_c0_z_cub);
            check("c1_flags", {30'd0, c1_flags}, e_c1_flags);
            check("c1_ptr", c1_ptr, e_c1_ptr);
            check("c1_x_lb_mod", {{(32 - N){1'b0}}, c1_x_lb_mod}, e_c1_x_lb_mod);
            check("c1_x_ub_mod", {{(32 - N){1'b0}}, c1_x_ub_mod}, e_c1_x_ub_mod);
            check("c1_x_child_scale", {24'd0, c1_x_child_scale}, e_c1_x_child_scale);
            check("c1_x_clb", c1_x_clb, e_c1_x_clb);
            check("c1_x_cub", c1_x_cub, e_c1_x_cub);
            check("c1_y_lb_mod", {{(32 - N){1'b0}}, c1_y_lb_mod}, e_c1_y_lb_mod);
            check("c1_y_ub_mod", {{(32 - N){1'b0}}, c1_y_ub_mod}, e_c1_y_ub_mod);
            check("c1_y_child_scale", {24'd0, c1_y_child_scale}, e_c1_y_child_scale);
            check("c1_y_clb", c1_y_clb, e_c1_y_clb);
            check("c1_y_cub", c1_y_cub, e_c1_y_cub);
            check("c1_z_lb_mod", {{(32 - N){1'b0}}, c1_z_lb_mod}, e_c1_z_lb_mod);
            check("c1_z_ub_mod", {{(32 - N){1'b0}}, c1_z_ub_mod}, e_c1_z_ub_mod);
            check("c1_z_child_scale", {24'd0, c1_z_child_scale}, e_c1_z_child_scale);
            check("c1_z_clb", c1_z_clb, e_c1_z_clb);
            check("c1_z_cub", c1_z_cub, e_c1_z_cub);
            check("status", {25'd0, status}, e_status);
            vf_read_line;
        end
        vf_finish;
    end
endmodule
