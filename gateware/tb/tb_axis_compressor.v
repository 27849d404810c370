// Testbench for cbvh_axis_compressor: runs a golden vector file (docs/vectors.md).
//   iverilog -g2005 -P tb_axis_compressor.N=6 -P tb_axis_compressor.E_MIN=-30 \
//       -o tb gateware/tb/tb_axis_compressor.v gateware/rtl/axis_compressor.v
//   vvp tb +vec=vectors/axis_compress-N6-ms-30.vec
module tb_axis_compressor;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    reg  [31:0]  lb, ub, node_clb;
    reg  [7:0]   scale;
    wire [N-1:0] lb_mod, ub_mod;
    wire [7:0]   child_scale;
    wire [31:0]  clb, cub;
    wire [7:0]   status;

    cbvh_axis_compressor #(.N(N), .E_MIN(E_MIN)) dut (
        .lb(lb), .ub(ub), .scale(scale), .node_clb(node_clb), .lb_mod(lb_mod), .ub_mod(ub_mod),
        .child_scale(child_scale), .clb(clb), .cub(cub), .status(status));

    localparam [8*24-1:0] VF_TB = "tb_axis_compressor", VF_UNIT = "axis_compress";
    localparam integer VF_ENC = 0, VF_MODULO = 0;
    `include "vecfile.vh"
    reg [31:0] i_lb, i_ub, i_node, x_clb, x_cub;
    reg [31:0] i_sc, x_lm, x_um, x_cs, x_st;

    initial begin
        vf_open;

        // vectors: lb ub scale node_clb -> lb_mod ub_mod child_scale clb cub status
        vf_read_line;
        while (vf_rc != 0) begin
            // 10 hex fields, no more
            {i_lb, i_ub, i_sc, i_node, x_lm, x_um, x_cs, x_clb, x_cub, x_st} =
                {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4], vf_w[5], vf_w[6], vf_w[7], vf_w[8], vf_w[9]};
            if (vf_nw != 10)
                $fatal(1, "tb_axis_compressor: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            lb = i_lb; ub = i_ub; scale = i_sc[7:0]; node_clb = i_node;
            #1;
            vf_nvec = vf_nvec + 1;
            if (x_lm !== {{(32-N){1'b0}}, lb_mod} || x_um !== {{(32-N){1'b0}}, ub_mod} ||
                x_cs !== {24'd0, child_scale} || clb !== x_clb || cub !== x_cub ||
                x_st !== {24'd0, status}) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10)
                    $display("mismatch line %0d: inputs lb=%08h ub=%08h scale=%02h node_clb=%08h expected %03h %03h %02h %08h %08h %02h got %03h %03h %02h %08h %08h %02h",
                             vf_lineno, i_lb, i_ub, i_sc[7:0], i_node,
                             x_lm[11:0], x_um[11:0], x_cs[7:0], x_clb, x_cub, x_st[7:0],
                             {{(12-N){1'b0}}, lb_mod}, {{(12-N){1'b0}}, ub_mod}, child_scale,
                             clb, cub, status);
            end
            vf_read_line;
        end
        vf_finish;
    end
endmodule
