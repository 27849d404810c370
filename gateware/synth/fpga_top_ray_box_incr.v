// Timing and area harness of the incremental ray-box unit (unit 10) for the
// iCE40UP5K (gateware/scripts/cost-ray-box-incr), the same scheme as
// synth/fpga_top.v (whose fpga_shift_io it uses): the unit's 449 input bits
// shift in on one pin, its 267 output bits are captured on load and shift out
// on another.  mant and texp are the design point's constants, as in a
// hardware instance.
`default_nettype none

module fpga_top_ray_box_incr #(parameter integer N = 6, parameter integer M = 8, parameter integer X = 8,
                               parameter integer P = 6) (
    input wire clk, input wire din, input wire load, output wire dout);
    localparam integer IN_W = 1 + 3 * 32 + 2 * 32 + 3 * (32 + 32 + 8 + 12 + 12);
    localparam integer OUT_W = 3 + 2 * 32 + 6 * 32 + 8;
    localparam [7:0] MC = M[7:0], XC = X[7:0];
    wire [IN_W-1:0] in_sr;
    wire in_ready, out_valid, hit;
    wire [31:0] t_near, t_far, xl, xu, yl, yu, zl, zu;
    wire [7:0] status;
    cbvh_ray_box_incr #(.N(N), .M(M), .X(X), .P(P)) unit (
        .clk(clk), .in_valid(in_sr[0]), .in_ready(in_ready),
        .rcp_x(in_sr[32:1]), .rcp_y(in_sr[64:33]), .rcp_z(in_sr[96:65]),
        .tmin(in_sr[128:97]), .tmax(in_sr[160:129]), .mant(MC), .texp(XC),
        .x_t_lb(in_sr[192:161]), .x_t_ub(in_sr[224:193]), .x_scale(in_sr[232:225]),
        .x_r(in_sr[244:233]), .x_sp(in_sr[256:245]),
        .y_t_lb(in_sr[288:257]), .y_t_ub(in_sr[320:289]), .y_scale(in_sr[328:321]),
        .y_r(in_sr[340:329]), .y_sp(in_sr[352:341]),
        .z_t_lb(in_sr[384:353]), .z_t_ub(in_sr[416:385]), .z_scale(in_sr[424:417]),
        .z_r(in_sr[436:425]), .z_sp(in_sr[448:437]),
        .out_valid(out_valid), .hit(hit), .t_near(t_near), .t_far(t_far),
        .x_c_lb(xl), .x_c_ub(xu), .y_c_lb(yl), .y_c_ub(yu), .z_c_lb(zl), .z_c_ub(zu), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({in_ready, out_valid, hit, t_near, t_far, xl, xu, yl, yu, zl, zu, status}), .in_bits(in_sr),
        .dout(dout));
endmodule
