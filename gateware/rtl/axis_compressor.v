// cbvh unit 2: single-axis compressor (docs/datapath.md section 6, Fig. 5 with the
// errata of section 11 fixed). Purely combinational, Verilog-2005.
//
//   k = floor(p / 2^e),  l = floor(q / 2^e) + 1,  cells = l - k,  fits = cells <= 2^N
//   lb_mod = k mod 2^N,  ub_mod = l mod 2^N
//   child_scale = fits ? max(E_MIN, e - N + ceil(log2 cells)) : e
//   clb = RD(k 2^e),  cub = RU(l 2^e)
//   OUTSIDE = k < K or l > K + 2^N,  K = floor(node_clb / 2^e)   (the node's window)
//
// Cost notes: no wide integers are built. k 2^e is a binary32 (section 3; -2^128
// comes out as the -Inf pattern), so clb and cub are masks and +-1 increments on the
// bit pattern. Only W = N + 2 low bits of k and floor(q/2^e) are extracted; the
// difference of the magnitude bit patterns decides whether those low bits give the
// whole difference l - k (see the proof sketch at "close"). The window test uses
// the same windows of K and the same closeness test on the pairs (p, u) and (u, q)
// (module cbvh_axis_compressor_pair): no wide integer either.

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_axis_compressor #(
    parameter integer N     = 6,    // bits per code, 3..10
    parameter integer E_MIN = -30   // minimum scale, -126..126
) (
    input  wire [31:0]  lb,          // p (binary32 bit pattern)
    input  wire [31:0]  ub,          // q
    input  wire [7:0]   scale,       // e, 8-bit two's complement
    input  wire [31:0]  node_clb,    // u, the node's decoded lower bound (-Inf = -2^128)
    output wire [N-1:0] lb_mod,      // r^ = k mod 2^N
    output wire [N-1:0] ub_mod,      // s^ = l mod 2^N
    output wire [7:0]   child_scale,
    output wire [31:0]  clb,         // u = RD(k 2^e)
    output wire [31:0]  cub,         // v = RU(l 2^e)
    output wire [7:0]   status
);
/* verilator lint_on DECLFILENAME */

    // Window width: N + 2 low bits of the grid coordinates are enough (see "close").
    localparam integer W = N + 2;

    localparam [0:0] BAD_PARAM = (N < 3) || (N > 10) || (E_MIN < -126) || (E_MIN > 126);
    localparam signed [9:0] EMIN10 = E_MIN[9:0];
    localparam signed [9:0] NS10   = N[9:0];

    wire signed [9:0] e = {{2{scale[7]}}, scale};

    // ---- per-bound grid alignment ---------------------------------------------
    wire         p_nan, p_neg, p_lt, p_le, p_big, p_sticky;
    wire [7:0]   p_ee;
    wire signed [9:0] p_d;
    wire [22:0]  p_mask;
    wire [W-1:0] p_f;
    wire         q_nan, q_neg, q_lt, q_le, q_big, q_sticky;
    wire [7:0]   q_ee;
    wire signed [9:0] q_d;
    wire [22:0]  q_mask;
    wire [W-1:0] q_f;
    // u = node_clb: the -Inf pattern decomposes as 2^23 * 2^(255-150) = 2^128
    wire         u_naninf, u_neg, u_big, u_sticky;
    /* verilator lint_off UNUSEDSIGNAL */
    wire         u_lt, u_le;              // only p and q need the decoded bounds
    wire [22:0]  u_mask;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [7:0]   u_ee;
    wire signed [9:0] u_d;
    wire [W-1:0] u_f;

    cbvh_axis_compressor_bound #(.W(W)) u_p (
        .x(lb), .e(e), .nan_inf(p_nan), .neg(p_neg), .ee(p_ee), .d(p_d),
        .mask(p_mask), .sticky(p_sticky), .lt(p_lt), .le(p_le), .big(p_big), .f(p_f));
    cbvh_axis_compressor_bound #(.W(W)) u_q (
        .x(ub), .e(e), .nan_inf(q_nan), .neg(q_neg), .ee(q_ee), .d(q_d),
        .mask(q_mask), .sticky(q_sticky), .lt(q_lt), .le(q_le), .big(q_big), .f(q_f));
    cbvh_axis_compressor_bound #(.W(W)) u_u (
        .x(node_clb), .e(e), .nan_inf(u_naninf), .neg(u_neg), .ee(u_ee), .d(u_d),
        .mask(u_mask), .sticky(u_sticky), .lt(u_lt), .le(u_le), .big(u_big), .f(u_f));
    wire u_nan = u_naninf & (node_clb != 32'hFF800000);  // NaN or +Inf; -Inf is -2^128

    // ---- codes: low W bits of k and kq = floor(q/2^e) ---------------------------
    // For x < 0: floor(x/2^e) = -(floor(|x|/2^e) + sticky) = ~f + !sticky (mod 2^W).
    wire [W-1:0] k_lo  = p_neg ? (~p_f + {{(W-1){1'b0}}, ~p_sticky}) : p_f;
    wire [W-1:0] kq_lo = q_neg ? (~q_f + {{(W-1){1'b0}}, ~q_sticky}) : q_f;
    wire [W-1:0] ku_lo = u_neg ? (~u_f + {{(W-1){1'b0}}, ~u_sticky}) : u_f;  // K
    // dd = (kq - k) mod 2^W = cells - 1 whenever "close" holds.
    wire [W-1:0] dd    = kq_lo - k_lo;

    // ---- close: is kq - k < 2^W, so that dd is the true difference? -------------
    // (module cbvh_axis_compressor_pair; it also orders p and q by value)
    wire         close, p_gt_q;
    /* verilator lint_off UNUSEDSIGNAL */
    wire         p_lt_q_unused;
    /* verilator lint_on UNUSEDSIGNAL */
    cbvh_axis_compressor_pair #(.N(N)) u_pq (
        .xm(lb[30:0]), .ym(ub[30:0]), .x_neg(p_neg), .y_neg(q_neg), .x_big(p_big), .y_big(q_big),
        .x_ee(p_ee), .y_ee(q_ee), .x_d(p_d), .y_d(q_d), .close(close), .lt(p_lt_q_unused), .gt(p_gt_q));

    wire         fits  = close & ~|dd[W-1:N];

    // ---- child scale: ceil(log2(cells)) = bit length of cells - 1 ---------------
    reg [3:0] blen;
    integer i;
    always @* begin
        blen = 4'd0;
        for (i = 0; i < N; i = i + 1)
            if (dd[i]) blen = i[3:0] + 4'd1;
    end
    wire signed [9:0] cs_raw = e - NS10 + {6'd0, blen};
    wire [7:0]        cs     = ~fits ? scale : (cs_raw < EMIN10) ? EMIN10[7:0] : cs_raw[7:0];

    // ---- decoded bounds (pattern arithmetic, section 3) ------------------------
    wire [7:0]  pow_e = scale + 8'd127;                  // biased exponent of 2^e
    // k 2^e for p: clear the bits below 2^e; for p < 0 with dropped bits, one more
    // grid step in magnitude: (pat | mask) + 1 (carries into the exponent; 2^128 is
    // the Inf pattern, i.e. -2^128 -> -Inf).
    wire [30:0] p_trunc = {lb[30:23], lb[22:0] & ~p_mask};
    wire [30:0] p_up    = {lb[30:23], lb[22:0] |  p_mask} + 31'd1;
    wire [31:0] u_val   = ~p_neg ? (p_lt ? 32'd0 : {1'b0, p_trunc})
                        : p_le   ? {1'b1, pow_e, 23'd0}
                        :          {1'b1, p_sticky ? p_up : lb[30:0]};
    // l 2^e for q >= 0: next grid line above q; when q's ulp exceeds 2^e the mask is
    // empty and +1 is RU(q + 2^e). q < 0: magnitude is the grid line strictly below
    // |q|; on a grid line that is |q| - 2^e, rounded toward zero: (pat - 1) with the
    // low bits cleared (one more bit when |q| is a power of two: the lower binade).
    // one adder: (pat | mask) + 1 for q >= 0, pat - 1 for q < 0
    wire [30:0] q_trunc = {ub[30:23], ub[22:0] & ~q_mask};
    wire [30:0] q_add   = {ub[30:23], ub[22:0] | (q_neg ? 23'd0 : q_mask)}
                        + (q_neg ? {31{1'b1}} : 31'd1);
    wire        q_pow2  = (ub[22:0] == 23'd0) && (q_d >= 10'sd0);
    wire [22:0] q_dmask = q_pow2 ? {q_mask[21:0], 1'b1} : q_mask;
    wire [30:0] q_down  = {q_add[30:23], q_add[22:0] & ~q_dmask};
    wire [31:0] v_val   = ~q_neg ? (q_lt ? {1'b0, pow_e, 23'd0} : {1'b0, q_add})
                        : q_le   ? 32'd0
                        :          {1'b1, q_sticky ? q_trunc : q_down};

    // ---- the node's window (section 6): inside iff K <= k and kq - K < 2^N -------
    // p >= u: K <= k, and (u, q) is an ordered pair, so kq - K < 2^N iff close(u, q)
    //         and its low bits say so (not close: kq - K >= 2^N);
    // p < u:  k <= K, so inside needs k = K, i.e. close(p, u) with equal low bits
    //         (not close: K - k >= 2^N), and then kq - K = cells - 1: fits.
    wire         pu_close, p_lt_u, uq_close;
    /* verilator lint_off UNUSEDSIGNAL */
    wire         p_gt_u_unused, u_lt_q_unused, u_gt_q_unused;
    /* verilator lint_on UNUSEDSIGNAL */
    cbvh_axis_compressor_pair #(.N(N)) u_pu (
        .xm(lb[30:0]), .ym(node_clb[30:0]), .x_neg(p_neg), .y_neg(u_neg), .x_big(p_big), .y_big(u_big),
        .x_ee(p_ee), .y_ee(u_ee), .x_d(p_d), .y_d(u_d), .close(pu_close), .lt(p_lt_u), .gt(p_gt_u_unused));
    cbvh_axis_compressor_pair #(.N(N)) u_uq (
        .xm(node_clb[30:0]), .ym(ub[30:0]), .x_neg(u_neg), .y_neg(q_neg), .x_big(u_big), .y_big(q_big),
        .x_ee(u_ee), .y_ee(q_ee), .x_d(u_d), .y_d(q_d), .close(uq_close), .lt(u_lt_q_unused), .gt(u_gt_q_unused));
    /* verilator lint_off UNUSEDSIGNAL */
    wire [W-1:0] dqk    = kq_lo - ku_lo;                  // kq - K when close(u, q): < 2^N?
    /* verilator lint_on UNUSEDSIGNAL */
    wire         in_window = p_lt_u ? (pu_close & (k_lo == ku_lo) & fits) : (uq_close & ~|dqk[W-1:N]);

    // ---- status (section 10) ----------------------------------------------------
    wire nan_inf   = p_nan | q_nan | u_nan;
    wire inverted  = ~nan_inf & p_gt_q;
    wire bad_scale = (e < EMIN10) || (e > 10'sd126);
    wire reject    = nan_inf | inverted | bad_scale | BAD_PARAM;
    // one reject bit: the first failing check in the order of section 10
    wire st_nan    = ~BAD_PARAM & nan_inf;
    wire st_scale  = ~BAD_PARAM & ~nan_inf & bad_scale;
    wire st_inv    = ~BAD_PARAM & ~nan_inf & ~bad_scale & inverted;

    assign lb_mod      = reject ? {N{1'b0}} : k_lo[N-1:0];
    assign ub_mod      = reject ? {N{1'b0}} : kq_lo[N-1:0] + {{(N-1){1'b0}}, 1'b1};
    assign child_scale = reject ? 8'd0 : cs;
    assign clb         = reject ? 32'd0 : u_val;
    assign cub         = reject ? 32'd0 : v_val;
    assign status      = {~reject & ~in_window, ~reject & ~fits, 2'b00, BAD_PARAM, st_scale, st_inv, st_nan};

endmodule

// Two values x <= y (as values; both decomposed by cbvh_axis_compressor_bound):
// their order, and "close": kq - k < 2^W for k = floor(x/2^e), kq = floor(y/2^e),
// so that the difference of the W-bit windows is the true one; not close
// implies kq - k >= 2^N.  (The order outputs hold for any x, y.)
//   Neither bound big (|x| < 2^(e+W-1)): |k|, |kq| <= 2^(W-1), the difference is
// below 2^W. A big bound and the other of opposite sign: difference
// >= 2^(W-1) > 2^N. Same sign, magnitudes A <= B, B big: binades two or
// more apart give B - A > B/2 >= 2^(e+W-2), difference >= 2^N. One
// binade apart at most (both normal, as B big means B >= 2^-121; the -Inf
// pattern, 2^128, is one more binade of the same pattern order): the
// magnitude-pattern difference P = pat(B) - pat(A) has X/2 <= P <= X, X = B - A
// in units of 2^expA. With T = N + e - expA, P <= 2^T holds when
// kq - k <= 2^N - 1 and fails when kq - k >= 2^W, which is all "close" needs.
module cbvh_axis_compressor_pair #(
    parameter integer N = 6
) (
    input  wire [30:0]       xm,      // |x| and |y| as patterns (the signs are x_neg, y_neg)
    input  wire [30:0]       ym,
    input  wire              x_neg,
    input  wire              y_neg,
    input  wire              x_big,
    input  wire              y_big,
    input  wire [7:0]        x_ee,
    input  wire [7:0]        y_ee,
    input  wire signed [9:0] x_d,
    input  wire signed [9:0] y_d,
    output wire              close,
    output wire              lt,      // x < y by value
    output wire              gt       // x > y by value
);
    localparam signed [9:0] NS10 = N[9:0];
    wire         same   = (x_neg == y_neg);
    wire signed [9:0] a_d = x_neg ? y_d : x_d;            // e - expA
    wire [8:0]   gq     = {1'b0, y_ee} - {1'b0, x_ee};
    wire         gap_ok = (gq == 9'd0) || (gq == (x_neg ? 9'h1FF : 9'd1));
    // pdiff = pat(y) - pat(x) (magnitudes); R = P for x, y >= 0, P - 1 for x, y < 0
    // (a one's complement instead of a negation; P = 0 is caught separately)
    wire [31:0]  pdiff  = {1'b0, ym} - {1'b0, xm};
    wire [30:0]  r_x    = x_neg ? ~pdiff[30:0] : pdiff[30:0];
    wire signed [9:0] t_x = a_d + NS10;                   // T
    wire [4:0]   t_xc   = (t_x < 10'sd0) ? 5'd0 : (t_x > 10'sd31) ? 5'd31 : t_x[4:0];
    wire [30:0]  x_low  = ~(31'h7FFFFFFF << t_xc);        // bits below 2^T
    wire         pd_zero = ~|pdiff;                       // P = 0 (R would wrap)
    // R < 2^T; for T < 0 only P = 0 passes (P - 1 < 2^T <=> P <= 2^T needs T >= 0)
    wire         x_small = pd_zero | (~t_x[9] & ~|(r_x & ~x_low));
    assign close = (~x_big & ~y_big) | (same & gap_ok & x_small);
    // the order (-0 is zero, so its neg flag is clear): from the sign flags and the
    // magnitude-pattern difference, which orders finite floats of one sign
    wire         pd_pos = ~pdiff[31] & ~pd_zero;
    assign gt = same ? (x_neg ? pd_pos : pdiff[31]) : (~x_neg & y_neg);
    assign lt = same ? (x_neg ? pdiff[31] : pd_pos) : (x_neg & ~y_neg);
endmodule

// Decomposition and grid alignment of one bound x at scale e (section 3):
// |x| = sig 2^(ee - 150), d = e - (ee - 150) = how many significand bits lie below 2^e.
module cbvh_axis_compressor_bound #(
    parameter integer W = 8
) (
    input  wire [31:0]       x,
    input  wire signed [9:0] e,
    output wire              nan_inf,
    output wire              neg,     // x < 0 as a value (-0 is zero)
    output wire [7:0]        ee,      // effective biased exponent (1 for subnormals)
    output wire signed [9:0] d,
    output wire [22:0]       mask,    // pattern bits below 2^e, d clamped to [0, 23]
    output wire              sticky,  // |x| is not a multiple of 2^e
    output wire              lt,      // |x| <  2^e
    output wire              le,      // |x| <= 2^e
    output wire              big,     // |x| >= 2^(e+W-1)
    output wire [W-1:0]      f        // floor(|x| / 2^e) mod 2^W
);
    localparam signed [9:0] W10 = W[9:0];

    wire sub = (x[30:23] == 8'd0);
    wire [23:0] sig = {~sub, x[22:0]};           // significand with hidden bit
    assign nan_inf = &x[30:23];
    assign neg     = x[31] & (sig != 24'd0);
    assign ee      = sub ? 8'd1 : x[30:23];
    assign d       = e + 10'sd150 - {2'b00, ee};

    wire [4:0]  dc = (d < 10'sd0) ? 5'd0 : (d > 10'sd23) ? 5'd23 : d[4:0];
    assign mask   = ~(23'h7FFFFF << dc);
    // d >= 24: the whole significand is below 2^e
    assign sticky = (d > 10'sd23) ? (sig != 24'd0) : |(x[22:0] & mask);
    // normal x: |x| < 2^e <=> d >= 24; subnormals are below 2^-126 <= 2^e
    assign lt     = sub | (d > 10'sd23);
    assign le     = lt | ((d == 10'sd23) & (x[22:0] == 23'd0));
    assign big    = (d <= (10'sd24 - W10));

    // f = bits [d, d+W) of sig, zero outside: a W-bit window of {0, sig, 0}
    // starting at t = d + W (t in [0, 24+W]; anything else selects only zeros)
    wire signed [9:0] t = d + W10;
    // Right shift by tc, largest step first, so each stage keeps only the bits the
    // later stages can still reach (about half the muxes of a full-width shifter).
    wire [W+62:0] ext = {39'd0, sig, {W{1'b0}}};
    wire [5:0]    tc  = t[5:0];
    wire [W+30:0] s5  = tc[5] ? ext[W+62:32] : ext[W+30:0];
    wire [W+14:0] s4  = tc[4] ? s5[W+30:16]  : s5[W+14:0];
    wire [W+6:0]  s3  = tc[3] ? s4[W+14:8]   : s4[W+6:0];
    wire [W+2:0]  s2  = tc[2] ? s3[W+6:4]    : s3[W+2:0];
    wire [W:0]    s1  = tc[1] ? s2[W+2:2]    : s2[W:0];
    wire [W-1:0]  s0  = tc[0] ? s1[W:1]      : s1[W-1:0];
    assign f = ((t < 10'sd0) || (t > 10'sd24 + W10)) ? {W{1'b0}} : s0;
endmodule
