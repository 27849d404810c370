// Testbench for cbvh_axis_decoder (unit 3): runs a golden vector file
// (docs/vectors.md, unit axis_decode) given by +vec=PATH. The file's header must
// match the parameters N, E_MIN and MODULO; every output field is compared.
//   iverilog -g2005 -P tb_axis_decoder.N=6 -P tb_axis_decoder.E_MIN=-30 \
//     -P tb_axis_decoder.MODULO=1 -o tb.vvp gateware/tb/tb_axis_decoder.v \
//     gateware/rtl/axis_decoder.v && vvp tb.vvp +vec=vectors/axis_decode-N6-ms-30-modulo.vec
module tb_axis_decoder;
    parameter integer N      = 6;
    parameter integer E_MIN  = -30;
    parameter integer MODULO = 1;

    reg  [7:0]   parent_scale, scale;
    reg  [11:0]  node_lb_mod, lb_code, ub_code;
    reg  [31:0]  node_clb;
    wire [N-1:0] lb_mod, ub_mod;
    wire [7:0]   child_scale;
    wire [31:0]  clb, cub;
    wire [6:0]   status;

    cbvh_axis_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) dut (
        .parent_scale(parent_scale), .scale(scale), .node_lb_mod(node_lb_mod),
        .node_clb(node_clb), .lb_code(lb_code), .ub_code(ub_code),
        .lb_mod(lb_mod), .ub_mod(ub_mod), .child_scale(child_scale),
        .clb(clb), .cub(cub), .status(status));

    localparam [8*24-1:0] VF_TB = "tb_axis_decoder", VF_UNIT = "axis_decode";
    localparam integer VF_ENC = 1, VF_MODULO = MODULO;
    `include "vecfile.vh"

    // expected outputs (file fields are wider than the ports: compare as read)
    reg [31:0] x_lb_mod, x_ub_mod, x_cs, x_clb, x_cub, x_status;
    reg [31:0] i_ps, i_sc, i_nlm, i_nclb, i_lb, i_ub;

    initial begin
        vf_open;
        // vectors
        vf_read_line;
        while (vf_rc != 0) begin
            {i_ps, i_sc, i_nlm, i_nclb, i_lb, i_ub, x_lb_mod, x_ub_mod, x_cs, x_clb, x_cub, x_status} =
                {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4], vf_w[5], vf_w[6], vf_w[7], vf_w[8], vf_w[9],
                vf_w[10], vf_w[11]};
            if (vf_nw != 12)
                $fatal(1, "tb_axis_decoder: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            parent_scale = i_ps[7:0];
            scale        = i_sc[7:0];
            node_lb_mod  = i_nlm[11:0];
            node_clb     = i_nclb;
            lb_code      = i_lb[11:0];
            ub_code      = i_ub[11:0];
            #1;
            vf_nvec = vf_nvec + 1;
            if ({{(32 - N){1'b0}}, lb_mod} !== x_lb_mod ||
                {{(32 - N){1'b0}}, ub_mod} !== x_ub_mod ||
                {24'd0, child_scale} !== x_cs || clb !== x_clb || cub !== x_cub ||
                {25'd0, status} !== x_status) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10)
                    $display("mismatch line %0d: inputs %02h %02h %03h %08h %03h %03h expected %03h %03h %02h %08h %08h %02h got %03h %03h %02h %08h %08h %02h",
                             vf_lineno, i_ps[7:0], i_sc[7:0], i_nlm[11:0], i_nclb, i_lb[11:0], i_ub[11:0],
                             x_lb_mod[11:0], x_ub_mod[11:0], x_cs[7:0], x_clb, x_cub, x_status[7:0],
                             {{(12 - N){1'b0}}, lb_mod}, {{(12 - N){1'b0}}, ub_mod}, child_scale,
                             clb, cub, {1'b0, status});
            end
            vf_read_line;
        end
        vf_finish;
    end
endmodule
