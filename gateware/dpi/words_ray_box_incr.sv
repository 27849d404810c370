// Word wrapper of cbvh_ray_box_incr (unit 10) for tb_dpi: the unit table's
// input words (rcp_x, rcp_y, rcp_z, tmin, tmax, mant, texp, then per axis
// t_lb, t_ub, scale, r, sp) to the ports, the outputs back to words (hit,
// t_near, t_far, x_c_lb, x_c_ub, y_c_lb, y_c_ub, z_c_lb, z_c_ub, status).
// Pipelined: a test every II = 6 / P clocks (in_ready).
module words_ray_box_incr #(parameter int N = 6, parameter int M = 8, parameter int X = 8, parameter int P = 6) (
    input  bit        clk,
    input  bit        in_valid,
    output wire       in_ready,
    input  bit [31:0] in_w [0:39],
    output wire       out_valid,
    output bit [31:0] out_w [0:39]
);
    wire        hit;
    wire [31:0] t_near, t_far, xl, xu, yl, yu, zl, zu;
    wire [7:0]  status;
    cbvh_ray_box_incr #(.N(N), .M(M), .X(X), .P(P)) u (
        .clk(clk), .in_valid(in_valid), .in_ready(in_ready),
        .rcp_x(in_w[0]), .rcp_y(in_w[1]), .rcp_z(in_w[2]), .tmin(in_w[3]), .tmax(in_w[4]),
        .mant(in_w[5][7:0]), .texp(in_w[6][7:0]),
        .x_t_lb(in_w[7]), .x_t_ub(in_w[8]), .x_scale(in_w[9][7:0]), .x_r(in_w[10][11:0]), .x_sp(in_w[11][11:0]),
        .y_t_lb(in_w[12]), .y_t_ub(in_w[13]), .y_scale(in_w[14][7:0]), .y_r(in_w[15][11:0]), .y_sp(in_w[16][11:0]),
        .z_t_lb(in_w[17]), .z_t_ub(in_w[18]), .z_scale(in_w[19][7:0]), .z_r(in_w[20][11:0]), .z_sp(in_w[21][11:0]),
        .out_valid(out_valid), .hit(hit), .t_near(t_near), .t_far(t_far),
        .x_c_lb(xl), .x_c_ub(xu), .y_c_lb(yl), .y_c_ub(yu), .z_c_lb(zl), .z_c_ub(zu), .status(status));
    always_comb begin
        for (int i = 0; i < 40; i++) out_w[i] = 32'd0;
        out_w[0] = {31'd0, hit}; out_w[1] = t_near; out_w[2] = t_far;
        out_w[3] = xl; out_w[4] = xu; out_w[5] = yl; out_w[6] = yu; out_w[7] = zl; out_w[8] = zu;
        out_w[9] = {24'd0, status};
    end
endmodule
