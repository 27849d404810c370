// Golden vector file reader shared by the testbenches (docs/vectors.md).
// `include it inside a testbench module that defines, before the include:
//   parameter integer N, E_MIN                  the instance's design point
//   localparam [8*24-1:0] VF_TB   = "tb_<unit>" the name in messages and the summary
//   localparam [8*24-1:0] VF_UNIT = "<unit>"    the header's unit
//   localparam integer VF_ENC     = 0 or 1      1: the header has an encoding ...
//   localparam integer VF_MODULO  = 0 or 1      ... which must be modulo (1) or relative (0)
// vf_open takes the file from +vec=PATH, checks the first line and the header
// (unit, quant_bits = N, min_scale = E_MIN, encoding, count) and stops with
// $fatal on any mismatch, so a file run with the wrong parameters cannot pass.
// The testbench then calls vf_read_line until vf_rc is 0, counting vf_nvec and
// vf_nfail, and ends with vf_finish: one summary line
// "tb_<unit>: PATH: V vectors, F failures" and $fatal unless every vector
// passed, at least one ran and their number equals the header's count.

    localparam VF_LINE_BYTES = 1024;

    reg [8*1024-1:0]          vf_path;
    reg [8*VF_LINE_BYTES-1:0] vf_line;
    reg [8*64-1:0]            vf_sval;
    reg [8*24-1:0]            vf_tb, vf_unit;  // Icarus prints string parameters as empty: copies
    integer vf_fd, vf_rc, vf_lineno, vf_count, vf_nvec, vf_nfail, vf_ival;
    integer vf_seen_unit, vf_seen_bits, vf_seen_ms, vf_seen_enc, vf_seen_count, vf_in_header;

    // vf_line without its trailing newline ($fgets keeps it; strings are right-aligned)
    function [8*VF_LINE_BYTES-1:0] vf_chomp;
        input [8*VF_LINE_BYTES-1:0] l;
        begin
            vf_chomp = (l[7:0] == 8'h0A) ? (l >> 8) : l;
        end
    endfunction

    task vf_read_line;
        begin
            vf_line = {8*VF_LINE_BYTES{1'b0}};
            vf_rc = $fgets(vf_line, vf_fd);
            vf_lineno = vf_lineno + 1;
        end
    endtask

    task vf_open;
        begin
            vf_tb = VF_TB;
            vf_unit = VF_UNIT;
            if (!$value$plusargs("vec=%s", vf_path))
                $fatal(1, "%0s: no vector file given (+vec=PATH)", vf_tb);
            vf_fd = $fopen(vf_path, "r");
            if (vf_fd == 0)
                $fatal(1, "%0s: cannot open vector file %0s", vf_tb, vf_path);
            vf_lineno = 0; vf_nvec = 0; vf_nfail = 0; vf_count = -1;
            vf_seen_unit = 0; vf_seen_bits = 0; vf_seen_ms = 0; vf_seen_enc = 0; vf_seen_count = 0;

            vf_read_line;
            if (vf_line != {"# cbvh golden vectors", 8'h0A})
                $fatal(1, "%0s: %0s:1: not a cbvh vector file", vf_tb, vf_path);
            vf_in_header = 1;
            while (vf_in_header) begin
                vf_read_line;
                if (vf_rc == 0)
                    $fatal(1, "%0s: %0s: no '---' line", vf_tb, vf_path);
                if (vf_line == {"---", 8'h0A}) begin
                    vf_in_header = 0;
                end else begin
                    vf_sval = 0;
                    if ($sscanf(vf_line, "unit: %s", vf_sval) == 1) begin
                        vf_seen_unit = 1;
                        if (vf_sval != vf_unit)
                            $fatal(1, "%0s: %0s:%0d: unit %0s, expected %0s",
                                   vf_tb, vf_path, vf_lineno, vf_sval, vf_unit);
                    end else if ($sscanf(vf_line, "quant_bits: %d", vf_ival) == 1) begin
                        vf_seen_bits = 1;
                        if (vf_ival != N)
                            $fatal(1, "%0s: %0s:%0d: quant_bits %0d but N = %0d",
                                   vf_tb, vf_path, vf_lineno, vf_ival, N);
                    end else if ($sscanf(vf_line, "min_scale: %d", vf_ival) == 1) begin
                        vf_seen_ms = 1;
                        if (vf_ival != E_MIN)
                            $fatal(1, "%0s: %0s:%0d: min_scale %0d but E_MIN = %0d",
                                   vf_tb, vf_path, vf_lineno, vf_ival, E_MIN);
                    end else if ($sscanf(vf_line, "encoding: %s", vf_sval) == 1) begin
                        vf_seen_enc = 1;
                        if (VF_ENC == 0 ||
                            !((vf_sval == "modulo" && VF_MODULO != 0) || (vf_sval == "relative" && VF_MODULO == 0)))
                            $fatal(1, "%0s: %0s:%0d: encoding %0s does not match this instance",
                                   vf_tb, vf_path, vf_lineno, vf_sval);
                    end else if ($sscanf(vf_line, "count: %d", vf_ival) == 1) begin
                        vf_seen_count = 1;
                        vf_count = vf_ival;
                    end
                end
            end
            if (!(vf_seen_unit && vf_seen_bits && vf_seen_ms && vf_seen_count && vf_seen_enc == VF_ENC))
                $fatal(1, "%0s: %0s: header lacks unit, quant_bits, min_scale, count or encoding",
                       vf_tb, vf_path);
        end
    endtask

    task vf_finish;
        begin
            $fclose(vf_fd);
            $display("%0s: %0s: %0d vectors, %0d failures", vf_tb, vf_path, vf_nvec, vf_nfail);
            if (vf_nfail > 0 || vf_nvec == 0 || vf_nvec != vf_count)
                $fatal(1, "%0s: FAILED (%0d failures, %0d vectors, header count %0d)",
                       vf_tb, vf_nfail, vf_nvec, vf_count);
            $finish;
        end
    endtask
