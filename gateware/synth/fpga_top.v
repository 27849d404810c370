// Timing and area harnesses for the iCE40UP5K (gateware/scripts/synth-ice40).
// A unit's ports are far wider than the 39 I/O pins of the UP5K's sg48
// package, so each harness feeds the unit's inputs from a shift register on
// one pin and captures its outputs in a register that shifts out on another.
// Every output bit stays observable (nothing is optimised away), and the
// only register-to-register path through the unit is input register ->
// unit -> output register, so nextpnr's maximum frequency is the unit's.
`default_nettype none

// The pins of every harness: inputs shift in from din, one bit per clock; on
// load the unit's outputs are captured, then shift out on dout.
module fpga_shift_io #(parameter integer IN_W = 8, parameter integer OUT_W = 8) (
    input wire clk, input wire din, input wire load, input wire [OUT_W-1:0] out_bits,
    output reg [IN_W-1:0] in_bits, output wire dout);
    reg [OUT_W-1:0] out_sr;
    always @(posedge clk) begin
        in_bits <= {in_bits[IN_W-2:0], din};
        out_sr <= load ? out_bits : {1'b0, out_sr[OUT_W-1:1]};
    end
    assign dout = out_sr[0];
endmodule

module fpga_top_scale_estimator #(parameter integer N = 6, parameter integer E_MIN = -30) (
    input wire clk, input wire din, input wire load, output wire dout);
    localparam integer IN_W = 64, OUT_W = 8 + 7;
    wire [IN_W-1:0] in_sr;
    wire [7:0] scale;
    wire [6:0] status;
    cbvh_scale_estimator #(.N(N), .E_MIN(E_MIN)) unit (
        .lb(in_sr[31:0]), .ub(in_sr[63:32]), .scale(scale), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({scale, status}), .in_bits(in_sr), .dout(dout));
endmodule

module fpga_top_axis_compressor #(parameter integer N = 6, parameter integer E_MIN = -30) (
    input wire clk, input wire din, input wire load, output wire dout);
    localparam integer IN_W = 104, OUT_W = 2 * N + 8 + 64 + 8;
    wire [IN_W-1:0] in_sr;
    wire [N-1:0] lb_mod, ub_mod;
    wire [7:0] child_scale;
    wire [31:0] clb, cub;
    wire [7:0] status;
    cbvh_axis_compressor #(.N(N), .E_MIN(E_MIN)) unit (
        .lb(in_sr[31:0]), .ub(in_sr[63:32]), .scale(in_sr[71:64]), .node_clb(in_sr[103:72]),
        .lb_mod(lb_mod), .ub_mod(ub_mod), .child_scale(child_scale),
        .clb(clb), .cub(cub), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({lb_mod, ub_mod, child_scale, clb, cub, status}), .in_bits(in_sr), .dout(dout));
endmodule

module fpga_top_axis_decoder #(parameter integer N = 6, parameter integer E_MIN = -30,
                               parameter integer MODULO = 1) (
    input wire clk, input wire din, input wire load, output wire dout);
    // Code inputs are 12 bits wide at every N (3 hex digits on the wire; the
    // unit flags codes >= 2^N).
    localparam integer IN_W = 8 + 8 + 12 + 32 + 12 + 12, OUT_W = 2 * N + 8 + 64 + 7;
    wire [IN_W-1:0] in_sr;
    wire [N-1:0] lb_mod, ub_mod;
    wire [7:0] child_scale;
    wire [31:0] clb, cub;
    wire [6:0] status;
    cbvh_axis_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) unit (
        .parent_scale(in_sr[7:0]), .scale(in_sr[15:8]), .node_lb_mod(in_sr[27:16]),
        .node_clb(in_sr[59:28]), .lb_code(in_sr[71:60]), .ub_code(in_sr[83:72]),
        .lb_mod(lb_mod), .ub_mod(ub_mod), .child_scale(child_scale),
        .clb(clb), .cub(cub), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({lb_mod, ub_mod, child_scale, clb, cub, status}), .in_bits(in_sr), .dout(dout));
endmodule

module fpga_top_qbvh_stack (input wire clk, input wire din, input wire load, output wire dout);
    localparam integer IN_W = 4 + 32 + 4 + 128 + 32, OUT_W = 32 + 32 + 1 + 8 + 4 + 8;
    wire [IN_W-1:0] in_sr;
    wire [31:0] node, next_entry;
    wire write;
    wire [7:0] order, status;
    wire [3:0] nhit;
    cbvh_qbvh_stack unit (
        .op(in_sr[3:0]), .first(in_sr[35:4]), .hit_mask(in_sr[39:36]), .t0(in_sr[71:40]),
        .t1(in_sr[103:72]), .t2(in_sr[135:104]), .t3(in_sr[167:136]), .entry(in_sr[199:168]),
        .node(node), .next_entry(next_entry), .write(write), .order(order), .nhit(nhit), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({node, next_entry, write, order, nhit, status}), .in_bits(in_sr), .dout(dout));
endmodule

// The ray-box unit is sequential (one shared divider): its own registers bound
// the critical path; start and rst come from pins.
module fpga_top_ray_box (input wire clk, input wire din, input wire load, input wire start,
                         input wire rst, output wire dout, output wire busy, output wire done);
    localparam integer IN_W = 8 * 32 + 8 + 3 * (32 + 8 + 24), OUT_W = 1 + 64 + 8;
    wire [IN_W-1:0] in_sr;
    wire hit;
    wire [31:0] t_near, t_far;
    wire [7:0] status;
    cbvh_ray_box unit (
        .clk(clk), .rst(rst), .start(start), .busy(busy), .done(done),
        .ox(in_sr[31:0]), .oy(in_sr[63:32]), .oz(in_sr[95:64]), .dx(in_sr[127:96]),
        .dy(in_sr[159:128]), .dz(in_sr[191:160]), .tmin(in_sr[223:192]), .tmax(in_sr[255:224]),
        .mant(in_sr[263:256]),
        .x_u(in_sr[295:264]), .x_scale(in_sr[303:296]), .x_r(in_sr[315:304]), .x_s(in_sr[327:316]),
        .y_u(in_sr[359:328]), .y_scale(in_sr[367:360]), .y_r(in_sr[379:368]), .y_s(in_sr[391:380]),
        .z_u(in_sr[423:392]), .z_scale(in_sr[431:424]), .z_r(in_sr[443:432]), .z_s(in_sr[455:444]),
        .hit(hit), .t_near(t_near), .t_far(t_far), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({hit, t_near, t_far, status}), .in_bits(in_sr), .dout(dout));
endmodule

module fpga_top_ray_sphere (input wire clk, input wire din, input wire load, input wire start,
                            input wire rst, output wire dout, output wire busy, output wire done);
    localparam integer IN_W = 12 * 32, OUT_W = 1 + 8;
    wire [IN_W-1:0] in_sr;
    wire hit;
    wire [7:0] status;
    cbvh_ray_sphere unit (
        .clk(clk), .rst(rst), .start(start), .busy(busy), .done(done),
        .ox(in_sr[31:0]), .oy(in_sr[63:32]), .oz(in_sr[95:64]), .dx(in_sr[127:96]),
        .dy(in_sr[159:128]), .dz(in_sr[191:160]), .tmin(in_sr[223:192]), .tmax(in_sr[255:224]),
        .cx(in_sr[287:256]), .cy(in_sr[319:288]), .cz(in_sr[351:320]), .r(in_sr[383:352]),
        .hit(hit), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({hit, status}), .in_bits(in_sr), .dout(dout));
endmodule

module fpga_top_ray_triangle (input wire clk, input wire din, input wire load, input wire start,
                              input wire rst, output wire dout, output wire busy, output wire done);
    localparam integer IN_W = 15 * 32, OUT_W = 1 + 3 * 32 + 8;
    wire [IN_W-1:0] in_sr;
    wire hit;
    wire [31:0] t, b1, b2;
    wire [7:0] status;
    cbvh_ray_triangle unit (
        .clk(clk), .rst(rst), .start(start), .busy(busy), .done(done),
        .ox(in_sr[31:0]), .oy(in_sr[63:32]), .oz(in_sr[95:64]), .dx(in_sr[127:96]),
        .dy(in_sr[159:128]), .dz(in_sr[191:160]),
        .v0x(in_sr[223:192]), .v0y(in_sr[255:224]), .v0z(in_sr[287:256]),
        .v1x(in_sr[319:288]), .v1y(in_sr[351:320]), .v1z(in_sr[383:352]),
        .v2x(in_sr[415:384]), .v2y(in_sr[447:416]), .v2z(in_sr[479:448]),
        .hit(hit), .t(t), .b1(b1), .b2(b2), .status(status));
    fpga_shift_io #(.IN_W(IN_W), .OUT_W(OUT_W)) io (.clk(clk), .din(din), .load(load),
        .out_bits({hit, t, b1, b2, status}), .in_bits(in_sr), .dout(dout));
endmodule

`default_nettype wire
