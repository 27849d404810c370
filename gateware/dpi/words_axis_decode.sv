// Word wrapper of cbvh_axis_decoder (unit 3, combinational) for tb_dpi: the
// unit table's words (parent_scale, scale, node_lb_mod, node_clb, lb_code,
// ub_code -> lb_mod, ub_mod, child_scale, clb, cub, status); the outputs are
// registered, so a result comes one clock after its inputs.
module words_axis_decode #(parameter int N = 6, parameter int E_MIN = -30, parameter int MODULO = 1) (
    input  bit        clk,
    input  bit        in_valid,
    output wire       in_ready,
    input  bit [31:0] in_w [0:39],
    output bit        out_valid,
    output bit [31:0] out_w [0:39]
);
    wire [N-1:0] lb_mod, ub_mod;
    wire [7:0]   child_scale;
    wire [31:0]  clb, cub;
    wire [6:0]   status;
    assign in_ready = 1'b1;
    cbvh_axis_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) u (
        .parent_scale(in_w[0][7:0]), .scale(in_w[1][7:0]), .node_lb_mod(in_w[2][11:0]), .node_clb(in_w[3]),
        .lb_code(in_w[4][11:0]), .ub_code(in_w[5][11:0]),
        .lb_mod(lb_mod), .ub_mod(ub_mod), .child_scale(child_scale), .clb(clb), .cub(cub), .status(status));
    always_ff @(posedge clk) begin
        out_valid <= in_valid;
        for (int i = 0; i < 40; i++) out_w[i] <= 32'd0;
        out_w[0] <= {{(32-N){1'b0}}, lb_mod}; out_w[1] <= {{(32-N){1'b0}}, ub_mod};
        out_w[2] <= {24'd0, child_scale}; out_w[3] <= clb; out_w[4] <= cub; out_w[5] <= {25'd0, status};
    end
endmodule
