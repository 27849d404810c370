// cbvh unit 3: single-axis decoder (docs/datapath.md §7, paper Fig. 4 with
// errata E4/E5 and deviations D2/D3 of §11). Purely combinational.
//
// Independent implementation from the written spec. Arithmetic outline:
//   u_node = (-1)^neg * M * 2^a           (node_clb broken as in §2; -Inf = -2^128)
//   X      = u_node + r * 2^e             (exact), clb = RD(X); same with s, cub = RU
// X is formed in a fixed window whose lsb is beta = max(e - 24, a - 2):
//   * a - 2 >= e - 24 : u_node is exact (4M); r * 2^e is shifted right by
//     d + 22 (d = a - e) and bits below beta become a sticky bit. Once bits are
//     cut u_node is normal and dominates, so the result ulp is >= 2^(a-1) > 2^beta.
//   * otherwise       : r * 2^e is exact (r << 24); u_node is shifted right by
//     -(d + 22) with sticky. Once bits are cut |u_node| < 2^(e-1) and r >= 1, so
//     the result ulp is >= 2^(e-24) = 2^beta.
// Hence floor(X / 2^beta) plus a sticky bit rounds exactly like X (§2), with a
// 36-bit adder instead of the model's 64-bit one. r = 0 (clb only) is bypassed:
// RD(u_node) = u_node.

// The file name is fixed by the project layout (axis_decoder.v); it holds the
// unit and its rounding helper.
/* verilator lint_off DECLFILENAME */

