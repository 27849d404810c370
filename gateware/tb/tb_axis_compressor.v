// Testbench for cbvh_axis_compressor: runs a golden vector file (docs/vectors.md).
//   iverilog -g2005 -P tb_axis_compressor.N=6 -P tb_axis_compressor.E_MIN=-30 \
//       -o tb gateware/tb/tb_axis_compressor.v gateware/rtl/axis_compressor.v
//   vvp tb +vec=vectors/axis_compress-N6-ms-30.vec
module tb_axis_compressor;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    localparam integer LW = 8 * 512;      // line buffer, bits

    reg  [31:0]  lb, ub;
    reg  [7:0]   scale;
    wire [N-1:0] lb_mod, ub_mod;
    wire [7:0]   child_scale;
    wire [31:0]  clb, cub;
    wire [6:0]   status;

    cbvh_axis_compressor #(.N(N), .E_MIN(E_MIN)) dut (
        .lb(lb), .ub(ub), .scale(scale), .lb_mod(lb_mod), .ub_mod(ub_mod),
        .child_scale(child_scale), .clb(clb), .cub(cub), .status(status));

    reg [8*1024-1:0] path;
    reg [LW-1:0]     line;
    reg [LW-1:0]     key, val, extra;
    integer fd, rc, lineno, nvec, nfail, count, qbits, mscale;
    integer have_unit, have_q, have_m, have_count, in_header;
    reg [31:0] i_lb, i_ub, x_clb, x_cub;
    reg [31:0] i_sc, x_lm, x_um, x_cs, x_st;

    // read one line into 'line' (zero-padded); returns chars read, 0 at EOF
    task read_line(output integer n);
        begin
            line = {LW{1'b0}};
            n = $fgets(line, fd);
            lineno = lineno + 1;
        end
    endtask

    initial begin
        if (!$value$plusargs("vec=%s", path))
            $fatal(1, "tb_axis_compressor: missing +vec=PATH");
        fd = $fopen(path, "r");
        if (fd == 0)
            $fatal(1, "tb_axis_compressor: cannot open vector file %0s", path);
        lineno = 0; nvec = 0; nfail = 0; count = -1;
        have_unit = 0; have_q = 0; have_m = 0; have_count = 0;

        read_line(rc);
        if (rc == 0 || line != "# cbvh golden vectors\n")
            $fatal(1, "tb_axis_compressor: %0s:1: not a cbvh vector file", path);

        // header: key: value lines up to ---
        in_header = 1;
        while (in_header) begin
            read_line(rc);
            if (rc == 0)
                $fatal(1, "tb_axis_compressor: %0s: no '---' line", path);
            if (line == "---\n") begin
                in_header = 0;
            end else begin
                key = {LW{1'b0}}; val = {LW{1'b0}};
                rc = $sscanf(line, "%s %s", key, val);
                if (key == "unit:") begin
                    have_unit = 1;
                    if (val != "axis_compress")
                        $fatal(1, "tb_axis_compressor: %0s:%0d: unit is '%0s', expected axis_compress",
                               path, lineno, val);
                end else if (key == "quant_bits:") begin
                    have_q = 1;
                    rc = $sscanf(line, "quant_bits: %d", qbits);
                    if (rc != 1 || qbits != N)
                        $fatal(1, "tb_axis_compressor: %0s:%0d: quant_bits %0d but the testbench has N=%0d",
                               path, lineno, qbits, N);
                end else if (key == "min_scale:") begin
                    have_m = 1;
                    rc = $sscanf(line, "min_scale: %d", mscale);
                    if (rc != 1 || mscale != E_MIN)
                        $fatal(1, "tb_axis_compressor: %0s:%0d: min_scale %0d but the testbench has E_MIN=%0d",
                               path, lineno, mscale, E_MIN);
                end else if (key == "count:") begin
                    have_count = 1;
                    rc = $sscanf(line, "count: %d", count);
                    if (rc != 1 || count < 0)
                        $fatal(1, "tb_axis_compressor: %0s:%0d: bad count", path, lineno);
                end
            end
        end
        if (!have_unit || !have_q || !have_m || !have_count)
            $fatal(1, "tb_axis_compressor: %0s: header lacks unit, quant_bits, min_scale or count", path);

        // vectors: lb ub scale -> lb_mod ub_mod child_scale clb cub status
        read_line(rc);
        while (rc != 0) begin
            // 9 hex fields; 'extra' catches a tenth one
            extra = {LW{1'b0}};
            rc = $sscanf(line, "%h %h %h %h %h %h %h %h %h %s",
                         i_lb, i_ub, i_sc, x_lm, x_um, x_cs, x_clb, x_cub, x_st, extra);
            if (rc != 9)
                $fatal(1, "tb_axis_compressor: %0s:%0d: malformed vector line", path, lineno);
            lb = i_lb; ub = i_ub; scale = i_sc[7:0];
            #1;
            nvec = nvec + 1;
            if (x_lm !== {{(32-N){1'b0}}, lb_mod} || x_um !== {{(32-N){1'b0}}, ub_mod} ||
                x_cs !== {24'd0, child_scale} || clb !== x_clb || cub !== x_cub ||
                x_st !== {25'd0, status}) begin
                nfail = nfail + 1;
                if (nfail <= 10)
                    $display("mismatch line %0d: inputs lb=%08h ub=%08h scale=%02h expected %03h %03h %02h %08h %08h %02h got %03h %03h %02h %08h %08h %02h",
                             lineno, i_lb, i_ub, i_sc[7:0],
                             x_lm[11:0], x_um[11:0], x_cs[7:0], x_clb, x_cub, x_st[7:0],
                             {{(12-N){1'b0}}, lb_mod}, {{(12-N){1'b0}}, ub_mod}, child_scale,
                             clb, cub, {1'b0, status});
            end
            read_line(rc);
        end
        $fclose(fd);

        $display("tb_axis_compressor: %0s: %0d vectors, %0d failures", path, nvec, nfail);
        if (nfail > 0 || nvec == 0 || nvec != count)
            $fatal(1, "tb_axis_compressor: FAIL (%0d failures, %0d vectors, header count %0d)",
                   nfail, nvec, count);
        $finish;
    end
endmodule
