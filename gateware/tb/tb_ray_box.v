// Testbench for cbvh_ray_box (unit 6): runs a golden vector file
// (docs/vectors.md, unit ray_box) given by +vec=PATH. The unit depends on
// neither N nor e_min; the parameters are only checked against the header.
// Every vector: drive the inputs, pulse start, wait for done (at most
// MAX_CYCLES clocks), compare hit, t_near, t_far and status.
//   iverilog -g2005 -P tb_ray_box.N=6 -P tb_ray_box.E_MIN=-30 -s tb_ray_box \
//     -o tb.vvp gateware/tb/tb_ray_box.v gateware/rtl/ray_box.v &&
//     vvp tb.vvp +vec=vectors/ray_box-N6-ms-30.vec
module tb_ray_box;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    localparam integer MAX_CYCLES = 2000;

    reg clk = 1'b0;
    reg rst = 1'b1;
    reg start = 1'b0;
    wire busy, done;
    reg  [31:0] ox, oy, oz, dx, dy, dz, tmin, tmax;
    reg  [7:0]  mant;
    reg  [31:0] x_u, y_u, z_u;
    reg  [7:0]  x_scale, y_scale, z_scale;
    reg  [11:0] x_r, x_s, y_r, y_s, z_r, z_s;
    wire        hit;
    wire [31:0] t_near, t_far;
    wire [7:0]  status;

    cbvh_ray_box dut (
        .clk(clk), .rst(rst), .start(start), .busy(busy), .done(done),
        .ox(ox), .oy(oy), .oz(oz), .dx(dx), .dy(dy), .dz(dz),
        .tmin(tmin), .tmax(tmax), .mant(mant),
        .x_u(x_u), .x_scale(x_scale), .x_r(x_r), .x_s(x_s),
        .y_u(y_u), .y_scale(y_scale), .y_r(y_r), .y_s(y_s),
        .z_u(z_u), .z_scale(z_scale), .z_r(z_r), .z_s(z_s),
        .hit(hit), .t_near(t_near), .t_far(t_far), .status(status));

    always #5 clk = ~clk;

    localparam [8*24-1:0] VF_TB = "tb_ray_box", VF_UNIT = "ray_box";
    localparam integer VF_ENC = 0, VF_MODULO = 0;
    `include "vecfile.vh"

    integer cyc, cyc_min, cyc_max, cyc_sum, cyc_int;
    reg [31:0] i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_tmin, i_tmax, i_mant;
    reg [31:0] i_xu, i_xe, i_xr, i_xs, i_yu, i_ye, i_yr, i_ys, i_zu, i_ze, i_zr, i_zs;
    reg [31:0] x_hit, x_tn, x_tf, x_status;

    initial begin
        vf_open;
        cyc_min = 0; cyc_max = 0; cyc_sum = 0;

        // reset
        repeat (2) @(posedge clk);
        #1 rst = 1'b0;

        vf_read_line;
        while (vf_rc != 0) begin
            {i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_tmin, i_tmax, i_mant, i_xu, i_xe, i_xr, i_xs, i_yu, i_ye,
                i_yr, i_ys, i_zu, i_ze, i_zr, i_zs, x_hit, x_tn, x_tf, x_status} =
                {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4], vf_w[5], vf_w[6], vf_w[7], vf_w[8], vf_w[9],
                vf_w[10], vf_w[11], vf_w[12], vf_w[13], vf_w[14], vf_w[15], vf_w[16], vf_w[17], vf_w[18],
                vf_w[19], vf_w[20], vf_w[21], vf_w[22], vf_w[23], vf_w[24]};
            if (vf_nw != 25)
                $fatal(1, "tb_ray_box: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            ox = i_ox; oy = i_oy; oz = i_oz; dx = i_dx; dy = i_dy; dz = i_dz;
            tmin = i_tmin; tmax = i_tmax; mant = i_mant[7:0];
            x_u = i_xu; x_scale = i_xe[7:0]; x_r = i_xr[11:0]; x_s = i_xs[11:0];
            y_u = i_yu; y_scale = i_ye[7:0]; y_r = i_yr[11:0]; y_s = i_ys[11:0];
            z_u = i_zu; z_scale = i_ze[7:0]; z_r = i_zr[11:0]; z_s = i_zs[11:0];
            start = 1'b1;
            @(posedge clk);
            #1 start = 1'b0;
            cyc = 1;
            while (!done) begin
                if (cyc >= MAX_CYCLES)
                    $fatal(1, "tb_ray_box: %0s:%0d: no done after %0d cycles", vf_path, vf_lineno, cyc);
                @(posedge clk);
                #1 cyc = cyc + 1;
            end
            cyc_int = cyc;
            if (vf_nvec == 0 || cyc_int < cyc_min) cyc_min = cyc_int;
            if (cyc_int > cyc_max) cyc_max = cyc_int;
            cyc_sum = cyc_sum + cyc_int;
            vf_nvec = vf_nvec + 1;
            if ({31'd0, hit} !== x_hit || t_near !== x_tn || t_far !== x_tf ||
                {24'd0, status} !== x_status) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10)
                    $display("mismatch line %0d: inputs %08h %08h %08h %08h %08h %08h %08h %08h %02h %08h %02h %03h %03h %08h %02h %03h %03h %08h %02h %03h %03h expected %01h %08h %08h %02h got %01h %08h %08h %02h",
                             vf_lineno, i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_tmin, i_tmax, i_mant[7:0],
                             i_xu, i_xe[7:0], i_xr[11:0], i_xs[11:0], i_yu, i_ye[7:0], i_yr[11:0], i_ys[11:0],
                             i_zu, i_ze[7:0], i_zr[11:0], i_zs[11:0],
                             x_hit[3:0], x_tn, x_tf, x_status[7:0], hit, t_near, t_far, status);
            end
            vf_read_line;
        end

        if (vf_nvec > 0)
            $display("tb_ray_box: cycles per vector (start to done): min %0d, avg %0d, max %0d",
                     cyc_min, cyc_sum / vf_nvec, cyc_max);
        vf_finish;
    end
endmodule
