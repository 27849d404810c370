// cbvh unit 4 (encode half): node-pair encoder (docs/datapath.md section 9).
// Purely combinational, Verilog-2005. Independent implementation from the spec.
//
//   per axis a: context check as the decoder does it (BAD_SCALE, BAD_CODE, NAN_INF)
//               p^ = (node_lb_mod << (parent_scale - scale)) mod 2^N  (0 if shift >= N)
//   per non-empty child c, axis a: cbvh_axis_compressor(lo, hi, scale, node_clb) -> r^, s^
//               modulo:   codes r^, s^
//               relative: codes (r^ - p^) mod 2^N, (s^ - p^) mod 2^N  (= r, s mod 2^N)
//   node: [2aN, +N) lower code, [2aN+N, +N) upper code, [6N] leaf,
//         [6N+1, +P) pointer, P = min(32, W - 6N - 1), W = 64 (N <= 6) / 96 (N >= 7)
//   empty child (flags bit 1): leaf = 1, pointer = all ones, codes zero; its box,
//         leaf flag and pointer inputs are ignored
//   BAD_FORMAT: leaf pointer = 2^P - 1 (the empty marker) or a pointer >= 2^P
//   status = the context checks' bits if any context is rejected; else the OR of the
//         non-empty children's compressor statuses and BAD_FORMAT (NO_FIT and OUTSIDE
//         included, also next to a reject); any reject bit zeroes every word (section 9).
//
// Flags input (one hex digit on the wire): bit 0 = leaf, bit 1 = empty child,
// bits 3:2 unused (ignored, as the vectors show).

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_nodepair_encoder #(
    parameter integer N      = 6,    // bits per code, 3..10
    parameter integer E_MIN  = -30,  // minimum scale, -126..126
    parameter integer MODULO = 1     // 1: modulo encoding, 0: relative
) (
    input  wire [7:0]  x_parent_scale,
    input  wire [7:0]  x_scale,
    input  wire [11:0] x_node_lb_mod,
    input  wire [31:0] x_node_clb,
    input  wire [7:0]  y_parent_scale,
    input  wire [7:0]  y_scale,
    input  wire [11:0] y_node_lb_mod,
    input  wire [31:0] y_node_clb,
    input  wire [7:0]  z_parent_scale,
    input  wire [7:0]  z_scale,
    input  wire [11:0] z_node_lb_mod,
    input  wire [31:0] z_node_clb,
    input  wire [31:0] c0_lo_x,
    input  wire [31:0] c0_hi_x,
    input  wire [31:0] c0_lo_y,
    input  wire [31:0] c0_hi_y,
    input  wire [31:0] c0_lo_z,
    input  wire [31:0] c0_hi_z,
    input  wire [3:0]  c0_flags,     // bit 0 leaf, bit 1 empty, bits 3:2 ignored
    input  wire [31:0] c0_ptr,
    input  wire [31:0] c1_lo_x,
    input  wire [31:0] c1_hi_x,
    input  wire [31:0] c1_lo_y,
    input  wire [31:0] c1_hi_y,
    input  wire [31:0] c1_lo_z,
    input  wire [31:0] c1_hi_z,
    input  wire [3:0]  c1_flags,
    input  wire [31:0] c1_ptr,
    output wire [31:0] word0,
    output wire [31:0] word1,
    output wire [31:0] word2,
    output wire [31:0] word3,
    output wire [31:0] word4,        // zero for N <= 6 (16-byte pair)
    output wire [31:0] word5,        // zero for N <= 6
    output wire [7:0]  status        // datapath.md section 10
);
/* verilator lint_on DECLFILENAME */

    localparam [0:0]  BAD_PARAM = (N < 3) || (N > 10) || (E_MIN < -126) || (E_MIN > 126);
    localparam integer NW  = (N <= 6) ? 64 : 96;                  // node width W
    localparam integer P   = (NW - 6 * N - 1 > 32) ? 32 : NW - 6 * N - 1;
    localparam [31:0] PMAX = (P >= 32) ? 32'hFFFFFFFF : ((32'd1 << P) - 32'd1); // 2^P - 1

    // ---- per-axis context: check and p^ ------------------------------------------
    wire [23:0]  ps_all  = {z_parent_scale, y_parent_scale, x_parent_scale};
    wire [23:0]  sc_all  = {z_scale, y_scale, x_scale};
    wire [35:0]  lbm_all = {z_node_lb_mod, y_node_lb_mod, x_node_lb_mod};
    wire [95:0]  clb_all = {z_node_clb, y_node_clb, x_node_clb};

    wire [3*N-1:0] phat;       // p^ per axis
    wire [2:0]     ctx_scale, ctx_code, ctx_nan;

    genvar a;
    generate
        for (a = 0; a < 3; a = a + 1) begin : g_ctx
            wire bad_scale, bad_code, nan_pinf;
            // the decoder's context check and p^ (axis_decoder.v), so both
            // directions reject the same contexts
            cbvh_axis_ctx #(.N(N), .E_MIN(E_MIN)) ctx (
                .parent_scale(ps_all[8*a +: 8]), .scale(sc_all[8*a +: 8]),
                .node_lb_mod(lbm_all[12*a +: 12]), .node_clb(clb_all[32*a +: 32]),
                .bad_scale(bad_scale), .bad_code(bad_code), .nan_inf(nan_pinf), .p_hat(phat[N*a +: N]));
            // one reject bit per context, in the decoder's order (section 10)
            assign ctx_scale[a] = ~BAD_PARAM & bad_scale;
            assign ctx_code[a]  = ~BAD_PARAM & ~bad_scale & bad_code;
            assign ctx_nan[a]   = ~BAD_PARAM & ~bad_scale & ~bad_code & nan_pinf;
        end
    endgenerate

    // ---- six compressors: index i = 3c + a (child c, axis a) ---------------------
    wire [383:0] box_all = {c1_hi_z, c1_lo_z, c1_hi_y, c1_lo_y, c1_hi_x, c1_lo_x,
                            c0_hi_z, c0_lo_z, c0_hi_y, c0_lo_y, c0_hi_x, c0_lo_x};
    wire [1:0] empty = {c1_flags[1], c0_flags[1]};

    wire [6*N-1:0] lo_code, hi_code;   // stored codes (zero for an empty child)
    wire [7:0]     cst [0:5];          // compressor statuses, masked for empty children

    genvar i;
    generate
        for (i = 0; i < 6; i = i + 1) begin : g_cmp
            localparam integer AX = i % 3;
            localparam integer CH = i / 3;
            wire [N-1:0] lm, um;
            wire [7:0]   st;
            // the encoder's words carry only the codes; the decoded box and the
            // child scale of unit 2 are not outputs of this unit
            /* verilator lint_off UNUSED */
            wire [7:0]   cs_unused;
            wire [31:0]  clb_unused, cub_unused;
            /* verilator lint_on UNUSED */
            cbvh_axis_compressor #(.N(N), .E_MIN(E_MIN)) u_cmp (
                .lb(box_all[64*i +: 32]), .ub(box_all[64*i+32 +: 32]),
                .scale(sc_all[8*AX +: 8]), .node_clb(clb_all[32*AX +: 32]), .lb_mod(lm), .ub_mod(um),
                .child_scale(cs_unused), .clb(clb_unused), .cub(cub_unused),
                .status(st));
            wire [N-1:0] ph = phat[N*AX +: N];
            wire [N-1:0] lo = (MODULO != 0) ? lm : (lm - ph);
            wire [N-1:0] hi = (MODULO != 0) ? um : (um - ph);
            assign lo_code[N*i +: N] = empty[CH] ? {N{1'b0}} : lo;
            assign hi_code[N*i +: N] = empty[CH] ? {N{1'b0}} : hi;
            assign cst[i] = empty[CH] ? 8'd0 : st;
        end
    endgenerate

    // ---- format checks and node packing ---------------------------------------------
    wire [63:0] ptr_all = {c1_ptr, c0_ptr};
    wire [1:0]  leaf_in = {c1_flags[0], c0_flags[0]};
    // flags bits 3:2 carry no meaning; the vectors show them ignored (no BAD_FORMAT)
    /* verilator lint_off UNUSEDSIGNAL */
    wire [3:0]  flags_unused = {c1_flags[3:2], c0_flags[3:2]};
    /* verilator lint_on UNUSEDSIGNAL */
    wire [1:0]  fmt_bad;
    wire [2*NW-1:0] pair;

    genvar c;
    generate
        for (c = 0; c < 2; c = c + 1) begin : g_node
            wire [31:0] ptr  = ptr_all[32*c +: 32];
            wire        leaf = leaf_in[c] | empty[c];
            wire        wide;                                 // pointer >= 2^P
            if (P < 32) begin : g_narrow
                assign wide = |ptr[31:P];
            end else begin : g_full
                assign wide = 1'b0;
            end
            wire        mark = leaf_in[c] & (ptr == PMAX);    // leaf = empty marker
            assign fmt_bad[c] = ~empty[c] & (wide | mark);
            wire [31:0] pval = empty[c] ? PMAX : (ptr & PMAX);
            // codes of axis a: lower at [2aN, +N), upper at [2aN+N, +N)
            wire [6*N-1:0] codes = {hi_code[N*(3*c+2) +: N], lo_code[N*(3*c+2) +: N],
                                    hi_code[N*(3*c+1) +: N], lo_code[N*(3*c+1) +: N],
                                    hi_code[N*(3*c)   +: N], lo_code[N*(3*c)   +: N]};
            // pointer at [6N+1, +P) (pval < 2^P), leaf at 6N, reserved bits zero
            assign pair[NW*c +: NW] = ({{(NW - 32){1'b0}}, pval} << (6 * N + 1)) |
                                      ({{(NW - 1){1'b0}}, leaf} << (6 * N)) |
                                      {{(NW - 6 * N){1'b0}}, codes};
        end
    endgenerate

    // ---- status and outputs --------------------------------------------------------
    // section 9: a rejected context ends the encode with the context bits alone;
    // otherwise the OR of the children's format checks and compressor statuses,
    // NO_FIT and OUTSIDE included even when another bit rejects the pair
    wire [7:0] ctx_st  = {2'b00, 1'b0, |ctx_code, BAD_PARAM, |ctx_scale, 1'b0, |ctx_nan};
    wire [7:0] axis_st = cst[0] | cst[1] | cst[2] | cst[3] | cst[4] | cst[5];
    wire [7:0] st_all  = (|ctx_st) ? ctx_st : (axis_st | {2'b00, |fmt_bad, 5'd0});
    wire       reject  = |st_all[5:0];
    wire [191:0] words;
    generate
        if (NW == 96) begin : g_w96
            assign words = reject ? 192'd0 : pair;
        end else begin : g_w64
            assign words = reject ? 192'd0 : {64'd0, pair};
        end
    endgenerate

    assign word0  = words[31:0];
    assign word1  = words[63:32];
    assign word2  = words[95:64];
    assign word3  = words[127:96];
    assign word4  = words[159:128];
    assign word5  = words[191:160];
    assign status = st_all;

endmodule
