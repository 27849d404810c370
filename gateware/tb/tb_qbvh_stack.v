// Testbench for cbvh_qbvh_stack: runs one golden vector file (docs/vectors.md).
//   iverilog -g2005 -P tb_qbvh_stack.N=6 -P tb_qbvh_stack.E_MIN=-30 ...
//   vvp sim +vec=vectors/qbvh_stack-N6-ms-30.vec
// The unit does not depend on N or e_min (docs/qbvh.md): the parameters are only
// checked against the file's header, as the runner passes them from it.
// No `timescale: the RTL has none either, so both use the simulator default unit.
module tb_qbvh_stack;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    localparam integer LW = 8 * 256;   // line buffer: 256 characters

    reg  [3:0]  op, hit_mask;
    reg  [31:0] first, t0, t1, t2, t3, entry;
    wire [31:0] node, next_entry;
    wire        write;
    wire [7:0]  order;
    wire [3:0]  nhit;
    wire [7:0]  status;

    cbvh_qbvh_stack dut (
        .op(op), .first(first), .hit_mask(hit_mask),
        .t0(t0), .t1(t1), .t2(t2), .t3(t3), .entry(entry),
        .node(node), .next_entry(next_entry), .write(write),
        .order(order), .nhit(nhit), .status(status)
    );

    reg [LW-1:0]  path;
    reg [LW-1:0]  line;
    reg [LW-1:0]  key;
    reg [LW-1:0]  val;
    integer fd, rc, lineno, nvec, nfail, count, qb, ms;
    reg     seen_unit, seen_qb, seen_ms, seen_count, in_header;
    reg [31:0] v_op, v_first, v_mask, v_t0, v_t1, v_t2, v_t3, v_entry;
    reg [31:0] v_node, v_next, v_write, v_order, v_nhit, v_status;
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
            $fatal(1, "tb_qbvh_stack: missing +vec=PATH");
        fd = $fopen(path, "r");
        if (fd == 0)
            $fatal(1, "tb_qbvh_stack: cannot open vector file '%0s'", path);

        // ---- header
        lineno = 1;
        line = 0;
        rc = $fgets(line, fd);
        if (rc == 0 || chomp(line) != "# cbvh golden vectors")
            $fatal(1, "tb_qbvh_stack: %0s:1: not a cbvh vector file", path);

        seen_unit = 0; seen_qb = 0; seen_ms = 0; seen_count = 0;
        in_header = 1;
        count = -1; qb = -1; ms = 0;
        while (in_header) begin
            line = 0;
            rc = $fgets(line, fd);
            lineno = lineno + 1;
            if (rc == 0)
                $fatal(1, "tb_qbvh_stack: %0s: no '---' line after the header", path);
            line = chomp(line);
            if (line == "---") begin
                in_header = 0;
            end else begin
                key = 0; val = 0;
                rc = $sscanf(line, "%s %s", key, val);
                if (rc < 1)
                    $fatal(1, "tb_qbvh_stack: %0s:%0d: malformed header line", path, lineno);
                if (key == "unit:") begin
                    seen_unit = 1;
                    if (val != "qbvh_stack")
                        $fatal(1, "tb_qbvh_stack: %0s:%0d: unit is '%0s', expected 'qbvh_stack'",
                               path, lineno, val);
                end else if (key == "quant_bits:") begin
                    seen_qb = 1;
                    rc = $sscanf(val, "%d", qb);
                    if (rc != 1 || qb != N)
                        $fatal(1, "tb_qbvh_stack: %0s:%0d: quant_bits '%0s' but the testbench has N = %0d",
                               path, lineno, val, N);
                end else if (key == "min_scale:") begin
                    seen_ms = 1;
                    rc = $sscanf(val, "%d", ms);
                    if (rc != 1 || ms != E_MIN)
                        $fatal(1, "tb_qbvh_stack: %0s:%0d: min_scale '%0s' but the testbench has E_MIN = %0d",
                               path, lineno, val, E_MIN);
                end else if (key == "count:") begin
                    seen_count = 1;
                    rc = $sscanf(val, "%d", count);
                    if (rc != 1 || count < 0)
                        $fatal(1, "tb_qbvh_stack: %0s:%0d: bad count '%0s'", path, lineno, val);
                end
            end
        end
        if (!(seen_unit && seen_qb && seen_ms && seen_count))
            $fatal(1, "tb_qbvh_stack: %0s: header lacks unit, quant_bits, min_scale or count", path);

        // ---- vectors: "OP FIRST HIT_MASK T0 T1 T2 T3 ENTRY NODE NEXT_ENTRY WRITE ORDER NHIT STATUS"
        // (the "->" is only in the fields header)
        nvec = 0;
        nfail = 0;
        line = 0;
        while ($fgets(line, fd) != 0) begin
            lineno = lineno + 1;
            line = chomp(line);
            extra = 0;
            rc = $sscanf(line, "%h %h %h %h %h %h %h %h %h %h %h %h %h %h %s",
                         v_op, v_first, v_mask, v_t0, v_t1, v_t2, v_t3, v_entry,
                         v_node, v_next, v_write, v_order, v_nhit, v_status, extra);
            if (rc != 14)
                $fatal(1, "tb_qbvh_stack: %0s:%0d: malformed vector line '%0s'", path, lineno, line);
            // inputs wider than their port cannot be driven faithfully
            if (v_op[31:4] != 0 || v_mask[31:4] != 0)
                $fatal(1, "tb_qbvh_stack: %0s:%0d: op or hit_mask wider than 4 bits", path, lineno);
            op       = v_op[3:0];
            first    = v_first;
            hit_mask = v_mask[3:0];
            t0       = v_t0;
            t1       = v_t1;
            t2       = v_t2;
            t3       = v_t3;
            entry    = v_entry;
            #1;
            nvec = nvec + 1;
            if (node !== v_node || next_entry !== v_next ||
                write !== v_write[0] || v_write[31:1] != 0 ||
                order !== v_order[7:0] || v_order[31:8] != 0 ||
                nhit !== v_nhit[3:0] || v_nhit[31:4] != 0 ||
                status !== v_status[7:0] || v_status[31:8] != 0) begin
                nfail = nfail + 1;
                if (nfail <= 10)
                    $display("mismatch line %0d: inputs op=%h first=%h hit_mask=%h t=%h %h %h %h entry=%h expected node=%h next_entry=%h write=%h order=%h nhit=%h status=%h got node=%h next_entry=%h write=%h order=%h nhit=%h status=%h",
                             lineno, v_op[3:0], v_first, v_mask[3:0], v_t0, v_t1, v_t2, v_t3, v_entry,
                             v_node, v_next, v_write[3:0], v_order[7:0], v_nhit[3:0], v_status[7:0],
                             node, next_entry, {3'b000, write}, order, nhit, status);
            end
            line = 0;
        end
        $fclose(fd);

        $display("tb_qbvh_stack: %0s: %0d vectors, %0d failures", path, nvec, nfail);
        if (nfail > 0 || nvec == 0 || nvec != count)
            $fatal(1, "tb_qbvh_stack: FAILED (%0d failures, %0d vectors, header count %0d)",
                   nfail, nvec, count);
        $finish;
    end
endmodule
