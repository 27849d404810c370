// Testbench for cbvh_scale_estimator: runs one golden vector file (docs/vectors.md).
//   iverilog -g2005 -P tb_scale_estimator.N=6 -P tb_scale_estimator.E_MIN=-30 ...
//   vvp sim +vec=vectors/scale_estimate-N6-ms-30.vec
// No `timescale: the RTL has none either, so both use the simulator default unit.
module tb_scale_estimator;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    localparam integer LW = 8 * 256;   // line buffer: 256 characters

    reg  [31:0] lb, ub;
    wire [7:0]  scale;
    wire [6:0]  status;

    cbvh_scale_estimator #(.N(N), .E_MIN(E_MIN)) dut (
        .lb(lb), .ub(ub), .scale(scale), .status(status)
    );

    reg [LW-1:0]  path;
    reg [LW-1:0]  line;
    reg [LW-1:0]  key;
    reg [LW-1:0]  val;
    integer fd, rc, lineno, nvec, nfail, count, qb, ms;
    reg     seen_unit, seen_qb, seen_ms, seen_count, in_header;
    reg [31:0] v_lb, v_ub, v_scale, v_status;
    reg [LW-1:0] extra;

    // Drop a trailing "\n" ($fgets keeps it; strings are right-aligned).
    function [LW-1:0] chomp;
        input [LW-1:0] s;
        begin
            chomp = (s[7:0] == 8'h0A) ? (s >> 8) : s;
        end
    endfunction

    initial begin
        if (!$value$plusargs("vec=%s", path))
            $fatal(1, "tb_scale_estimator: missing +vec=PATH");
        fd = $fopen(path, "r");
        if (fd == 0)
            $fatal(1, "tb_scale_estimator: cannot open vector file '%0s'", path);

        // ---- header
        lineno = 1;
        line = 0;
        rc = $fgets(line, fd);
        if (rc == 0 || chomp(line) != "# cbvh golden vectors")
            $fatal(1, "tb_scale_estimator: %0s:1: not a cbvh vector file", path);

        seen_unit = 0; seen_qb = 0; seen_ms = 0; seen_count = 0;
        in_header = 1;
        count = -1; qb = -1; ms = 0;
        while (in_header) begin
            line = 0;
            rc = $fgets(line, fd);
            lineno = lineno + 1;
            if (rc == 0)
                $fatal(1, "tb_scale_estimator: %0s: no '---' line after the header", path);
            line = chomp(line);
            if (line == "---") begin
                in_header = 0;
            end else begin
                key = 0; val = 0;
                rc = $sscanf(line, "%s %s", key, val);
                if (rc < 1)
                    $fatal(1, "tb_scale_estimator: %0s:%0d: malformed header line", path, lineno);
                if (key == "unit:") begin
                    seen_unit = 1;
                    if (val != "scale_estimate")
                        $fatal(1, "tb_scale_estimator: %0s:%0d: unit is '%0s', expected 'scale_estimate'",
                               path, lineno, val);
                end else if (key == "quant_bits:") begin
                    seen_qb = 1;
                    rc = $sscanf(val, "%d", qb);
                    if (rc != 1 || qb != N)
                        $fatal(1, "tb_scale_estimator: %0s:%0d: quant_bits '%0s' but the DUT has N = %0d",
                               path, lineno, val, N);
                end else if (key == "min_scale:") begin
                    seen_ms = 1;
                    rc = $sscanf(val, "%d", ms);
                    if (rc != 1 || ms != E_MIN)
                        $fatal(1, "tb_scale_estimator: %0s:%0d: min_scale '%0s' but the DUT has E_MIN = %0d",
                               path, lineno, val, E_MIN);
                end else if (key == "count:") begin
                    seen_count = 1;
                    rc = $sscanf(val, "%d", count);
                    if (rc != 1 || count < 0)
                        $fatal(1, "tb_scale_estimator: %0s:%0d: bad count '%0s'", path, lineno, val);
                end
            end
        end
        if (!(seen_unit && seen_qb && seen_ms && seen_count))
            $fatal(1, "tb_scale_estimator: %0s: header lacks unit, quant_bits, min_scale or count", path);

        // ---- vectors: "LB UB SCALE STATUS" (the "->" is only in the fields header)
        nvec = 0;
        nfail = 0;
        line = 0;
        while ($fgets(line, fd) != 0) begin
            lineno = lineno + 1;
            line = chomp(line);
            extra = 0;
            rc = $sscanf(line, "%h %h %h %h %s", v_lb, v_ub, v_scale, v_status, extra);
            if (rc != 4)
                $fatal(1, "tb_scale_estimator: %0s:%0d: malformed vector line '%0s'", path, lineno, line);
            lb = v_lb;
            ub = v_ub;
            #1;
            nvec = nvec + 1;
            if (scale !== v_scale[7:0] || status !== v_status[6:0] || v_status[31:7] != 0) begin
                nfail = nfail + 1;
                if (nfail <= 10)
                    $display("mismatch line %0d: inputs lb=%h ub=%h expected scale=%h status=%h got scale=%h status=%h",
                             lineno, v_lb, v_ub, v_scale[7:0], v_status[7:0], scale, {1'b0, status});
            end
            line = 0;
        end
        $fclose(fd);

        $display("tb_scale_estimator: %0s: %0d vectors, %0d failures", path, nvec, nfail);
        if (nfail > 0 || nvec == 0 || nvec != count)
            $fatal(1, "tb_scale_estimator: FAILED (%0d failures, %0d vectors, header count %0d)",
                   nfail, nvec, count);
        $finish;
    end
endmodule
