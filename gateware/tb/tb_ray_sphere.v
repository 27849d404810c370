// Testbench for cbvh_ray_sphere (unit 9): runs a golden vector file
// (docs/vectors.md, unit ray_sphere) given by +vec=PATH. The unit depends on
// neither N nor e_min; the parameters are only checked against the header.
// Every vector: drive the inputs, pulse start, wait for done (at most
// MAX_CYCLES clocks), compare hit and status.
//   iverilog -g2005 -P tb_ray_sphere.N=6 -P tb_ray_sphere.E_MIN=-30 -s tb_ray_sphere \
//     -I gateware/tb -o tb.vvp gateware/tb/tb_ray_sphere.v gateware/rtl/ray_sphere.v &&
//     vvp tb.vvp +vec=vectors/ray_sphere-N6-ms-30.vec
module tb_ray_sphere;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    // the unit's worst case is about 2,130 cycles: Q(tmin), Q(tmax) and D,
    // 51 monomials, each carry rippling through all 35 accumulator words
    localparam integer MAX_CYCLES = 5000;

    reg clk = 1'b0;
    reg rst = 1'b1;
    reg start = 1'b0;
    wire busy, done;
    reg  [31:0] ox, oy, oz, dx, dy, dz, tmin, tmax, cx, cy, cz, r;
    wire        hit;
    wire [7:0]  status;

    cbvh_ray_sphere dut (
        .clk(clk), .rst(rst), .start(start), .busy(busy), .done(done),
        .ox(ox), .oy(oy), .oz(oz), .dx(dx), .dy(dy), .dz(dz),
        .tmin(tmin), .tmax(tmax), .cx(cx), .cy(cy), .cz(cz), .r(r),
        .hit(hit), .status(status));

    always #5 clk = ~clk;

    localparam [8*24-1:0] VF_TB = "tb_ray_sphere", VF_UNIT = "ray_sphere";
    localparam integer VF_ENC = 0, VF_MODULO = 0;
    `include "vecfile.vh"

    integer cyc, cyc_min, cyc_max, cyc_sum;
    reg [31:0] i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_tmin, i_tmax, i_cx, i_cy, i_cz, i_r;
    reg [31:0] x_hit, x_status;

    initial begin
        vf_open;
        cyc_min = 0; cyc_max = 0; cyc_sum = 0;

        // reset
        repeat (2) @(posedge clk);
        #1 rst = 1'b0;

        // "OX OY OZ DX DY DZ TMIN TMAX CX CY CZ R HIT STATUS"
        vf_read_line;
        while (vf_rc != 0) begin
            {i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_tmin, i_tmax, i_cx, i_cy, i_cz, i_r, x_hit, x_status} =
                {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4], vf_w[5], vf_w[6], vf_w[7], vf_w[8], vf_w[9],
                vf_w[10], vf_w[11], vf_w[12], vf_w[13]};
            if (vf_nw != 14)
                $fatal(1, "tb_ray_sphere: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            ox = i_ox; oy = i_oy; oz = i_oz; dx = i_dx; dy = i_dy; dz = i_dz;
            tmin = i_tmin; tmax = i_tmax; cx = i_cx; cy = i_cy; cz = i_cz; r = i_r;
            start = 1'b1;
            @(posedge clk);
            #1 start = 1'b0;
            cyc = 1;
            while (!done) begin
                if (cyc >= MAX_CYCLES)
                    $fatal(1, "tb_ray_sphere: %0s:%0d: no done after %0d cycles", vf_path, vf_lineno, cyc);
                @(posedge clk);
                #1 cyc = cyc + 1;
            end
            if (vf_nvec == 0 || cyc < cyc_min) cyc_min = cyc;
            if (cyc > cyc_max) cyc_max = cyc;
            cyc_sum = cyc_sum + cyc;
            vf_nvec = vf_nvec + 1;
            if ({31'd0, hit} !== x_hit || {24'd0, status} !== x_status) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10)
                    $display("mismatch line %0d: inputs %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h expected %01h %02h got %01h %02h",
                             vf_lineno, i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_tmin, i_tmax,
                             i_cx, i_cy, i_cz, i_r, x_hit[3:0], x_status[7:0], hit, status);
            end
            vf_read_line;
        end

        if (vf_nvec > 0)
            $display("tb_ray_sphere: cycles per vector (start to done): min %0d, avg %0d, max %0d",
                     cyc_min, cyc_sum / vf_nvec, cyc_max);
        vf_finish;
    end
endmodule
