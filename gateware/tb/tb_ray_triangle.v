// Testbench for cbvh_ray_triangle (unit 7): runs a golden vector file
// (docs/vectors.md, unit ray_triangle) given by +vec=PATH. The unit depends
// on neither N nor e_min; the parameters are only checked against the header.
// Every vector: drive the inputs, pulse start, wait for done (at most
// MAX_CYCLES clocks), compare hit, t, b1, b2 and status.
//   iverilog -g2005 -P tb_ray_triangle.N=6 -P tb_ray_triangle.E_MIN=-30 -s tb_ray_triangle \
//     -I gateware/tb -o tb.vvp gateware/tb/tb_ray_triangle.v gateware/rtl/*.v &&
//     vvp tb.vvp +vec=vectors/ray_triangle-N6-ms-30.vec
module tb_ray_triangle;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    // the unit's worst case is about 6,500 cycles (every monomial's carry
    // rippling to the accumulator's top word, then three 25-step divisions)
    localparam integer MAX_CYCLES = 20000;

    reg clk = 1'b0;
    reg rst = 1'b1;
    reg start = 1'b0;
    wire busy, done;
    reg  [31:0] ox, oy, oz, dx, dy, dz, v0x, v0y, v0z, v1x, v1y, v1z, v2x, v2y, v2z;
    wire        hit;
    wire [31:0] t, b1, b2;
    wire [7:0]  status;

    cbvh_ray_triangle dut (
        .clk(clk), .rst(rst), .start(start), .busy(busy), .done(done),
        .ox(ox), .oy(oy), .oz(oz), .dx(dx), .dy(dy), .dz(dz),
        .v0x(v0x), .v0y(v0y), .v0z(v0z), .v1x(v1x), .v1y(v1y), .v1z(v1z),
        .v2x(v2x), .v2y(v2y), .v2z(v2z),
        .hit(hit), .t(t), .b1(b1), .b2(b2), .status(status));

    always #5 clk = ~clk;

    localparam [8*24-1:0] VF_TB = "tb_ray_triangle", VF_UNIT = "ray_triangle";
    localparam integer VF_ENC = 0, VF_MODULO = 0;
    `include "vecfile.vh"

    integer cyc, cyc_min, cyc_max, cyc_sum;
    reg [31:0] i_ox, i_oy, i_oz, i_dx, i_dy, i_dz;
    reg [31:0] i_v0x, i_v0y, i_v0z, i_v1x, i_v1y, i_v1z, i_v2x, i_v2y, i_v2z;
    reg [31:0] x_hit, x_t, x_b1, x_b2, x_status;

    initial begin
        vf_open;
        cyc_min = 0; cyc_max = 0; cyc_sum = 0;

        // reset
        repeat (2) @(posedge clk);
        #1 rst = 1'b0;

        // "OX OY OZ DX DY DZ V0X V0Y V0Z V1X V1Y V1Z V2X V2Y V2Z HIT T B1 B2 STATUS"
        vf_read_line;
        while (vf_rc != 0) begin
            {i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_v0x, i_v0y, i_v0z, i_v1x, i_v1y, i_v1z, i_v2x, i_v2y,
                i_v2z, x_hit, x_t, x_b1, x_b2, x_status} =
                {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4], vf_w[5], vf_w[6], vf_w[7], vf_w[8], vf_w[9],
                vf_w[10], vf_w[11], vf_w[12], vf_w[13], vf_w[14], vf_w[15], vf_w[16], vf_w[17], vf_w[18],
                vf_w[19]};
            if (vf_nw != 20)
                $fatal(1, "tb_ray_triangle: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            ox = i_ox; oy = i_oy; oz = i_oz; dx = i_dx; dy = i_dy; dz = i_dz;
            v0x = i_v0x; v0y = i_v0y; v0z = i_v0z; v1x = i_v1x; v1y = i_v1y; v1z = i_v1z;
            v2x = i_v2x; v2y = i_v2y; v2z = i_v2z;
            start = 1'b1;
            @(posedge clk);
            #1 start = 1'b0;
            cyc = 1;
            while (!done) begin
                if (cyc >= MAX_CYCLES)
                    $fatal(1, "tb_ray_triangle: %0s:%0d: no done after %0d cycles", vf_path, vf_lineno, cyc);
                @(posedge clk);
                #1 cyc = cyc + 1;
            end
            if (vf_nvec == 0 || cyc < cyc_min) cyc_min = cyc;
            if (cyc > cyc_max) cyc_max = cyc;
            cyc_sum = cyc_sum + cyc;
            vf_nvec = vf_nvec + 1;
            if ({31'd0, hit} !== x_hit || t !== x_t || b1 !== x_b1 || b2 !== x_b2 ||
                {24'd0, status} !== x_status) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10)
                    $display("mismatch line %0d: inputs %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h %08h expected %01h %08h %08h %08h %02h got %01h %08h %08h %08h %02h",
                             vf_lineno, i_ox, i_oy, i_oz, i_dx, i_dy, i_dz, i_v0x, i_v0y, i_v0z,
                             i_v1x, i_v1y, i_v1z, i_v2x, i_v2y, i_v2z,
                             x_hit[3:0], x_t, x_b1, x_b2, x_status[7:0], hit, t, b1, b2, status);
            end
            vf_read_line;
        end

        if (vf_nvec > 0)
            $display("tb_ray_triangle: cycles per vector (start to done): min %0d, avg %0d, max %0d",
                     cyc_min, cyc_sum / vf_nvec, cyc_max);
        vf_finish;
    end
endmodule
