// Testbench for cbvh_ray_box_incr (unit 10): runs a golden vector file
// (docs/vectors.md, unit ray_box_incr) given by +vec=PATH through the
// pipelined unit, one vector per clock it is ready, and compares every output
// of each result (they come back in order) with the file's.
//
// An instance is built for one design point (N from the header; M and X,
// which the file holds per vector in its mant and texp fields).  It runs the
// vectors whose mant and texp are M and X, and, when RUN_INVALID = 1, those
// with a mant outside 3..24 or a texp outside 3..8 (BAD_PARAM for every
// instance); gateware/scripts/run-vectors builds one instance per (mant, texp)
// pair in the file, the first with RUN_INVALID = 1, so every vector runs once.
//   iverilog -g2005 -P tb_ray_box_incr.N=6 -P tb_ray_box_incr.M=8 -s tb_ray_box_incr \
//     -o tb.vvp -I gateware/tb gateware/tb/tb_ray_box_incr.v gateware/rtl/ray_box_incr.v &&
//     vvp tb.vvp +vec=vectors/ray_box_incr-N6-ms-30.vec
module tb_ray_box_incr;
    parameter integer N = 6;
    parameter integer E_MIN = -30;
    parameter integer M = 8;
    parameter integer X = 8;
    parameter integer P = 6;
    parameter integer RUN_INVALID = 1;

    localparam integer QD = 64;            // results in flight, at most
    localparam integer MAX_WAIT = 1000;    // clocks without a result

    reg clk = 1'b0;
    always #5 clk = ~clk;

    reg         in_valid = 1'b0;
    wire        in_ready, out_valid, hit;
    reg  [31:0] rcp_x, rcp_y, rcp_z, tmin, tmax, x_t_lb, x_t_ub, y_t_lb, y_t_ub, z_t_lb, z_t_ub;
    reg  [7:0]  mant, texp, x_scale, y_scale, z_scale;
    reg  [11:0] x_r, x_sp, y_r, y_sp, z_r, z_sp;
    wire [31:0] t_near, t_far, x_c_lb, x_c_ub, y_c_lb, y_c_ub, z_c_lb, z_c_ub;
    wire [7:0]  status;

    cbvh_ray_box_incr #(.N(N), .M(M), .X(X), .P(P)) dut (
        .clk(clk), .in_valid(in_valid), .in_ready(in_ready),
        .rcp_x(rcp_x), .rcp_y(rcp_y), .rcp_z(rcp_z), .tmin(tmin), .tmax(tmax), .mant(mant), .texp(texp),
        .x_t_lb(x_t_lb), .x_t_ub(x_t_ub), .x_scale(x_scale), .x_r(x_r), .x_sp(x_sp),
        .y_t_lb(y_t_lb), .y_t_ub(y_t_ub), .y_scale(y_scale), .y_r(y_r), .y_sp(y_sp),
        .z_t_lb(z_t_lb), .z_t_ub(z_t_ub), .z_scale(z_scale), .z_r(z_r), .z_sp(z_sp),
        .out_valid(out_valid), .hit(hit), .t_near(t_near), .t_far(t_far),
        .x_c_lb(x_c_lb), .x_c_ub(x_c_ub), .y_c_lb(y_c_lb), .y_c_ub(y_c_ub), .z_c_lb(z_c_lb), .z_c_ub(z_c_ub),
        .status(status));

    localparam [8*24-1:0] VF_TB = "tb_ray_box_incr", VF_UNIT = "ray_box_incr";
    localparam integer VF_ENC = 0, VF_MODULO = 0;
    `include "vecfile.vh"

    // the expected outputs of the vectors in flight, and their line numbers
    reg [31:0] q_w [0:QD*10-1];
    integer    q_line [0:QD-1];
    integer    qh, qt, nq, nskip, wait_cyc, i;
    reg [31:0] got [0:9];

    task check_result;   // the oldest vector in flight against the outputs now
        begin
            got[0] = {31'd0, hit}; got[1] = t_near; got[2] = t_far; got[3] = x_c_lb; got[4] = x_c_ub;
            got[5] = y_c_lb; got[6] = y_c_ub; got[7] = z_c_lb; got[8] = z_c_ub; got[9] = {24'd0, status};
            vf_nvec = vf_nvec + 1;
            for (i = 0; i < 10; i = i + 1)
                if (got[i] !== q_w[qh * 10 + i]) begin
                    if (vf_nfail < 10)
                        $display("mismatch line %0d: output %0d is %08h, expected %08h (hit %0d status %02h)",
                                 q_line[qh], i, got[i], q_w[qh * 10 + i], hit, status);
                    vf_nfail = vf_nfail + 1;
                    i = 10;
                end
            qh = (qh + 1) % QD;
            nq = nq - 1;
        end
    endtask

    function param_ok;   // mant and texp in the unit's ranges
        input [31:0] m, x;
        param_ok = m >= 3 && m <= 24 && x >= 3 && x <= 8;
    endfunction

    initial begin
        vf_open;
        qh = 0; qt = 0; nq = 0; nskip = 0;
        repeat (2) @(posedge clk);
        vf_read_line;
        while (vf_rc != 0 || nq > 0) begin
            // present the next vector this unit runs (or nothing)
            #1;
            in_valid = 1'b0;
            while (vf_rc != 0 && !in_valid) begin
                if (vf_nw != 32)
                    $fatal(1, "tb_ray_box_incr: %0s:%0d: malformed vector line", vf_path, vf_lineno);
                if (param_ok(vf_w[5], vf_w[6]) ? (vf_w[5] == M && vf_w[6] == X) : (RUN_INVALID != 0)) begin
                    {rcp_x, rcp_y, rcp_z, tmin, tmax} = {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4]};
                    mant = vf_w[5][7:0]; texp = vf_w[6][7:0];
                    {x_t_lb, x_t_ub} = {vf_w[7], vf_w[8]};
                    x_scale = vf_w[9][7:0]; x_r = vf_w[10][11:0]; x_sp = vf_w[11][11:0];
                    {y_t_lb, y_t_ub} = {vf_w[12], vf_w[13]};
                    y_scale = vf_w[14][7:0]; y_r = vf_w[15][11:0]; y_sp = vf_w[16][11:0];
                    {z_t_lb, z_t_ub} = {vf_w[17], vf_w[18]};
                    z_scale = vf_w[19][7:0]; z_r = vf_w[20][11:0]; z_sp = vf_w[21][11:0];
                    for (i = 0; i < 10; i = i + 1) q_w[qt * 10 + i] = vf_w[22 + i];
                    q_line[qt] = vf_lineno;
                    in_valid = 1'b1;
                end else begin
                    nskip = nskip + 1;
                    vf_read_line;
                end
            end
            @(posedge clk);
            if (in_valid && in_ready) begin   // taken at this edge
                qt = (qt + 1) % QD;
                nq = nq + 1;
                if (nq == QD) $fatal(1, "tb_ray_box_incr: more than %0d results in flight", QD);
                vf_read_line;
            end
            if (out_valid) begin
                if (nq == 0) $fatal(1, "tb_ray_box_incr: a result with no vector");
                check_result;
                wait_cyc = 0;
            end else if (nq > 0) begin
                wait_cyc = wait_cyc + 1;
                if (wait_cyc > MAX_WAIT) $fatal(1, "tb_ray_box_incr: no result for %0d clocks", MAX_WAIT);
            end
        end
        // every vector of the file was run or left to another instance
        $fclose(vf_fd);
        $display("tb_ray_box_incr: %0s: %0d vectors, %0d failures", vf_path, vf_nvec, vf_nfail);
        if (vf_nfail > 0 || vf_nvec + nskip != vf_count)
            $fatal(1, "tb_ray_box_incr: FAILED (%0d failures, %0d vectors run, %0d left to other instances, header count %0d)",
                   vf_nfail, vf_nvec, nskip, vf_count);
        $finish;
    end
endmodule
