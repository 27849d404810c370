// A DPI-C scoreboard for any unit (docs/gateware.md, "DPI-C scoreboard"):
// random input words from the C model's stimulus go into the unit's word
// wrapper on every clock it is ready, and every result the wrapper returns
// is compared, in order, with the C model's outputs for the same words
// (cbvh_dpi_eval, the unit table's eval).  Built by
// gateware/scripts/dpi-scoreboard with
//   -DDPI_WORDS=<wrapper module #(parameters)>  -DDPI_UNIT='"<unit>"'
//   -DDPI_N=<N> -DDPI_EMIN=<min scale> -DDPI_MODULO=<0|1> -DDPI_PINS='"<name=value,...>"'
// Plusargs: +tests=K (default 10^6), +seed=S.  Prints one summary line
//   tb_dpi: <unit> <pins>: K tests, F failures, C cycles (II x.xx), latency L, V valid, H hits
// (V: results with status 0, H: with hit = 1, for units with such fields)
// and ends with $fatal (exit 1) on any mismatch.
module tb_dpi;
    `include "cbvh_dpi.svh"

    bit clk = 1'b0;
    always #5 clk = ~clk;

    bit [31:0] in_w [0:39];
    bit [31:0] out_w [0:39];
    bit        in_valid = 1'b0;
    wire       in_ready, out_valid;

    `DPI_WORDS dut (.clk(clk), .in_valid(in_valid), .in_ready(in_ready), .in_w(in_w),
                    .out_valid(out_valid), .out_w(out_w));

    localparam int QD = 256;          // results in flight, at most
    localparam int MAX_WAIT = 100000; // clocks without a result before giving up
    bit [31:0] q_out [0:QD-1][0:39];
    bit [31:0] q_in  [0:QD-1][0:39];
    longint    q_cyc [0:QD-1];
    int qh = 0, qt = 0, h, nin, nout, seed = 1, tests = 1000000, latency = -1, idle = 0;
    longint sent = 0, checked = 0, fails = 0, cycles = 0, first_in = -1, last_out = 0, nvalid = 0, nhit = 0;
    int f_status = -1, f_hit = -1;
    string unit = `DPI_UNIT, pins = `DPI_PINS;
    bit [31:0] nw [0:39];
    bit [31:0] ew [0:39];

    initial begin
        void'($value$plusargs("tests=%d", tests));
        void'($value$plusargs("seed=%d", seed));
        h = cbvh_dpi_open(unit, `DPI_N, `DPI_EMIN, `DPI_MODULO, pins, seed);
        if (h < 0) $fatal(1, "tb_dpi: %s: cbvh_dpi_open failed", unit);
        nin = cbvh_dpi_n_in(h);
        nout = cbvh_dpi_n_out(h);
        for (int i = 0; i < nout; i++) begin
            if (cbvh_dpi_field(h, 1, i) == "status") f_status = i;
            if (cbvh_dpi_field(h, 1, i) == "hit") f_hit = i;
        end
    end

    always @(posedge clk) begin
        cycles = cycles + 1;
        if (out_valid) begin
            if (qh == qt) $fatal(1, "tb_dpi: %s: a result with no input", unit);
            if (latency < 0) latency = int'(cycles - q_cyc[qh]);
            for (int i = 0; i < nout; i++)
                if (out_w[i] != q_out[qh][i]) begin
                    fails = fails + 1;
                    if (fails <= 10) begin
                        $display("tb_dpi: %s: test %0d: %s = %08h, model %08h; inputs:", unit, checked,
                                 cbvh_dpi_field(h, 1, i), out_w[i], q_out[qh][i]);
                        for (int j = 0; j < nin; j++) $display("    %s = %08h", cbvh_dpi_field(h, 0, j), q_in[qh][j]);
                    end
                    break;
                end
            qh = (qh + 1) % QD;
            checked = checked + 1;
            last_out = cycles;
            idle = 0;
        end else if (qh != qt) begin
            idle = idle + 1;
            if (idle > MAX_WAIT) $fatal(1, "tb_dpi: %s: no result for %0d clocks", unit, MAX_WAIT);
        end
        if (in_valid && in_ready) begin   // the wrapper takes in_w at this edge
            cbvh_dpi_eval(h, in_w, ew);
            if (f_status >= 0 && ew[f_status] == 32'd0) nvalid = nvalid + 1;
            if (f_hit >= 0 && ew[f_hit] == 32'd1) nhit = nhit + 1;
            q_out[qt] = ew;
            q_in[qt] = in_w;
            q_cyc[qt] = cycles;
            if (first_in < 0) first_in = cycles;
            qt = (qt + 1) % QD;
            if (qt == qh) $fatal(1, "tb_dpi: %s: more than %0d results in flight", unit, QD);
            sent = sent + 1;
        end
        if (sent < tests) begin
            if (!in_valid || in_ready) begin
                cbvh_dpi_stimulus(h, nw);
                in_w <= nw;
                in_valid <= 1'b1;
            end
        end else begin
            in_valid <= 1'b0;
            if (checked == sent) begin
                $display("tb_dpi: %s %s: %0d tests, %0d failures, %0d cycles (II %0.2f), latency %0d, %0d valid, %0d hits",
                         unit, pins, checked, fails, last_out - first_in,
                         real'(last_out - first_in - latency + 1) / real'(checked), latency, nvalid, nhit);
                if (fails != 0) $fatal(1, "tb_dpi: %s: %0d failures", unit, fails);
                $finish;
            end
        end
    end
endmodule