// Rounds (-1)^F[35] * (F + frac) * 2^beta, frac in [0,1) (frac > 0 iff st) once
// to binary32 (§2: directed, subnormals, IEEE overflow, zero is +0).
module cbvh_axis_decoder_pack (
    input  wire [35:0] f,        // floor(X / 2^beta), two's complement
    input  wire        st,       // X is not a multiple of 2^beta
    input  wire [9:0]  beta,     // signed, in [-151, 103]
    input  wire        round_up, // 1: RU (toward +Inf), 0: RD (toward -Inf)
    output wire [31:0] y
);
    localparam MW = 35;          // |X| / 2^beta < 2^35 (T <= 2^34, U < 2^26)

    wire neg = f[35];
    // floor(|X| / 2^beta): for X < 0 with a fraction, |X| is in (~F, ~F + 1)
    wire [MW-1:0] mag = neg ? (~f[MW-1:0] + {{(MW - 1){1'b0}}, ~st}) : f[MW-1:0];

    // leading zeros of mag (35 when mag = 0): the priority encoder
    reg [5:0] lz;
    integer i;
    always @* begin
        lz = 6'd35;
        for (i = 0; i < MW; i = i + 1)
            if (mag[i]) lz = 6'd34 - i[5:0];
    end

    // normal: biased exponent eb = beta + 161 - lz >= 1; else the subnormal
    // left shift lsub = beta + 160 puts the 2^-149 unit at bit 11 of z
    wire [9:0] lsub = beta + 10'sd160;
    wire [9:0] eb   = lsub + 10'd1 - {4'd0, lz};
    wire       normal = ($signed(lsub) >= $signed({4'd0, lz}));
    wire [5:0] lsh = normal ? lz : lsub[5:0];  // lsub < 35 here, and >= 9
    // the hidden bit (bit MW-1 of mag << lsh) is implied by the exponent field
    wire [MW-2:0] z = mag[MW-2:0] << lsh;
    wire [22:0] frac = z[MW-2:11];
    wire inexact = (|z[10:0]) | st;
    // directed rounding on sign-magnitude: magnitude grows toward the
    // infinity of the rounding direction
    wire away = round_up ? ~neg : neg;
    wire rup  = inexact & away;
    wire ovf  = normal & ($signed(eb) >= $signed(10'sd255));
    wire [7:0]  efield = normal ? eb[7:0] : 8'd0;
    // carry out of the fraction bumps the exponent (also subnormal -> normal
    // and 254 -> 255 = Inf, which only happens when rounding away)
    wire [30:0] body = {efield, frac} + {30'd0, rup};
    wire is_zero = ~neg & ~(|mag) & ~st;

    assign y = is_zero ? 32'd0 :
               ovf     ? (away ? {neg, 31'h7F800000} : {neg, 31'h7F7FFFFF}) :
                         {neg, body};
endmodule

// A node's context (§8), checked as §7 and §9 require and brought to the
// child grid (Fig. 4 line 1): shared by the decoder and the node-pair encoder,
// so both reject the same contexts.
module cbvh_axis_ctx #(
    parameter integer N     = 6,
    parameter integer E_MIN = -30
) (
    input  wire [7:0]   parent_scale,
    input  wire [7:0]   scale,
    input  wire [11:0]  node_lb_mod,
    input  wire [31:0]  node_clb,
    output wire         bad_scale,  // scale < e_min, parent_scale > 126 or < scale
    output wire         bad_code,   // node_lb_mod >= 2^N
    output wire         nan_inf,    // node_clb NaN or +Inf; -Inf is the valid value -2^128 (§3)
    output wire [N-1:0] p_hat       // node r_hat at the child scale; 0 once the shift reaches N
);
    localparam [9:0] E_MIN10 = E_MIN[9:0];
    localparam [9:0] N10 = N[9:0];
    wire [9:0] ps10 = {{2{parent_scale[7]}}, parent_scale};
    wire [9:0] e10  = {{2{scale[7]}}, scale};
    assign bad_scale = ($signed(e10) < $signed(E_MIN10)) || ($signed(e10) > 10'sd126) ||
                       ($signed(ps10) > 10'sd126) || ($signed(ps10) < $signed(e10));
    assign bad_code = |node_lb_mod[11:N];
    assign nan_inf  = (&node_clb[30:23]) & ((|node_clb[22:0]) | ~node_clb[31]);
    wire [9:0] sh = ps10 - e10;               // parent_scale - scale (>= 0 if valid)
    assign p_hat = ($signed(sh) >= $signed(N10)) ? {N{1'b0}} : (node_lb_mod[N-1:0] << sh[3:0]);
endmodule

module cbvh_axis_decoder #(
    parameter integer N      = 6,
    parameter integer E_MIN  = -30,
    parameter integer MODULO = 1
) (
    input  wire [7:0]   parent_scale,
    input  wire [7:0]   scale,
    // codes are 12 bits (3 hex digits on the wire) so that BAD_CODE is
    // detectable for every N, including N = 10
    input  wire [11:0]  node_lb_mod,
    input  wire [31:0]  node_clb,
    input  wire [11:0]  lb_code,
    input  wire [11:0]  ub_code,
    output wire [N-1:0] lb_mod,
    output wire [N-1:0] ub_mod,
    output wire [7:0]   child_scale,
    output wire [31:0]  clb,
    output wire [31:0]  cub,
    output wire [6:0]   status
);
    localparam [N:0] TWO_N = {1'b1, {N{1'b0}}};
    localparam BAD_PARAM = (N < 3) || (N > 10) || (E_MIN < -126) || (E_MIN > 126);
    localparam [9:0] E_MIN10 = E_MIN[9:0];
    localparam [9:0] N10 = N[9:0];

    // ---------------------------------------------------------------- checks
    wire [9:0] e10  = {{2{scale[7]}}, scale};
    wire bad_scale, bad_node_code, nan_inf;
    wire [N-1:0] p_hat;
    cbvh_axis_ctx #(.N(N), .E_MIN(E_MIN)) ctx (
        .parent_scale(parent_scale), .scale(scale), .node_lb_mod(node_lb_mod), .node_clb(node_clb),
        .bad_scale(bad_scale), .bad_code(bad_node_code), .nan_inf(nan_inf), .p_hat(p_hat));
    wire bad_child_code = (|lb_code[11:N]) | (|ub_code[11:N]);
    wire bad_code  = bad_node_code | bad_child_code;
    wire clb_sign = node_clb[31];
    wire [7:0]  clb_ef = node_clb[30:23];
    wire [22:0] clb_fr = node_clb[22:0];

    // ---------------------------------------------- Eq. 9

    wire [N-1:0] r_lo, s_lo, lbm, ubm;
    generate
        if (MODULO != 0) begin : g_modulo
            assign r_lo = lb_code[N-1:0] - p_hat;
            assign s_lo = ub_code[N-1:0] - p_hat;
            assign lbm  = lb_code[N-1:0];     // = (r + p_hat) mod 2^N
            assign ubm  = ub_code[N-1:0];
        end else begin : g_relative
            assign r_lo = lb_code[N-1:0];
            assign s_lo = ub_code[N-1:0];
            assign lbm  = lb_code[N-1:0] + p_hat;
            assign ubm  = ub_code[N-1:0] + p_hat;
        end
    endgenerate

    wire [N:0] r = {1'b0, r_lo};
    wire [N:0] s = (|s_lo) ? {1'b0, s_lo} : TWO_N;   // D2: s = 0 means 2^N
    wire inverted = (r >= s);

    // ------------------------------------------------ child scale (§4, Eq. 2)
    wire [N:0] cells = s - r;                 // in [1, 2^N] when not inverted
    wire [N:0] cm1   = cells - {{N{1'b0}}, 1'b1};
    reg  [3:0] clog2;                          // ceil(log2 cells) = bits of cells-1
    integer j;
    always @* begin
        clog2 = 4'd0;
        for (j = 0; j <= N; j = j + 1)
            if (cm1[j]) clog2 = j[3:0] + 4'd1;
    end
    wire [9:0] cs_raw = e10 - N10 + {6'd0, clog2};
    wire [7:0] cs = ($signed(cs_raw) < $signed(E_MIN10)) ? E_MIN10[7:0] : cs_raw[7:0];

    // -------------------------------------- u_node + r*2^e, rounded once (§2)
    // break: value = M * 2^a; the exponent field 255 (-Inf) gives 2^23 * 2^105
    wire        clb_sub = ~(|clb_ef);
    wire [23:0] m = {~clb_sub, clb_fr};
    wire [9:0]  a = clb_sub ? -10'sd149 : ({2'b00, clb_ef} - 10'd150);
    wire [9:0]  dk = a - e10 + 10'sd22;       // d + 22, d = a - e
    wire        sel_a = ~dk[9];               // beta = a - 2 (else e - 24)
    wire [9:0]  beta = sel_a ? (a - 10'd2) : (e10 - 10'd24);
    wire [9:0]  ndk = -dk;
    // right shifts (only one operand is ever cut), clamped where all is sticky
    wire [5:0]  k_t = ~sel_a ? 6'd0 : (($signed(dk) > 10'sd35) ? 6'd35 : dk[5:0]);
    wire [4:0]  k_u =  sel_a ? 5'd0 : (($signed(ndk) > 10'sd26) ? 5'd26 : ndk[4:0]);

    // U = floor(4M / 2^k_u), shared by clb and cub
    wire [51:0] uw = {m, 28'd0} >> k_u;
    wire [25:0] u_al = uw[51:26];
    wire        st_u = |uw[25:0];
    wire [35:0] u_ext = {10'd0, u_al};
    // floor(-(U + frac)) = ~U when frac > 0, else -U = ~U + 1
    wire [35:0] u_sgn = clb_sign ? ~u_ext : u_ext;
    wire [35:0] u_cin = {35'd0, clb_sign & ~st_u};

    // T = floor(r * 2^(24 - k_t)) for r and s (r, s <= 2^N, so T < 2^(N+25))
    wire [N+35:0] tw_r = {r, 35'd0} >> k_t;
    wire [N+35:0] tw_s = {s, 35'd0} >> k_t;
    wire        st_r = st_u | (|tw_r[10:0]);
    wire        st_s = st_u | (|tw_s[10:0]);
    wire [35:0] t_r = {{(11 - N){1'b0}}, tw_r[N+35:11]};
    wire [35:0] t_s = {{(11 - N){1'b0}}, tw_s[N+35:11]};
    wire [35:0] f_r = t_r + u_sgn + u_cin;
    wire [35:0] f_s = t_s + u_sgn + u_cin;

    wire [31:0] clb_sum, cub_sum;
    cbvh_axis_decoder_pack u_pack_lo (.f(f_r), .st(st_r), .beta(beta), .round_up(1'b0), .y(clb_sum));
    cbvh_axis_decoder_pack u_pack_hi (.f(f_s), .st(st_s), .beta(beta), .round_up(1'b1), .y(cub_sum));
    // r = 0: RD(u_node) = u_node (-Inf stays -Inf, -0 becomes +0); the window
    // above assumes r >= 1 when it cuts u_node
    wire [31:0] clb_r0 = (node_clb == 32'h80000000) ? 32'd0 : node_clb;
    wire [31:0] clb_val = (|r_lo) ? clb_sum : clb_r0;

    // ----------------------------------------------------------------- status
    // context faults are reported together; INVERTED needs a valid context
    wire ctx_bad = BAD_PARAM | bad_scale | bad_code | nan_inf;
    wire inv_rej = ~ctx_bad & inverted;
    // one reject bit: the first failing check in the order of section 10
    // (BAD_PARAM, BAD_SCALE, node code, node_clb NaN/+Inf, child codes, INVERTED)
    wire st_scale = ~BAD_PARAM & bad_scale;
    wire st_code  = ~BAD_PARAM & ~bad_scale & (bad_node_code | (~nan_inf & bad_child_code));
    wire st_nan   = ~BAD_PARAM & ~bad_scale & ~bad_node_code & nan_inf;
    assign status = {1'b0, 1'b0, st_code, BAD_PARAM ? 1'b1 : 1'b0, st_scale, inv_rej, st_nan};
    wire reject = ctx_bad | inverted;

    assign lb_mod      = reject ? {N{1'b0}} : lbm;
    assign ub_mod      = reject ? {N{1'b0}} : ubm;
    assign child_scale = reject ? 8'd0 : cs;
    assign clb         = reject ? 32'd0 : clb_val;
    assign cub         = reject ? 32'd0 : cub_sum;
endmodule
