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
// The testbench then calls vf_read_line until vf_rc is 0, takes each line's
// fields from vf_w[0 .. vf_nw-1], counting vf_nvec and
// vf_nfail, and ends with vf_finish: one summary line
// "tb_<unit>: PATH: V vectors, F failures" and $fatal unless every vector
// passed, at least one ran and their number equals the header's count.

    // Data lines are read a field at a time ($fscanf "%h%c": the number and
    // the character after it), header lines a character at a time; not with
    // $fgets and $sscanf into one wide string, which Verilator cannot take
    // (strings are limited to 2,048 bits, VL_VALUE_STRING_MAX_WORDS; data
    // lines run to ~500 characters).  Per field, not per character: Icarus
    // keeps its speed.
    localparam VF_HEAD_BYTES = 128;
    localparam VF_MAX_WORDS  = 64;

    reg [8*1024-1:0]  vf_path;
    reg [7:0]         vf_buf [0:VF_HEAD_BYTES-1];  // a header line's first characters
    integer           vf_len;                      // its length
    reg [31:0]        vf_w [0:VF_MAX_WORDS-1];     // a data line's hex fields ...
    integer           vf_nw;                       // ... their number, or -1: a field is not hex
                                                   // or not below 2^32, or there are too many
    reg [8*64-1:0]    vf_sval;
    reg [8*24-1:0]    vf_tb, vf_unit;  // Icarus prints string parameters as empty: copies
    integer vf_fd, vf_rc, vf_lineno, vf_count, vf_nvec, vf_nfail, vf_ival, vf_c, vf_more;
    integer vf_seen_unit, vf_seen_bits, vf_seen_ms, vf_seen_enc, vf_seen_count, vf_in_header;
    reg [63:0] vf_num;
    reg [7:0]  vf_sep;

    // the rest of the line, skipped (a bad line is reported by the caller)
    task vf_skip_line;
        begin
            while (vf_c != -1 && vf_c != 10) vf_c = $fgetc(vf_fd);
        end
    endtask

    // the next data line: its fields in vf_w[0 .. vf_nw-1]; vf_rc = 0 at the
    // end of the file.  (%h skips white space, new lines too, before a number:
    // a line that ends in a blank runs into the next one, which then has the
    // wrong number of fields.)
    task vf_read_line;
        begin
            vf_nw = 0; vf_more = 1;
            vf_c = $fscanf(vf_fd, "%h%c", vf_num, vf_sep);
            if (vf_c <= 0 && $feof(vf_fd)) vf_c = -1;   // (0, not -1, at the end in Verilator)
            vf_rc = (vf_c != -1);
            while (vf_more != 0 && vf_c != -1) begin
                if (vf_c == 0) begin                     // not a number
                    vf_nw = -1; vf_more = 0;
                    vf_skip_line;
                end else begin
                    if (vf_nw >= 0 && vf_nw < VF_MAX_WORDS && vf_num[63:32] == 32'd0 && ^vf_num !== 1'bx) begin
                        vf_w[vf_nw] = vf_num[31:0];
                        vf_nw = vf_nw + 1;
                    end else begin
                        vf_nw = -1;
                    end
                    if (vf_c == 1 || vf_sep == 8'd10) begin  // the end of the file or of the line
                        vf_more = 0;
                    end else if (vf_sep == 8'd32 || vf_sep == 8'd9) begin
                        vf_c = $fscanf(vf_fd, "%h%c", vf_num, vf_sep);
                        if (vf_c <= 0 && $feof(vf_fd)) vf_c = -1;
                        if (vf_c == -1) vf_more = 0;
                    end else begin                       // CR LF, or a field that runs into a non-digit
                        vf_c = vf_sep == 8'd13 ? $fgetc(vf_fd) : 0;
                        if (vf_c != 10) begin
                            vf_nw = -1;
                            vf_skip_line;
                        end
                        vf_more = 0;
                    end
                end
            end
            vf_lineno = vf_lineno + 1;
        end
    endtask

    // the next header line, its first characters in vf_buf
    task vf_read_text_line;
        begin
            vf_len = 0;
            vf_c = $fgetc(vf_fd);
            vf_rc = (vf_c != -1);
            while (vf_c != -1 && vf_c != 10) begin
                if (vf_len < VF_HEAD_BYTES) vf_buf[vf_len] = vf_c[7:0];
                vf_len = vf_len + 1;
                vf_c = $fgetc(vf_fd);
            end
            vf_lineno = vf_lineno + 1;
        end
    endtask

    // a header line's first n <= 64 characters as a string
    function [8*64-1:0] vf_text;
        input integer n;
        integer i;
        begin
            vf_text = 0;
            for (i = 0; i < n && i < vf_len && i < VF_HEAD_BYTES; i = i + 1)
                vf_text = {vf_text[8*63-1:0], vf_buf[i]};
        end
    endfunction

    // A header line "key: value": vf_hkey = key (its last 16 characters; 0
    // without ": "), vf_sval = value (its first 64), vf_ival = the value as a
    // decimal integer when vf_ivalok.  (Not $sscanf: Verilator reads the
    // string's leading NUL bytes as characters.)
    reg [8*16-1:0] vf_hkey;
    integer        vf_ivalok, vf_first, vf_i;
    reg [7:0]      vf_ch;
    task vf_header_field;
        begin
            vf_hkey = 0; vf_sval = 0; vf_ival = 0; vf_ivalok = 0;
            vf_i = 0;
            while (vf_i + 1 < vf_len && vf_i + 1 < VF_HEAD_BYTES && !(vf_buf[vf_i] == ":" && vf_buf[vf_i + 1] == " ")) begin
                vf_hkey = {vf_hkey[8*15-1:0], vf_buf[vf_i]};
                vf_i = vf_i + 1;
            end
            if (vf_i + 1 >= vf_len || vf_i + 1 >= VF_HEAD_BYTES) begin
                vf_hkey = 0;
            end else begin
                vf_first = vf_i + 2;
                vf_ivalok = vf_first < vf_len && !(vf_buf[vf_first] == "-" && vf_first + 1 == vf_len);
                for (vf_i = vf_first; vf_i < vf_len && vf_i < VF_HEAD_BYTES; vf_i = vf_i + 1) begin
                    vf_ch = vf_buf[vf_i];
                    if (vf_i - vf_first < 64) vf_sval = {vf_sval[8*63-1:0], vf_ch};
                    if (vf_ch >= "0" && vf_ch <= "9")
                        vf_ival = vf_ival * 10 + (vf_ch - "0");
                    else if (!(vf_ch == "-" && vf_i == vf_first))
                        vf_ivalok = 0;
                end
                if (vf_buf[vf_first] == "-") vf_ival = -vf_ival;
            end
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

            vf_read_text_line;
            if (vf_len != 21 || vf_text(21) != "# cbvh golden vectors")
                $fatal(1, "%0s: %0s:1: not a cbvh vector file", vf_tb, vf_path);
            vf_in_header = 1;
            while (vf_in_header) begin
                vf_read_text_line;
                if (vf_rc == 0)
                    $fatal(1, "%0s: %0s: no '---' line", vf_tb, vf_path);
                if (vf_len == 3 && vf_text(3) == "---") begin
                    vf_in_header = 0;
                end else begin
                    vf_header_field;
                    if (vf_hkey == "unit") begin
                        vf_seen_unit = 1;
                        if (vf_sval != vf_unit)
                            $fatal(1, "%0s: %0s:%0d: unit %0s, expected %0s",
                                   vf_tb, vf_path, vf_lineno, vf_sval, vf_unit);
                    end else if (vf_hkey == "quant_bits" && vf_ivalok) begin
                        vf_seen_bits = 1;
                        if (vf_ival != N)
                            $fatal(1, "%0s: %0s:%0d: quant_bits %0d but N = %0d",
                                   vf_tb, vf_path, vf_lineno, vf_ival, N);
                    end else if (vf_hkey == "min_scale" && vf_ivalok) begin
                        vf_seen_ms = 1;
                        if (vf_ival != E_MIN)
                            $fatal(1, "%0s: %0s:%0d: min_scale %0d but E_MIN = %0d",
                                   vf_tb, vf_path, vf_lineno, vf_ival, E_MIN);
                    end else if (vf_hkey == "encoding") begin
                        vf_seen_enc = 1;
                        if (VF_ENC == 0 ||
                            !((vf_sval == "modulo" && VF_MODULO != 0) || (vf_sval == "relative" && VF_MODULO == 0)))
                            $fatal(1, "%0s: %0s:%0d: encoding %0s does not match this instance",
                                   vf_tb, vf_path, vf_lineno, vf_sval);
                    end else if (vf_hkey == "count" && vf_ivalok) begin
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
