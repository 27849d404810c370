// Testbench for cbvh_axis_decoder (unit 3): runs a golden vector file
// (docs/vectors.md, unit axis_decode) given by +vec=PATH. The file's header must
// match the parameters N, E_MIN and MODULO; every output field is compared.
//   iverilog -g2005 -P tb_axis_decoder.N=6 -P tb_axis_decoder.E_MIN=-30 \
//     -P tb_axis_decoder.MODULO=1 -o tb.vvp gateware/tb/tb_axis_decoder.v \
//     gateware/rtl/axis_decoder.v && vvp tb.vvp +vec=vectors/axis_decode-N6-ms-30-modulo.vec
module tb_axis_decoder;
    parameter integer N      = 6;
    parameter integer E_MIN  = -30;
    parameter integer MODULO = 1;

    localparam LINE_BYTES = 256;

    reg  [7:0]   parent_scale, scale;
    reg  [11:0]  node_lb_mod, lb_code, ub_code;
    reg  [31:0]  node_clb;
    wire [N-1:0] lb_mod, ub_mod;
    wire [7:0]   child_scale;
    wire [31:0]  clb, cub;
    wire [6:0]   status;

    cbvh_axis_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) dut (
        .parent_scale(parent_scale), .scale(scale), .node_lb_mod(node_lb_mod),
        .node_clb(node_clb), .lb_code(lb_code), .ub_code(ub_code),
        .lb_mod(lb_mod), .ub_mod(ub_mod), .child_scale(child_scale),
        .clb(clb), .cub(cub), .status(status));

    reg [8*1024-1:0]         path;
    reg [8*LINE_BYTES-1:0]   line;
    reg [8*64-1:0]           sval;
    integer fd, rc, lineno, nvec, nfail, count, ival;
    integer seen_unit, seen_bits, seen_ms, seen_enc, seen_count, in_header;
    // expected outputs (file fields are wider than the ports: compare as read)
    reg [31:0] x_lb_mod, x_ub_mod, x_cs, x_clb, x_cub, x_status;
    reg [31:0] i_ps, i_sc, i_nlm, i_nclb, i_lb, i_ub;

    task read_line;
        begin
            line = {8*LINE_BYTES{1'b0}};
            rc = $fgets(line, fd);
            lineno = lineno + 1;
        end
    endtask

    initial begin
        if (!$value$plusargs("vec=%s", path))
            $fatal(1, "tb_axis_decoder: no vector file given (+vec=PATH)");
        fd = $fopen(path, "r");
        if (fd == 0)
            $fatal(1, "tb_axis_decoder: cannot open vector file %0s", path);
        lineno = 0; nvec = 0; nfail = 0; count = -1;
        seen_unit = 0; seen_bits = 0; seen_ms = 0; seen_enc = 0; seen_count = 0;

        read_line;
        if (line != {"# cbvh golden vectors", 8'h0A})
            $fatal(1, "tb_axis_decoder: %0s:1: not a cbvh vector file", path);

        // header: key: value lines until ---
        in_header = 1;
        while (in_header) begin
            read_line;
            if (rc == 0)
                $fatal(1, "tb_axis_decoder: %0s: no '---' line", path);
            if (line == {"---", 8'h0A}) begin
                in_header = 0;
            end else begin
                sval = 0;
                if ($sscanf(line, "unit: %s", sval) == 1) begin
                    seen_unit = 1;
                    if (sval != "axis_decode")
                        $fatal(1, "tb_axis_decoder: %0s:%0d: unit %0s, expected axis_decode",
                               path, lineno, sval);
                end else if ($sscanf(line, "quant_bits: %d", ival) == 1) begin
                    seen_bits = 1;
                    if (ival != N)
                        $fatal(1, "tb_axis_decoder: %0s:%0d: quant_bits %0d but N = %0d",
                               path, lineno, ival, N);
                end else if ($sscanf(line, "min_scale: %d", ival) == 1) begin
                    seen_ms = 1;
                    if (ival != E_MIN)
                        $fatal(1, "tb_axis_decoder: %0s:%0d: min_scale %0d but E_MIN = %0d",
                               path, lineno, ival, E_MIN);
                end else if ($sscanf(line, "encoding: %s", sval) == 1) begin
                    seen_enc = 1;
                    if (!((sval == "modulo" && MODULO != 0) || (sval == "relative" && MODULO == 0)))
                        $fatal(1, "tb_axis_decoder: %0s:%0d: encoding %0s but MODULO = %0d",
                               path, lineno, sval, MODULO);
                end else if ($sscanf(line, "count: %d", ival) == 1) begin
                    seen_count = 1;
                    count = ival;
                end
            end
        end
        if (!(seen_unit && seen_bits && seen_ms && seen_enc && seen_count))
            $fatal(1, "tb_axis_decoder: %0s: header lacks unit, quant_bits, min_scale, encoding or count",
                   path);

        // vectors
        read_line;
        while (rc != 0) begin
            if ($sscanf(line, "%h %h %h %h %h %h %h %h %h %h %h %h",
                        i_ps, i_sc, i_nlm, i_nclb, i_lb, i_ub,
                        x_lb_mod, x_ub_mod, x_cs, x_clb, x_cub, x_status) != 12)
                $fatal(1, "tb_axis_decoder: %0s:%0d: malformed vector line", path, lineno);
            parent_scale = i_ps[7:0];
            scale        = i_sc[7:0];
            node_lb_mod  = i_nlm[11:0];
            node_clb     = i_nclb;
            lb_code      = i_lb[11:0];
            ub_code      = i_ub[11:0];
            #1;
            nvec = nvec + 1;
            if ({{(32 - N){1'b0}}, lb_mod} !== x_lb_mod ||
                {{(32 - N){1'b0}}, ub_mod} !== x_ub_mod ||
                {24'd0, child_scale} !== x_cs || clb !== x_clb || cub !== x_cub ||
                {25'd0, status} !== x_status) begin
                nfail = nfail + 1;
                if (nfail <= 10)
                    $display("mismatch line %0d: inputs %02h %02h %03h %08h %03h %03h expected %03h %03h %02h %08h %08h %02h got %03h %03h %02h %08h %08h %02h",
                             lineno, i_ps[7:0], i_sc[7:0], i_nlm[11:0], i_nclb, i_lb[11:0], i_ub[11:0],
                             x_lb_mod[11:0], x_ub_mod[11:0], x_cs[7:0], x_clb, x_cub, x_status[7:0],
                             {{(12 - N){1'b0}}, lb_mod}, {{(12 - N){1'b0}}, ub_mod}, child_scale,
                             clb, cub, {1'b0, status});
            end
            read_line;
        end
        $fclose(fd);

        $display("tb_axis_decoder: %0s: %0d vectors, %0d failures", path, nvec, nfail);
        if (nfail > 0 || nvec == 0 || nvec != count)
            $fatal(1, "tb_axis_decoder: FAILED (%0d failures, %0d vectors, header count %0d)",
                   nfail, nvec, count);
        $finish;
    end
endmodule
