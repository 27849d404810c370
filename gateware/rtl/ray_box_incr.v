// cbvh_ray_box_incr: unit 10, the incremental reduced-precision ray-box test
// (docs/traversal.md §17; seed 003's Eq. 5), pipelined.  P plane datapaths
// (cbvh_rbi_step) serve the six planes of a test, so a new test is taken
// every II = 6 / P clocks (in_ready): P = 6 (the default), one test per
// clock; P = 3, 2, 1: II = 2, 3, 6 for a third, half, a sixth of the steps.
// A result leaves SD + II + 3 clocks after its test was taken (10 at P = 6);
// in order, out_valid for one clock each.
//
// Parameters fix the design point: N code bits, M significant bits of the
// reciprocal and of the plane distances, X exponent bits of the plane-distance
// format F(M, X).  The ports mant and texp must equal M and X (BAD_PARAM
// otherwise; vectors hold one M per file).
//
// Per plane (cbvh_rbi_step): t + c 2^e rho, exact, rounded
// once outward into F: an N-bit normalise of the code, an M x N-bit product,
// a magnitude compare and swap, an alignment shift into a (M+N+3)-bit window
// with a sticky bit, one add or subtract, a leading-zero normalise, a directed
// increment of the M kept bits, F's range rules.  Then near/far per axis by
// the sign of rho, max(tmin, near) and min(tmax, far) in two comparator
// levels, hit = t_near <= t_far, every output zero on a miss or a reject.
//
// Why the window is enough: see cbvh_rbi_step.
/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_ray_box_incr #(
    parameter integer N = 6,
    parameter integer M = 8,
    parameter integer X = 8,
    parameter integer P = 6
) (
    input  wire        clk,
    input  wire        in_valid,
    output wire        in_ready,
    input  wire [31:0] rcp_x, rcp_y, rcp_z,
    input  wire [31:0] tmin, tmax,
    input  wire [7:0]  mant, texp,
    input  wire [31:0] x_t_lb, x_t_ub, y_t_lb, y_t_ub, z_t_lb, z_t_ub,
    input  wire [7:0]  x_scale, y_scale, z_scale,
    input  wire [11:0] x_r, x_sp, y_r, y_sp, z_r, z_sp,
    output reg         out_valid,
    output reg         hit,
    output reg  [31:0] t_near, t_far,
    output reg  [31:0] x_c_lb, x_c_ub, y_c_lb, y_c_ub, z_c_lb, z_c_ub,
    output reg  [7:0]  status
);
/* verilator lint_on DECLFILENAME */
    localparam integer II = 6 / P;
    localparam integer EMAX = (1 << (X - 1)) - 1;
    localparam integer EMIN = 2 - (1 << (X - 1));
    localparam [7:0] ST_NAN_INF = 8'h01, ST_INVERTED = 8'h02, ST_BAD_SCALE = 8'h04, ST_BAD_PARAM = 8'h08,
                     ST_BAD_CODE = 8'h10, ST_BAD_FORMAT = 8'h20;

    // ---- stage A: a test, held for its II issue phases ----
    reg        a_v = 1'b0;
    reg [2:0]  ph_r = 3'd0;
    wire [2:0] ph = (II == 1) ? 3'd0 : ph_r;   // the issue phase (a constant 0 at P = 6)
    reg [31:0] a_rcp [0:2];
    reg [31:0] a_tmin, a_tmax, a_lb [0:2], a_ub [0:2];
    reg [7:0]  a_mant, a_texp, a_e [0:2];
    reg [11:0] a_r [0:2], a_sp [0:2];
    localparam integer II1 = II - 1;
    localparam [2:0] PH_LAST = II1[2:0];
    wire last = (ph == PH_LAST);
    assign in_ready = !a_v || last;
    always @(posedge clk) begin
        if (in_valid && in_ready) begin
            a_v <= 1'b1; ph_r <= 3'd0;
            a_rcp[0] <= rcp_x; a_rcp[1] <= rcp_y; a_rcp[2] <= rcp_z;
            a_tmin <= tmin; a_tmax <= tmax; a_mant <= mant; a_texp <= texp;
            a_lb[0] <= x_t_lb; a_ub[0] <= x_t_ub; a_e[0] <= x_scale; a_r[0] <= x_r; a_sp[0] <= x_sp;
            a_lb[1] <= y_t_lb; a_ub[1] <= y_t_ub; a_e[1] <= y_scale; a_r[1] <= y_r; a_sp[1] <= y_sp;
            a_lb[2] <= z_t_lb; a_ub[2] <= z_t_ub; a_e[2] <= z_scale; a_r[2] <= z_r; a_sp[2] <= z_sp;
        end else if (last) a_v <= 1'b0;
        else ph_r <= ph_r + 3'd1;
    end

    // ---- status (docs/traversal.md §17.4), from the test in A ----
    function nan32;      input [30:0] f; nan32 = (f[30:23] == 8'hFF) && (f[22:0] != 23'd0); endfunction
    function naninf32;   input [7:0] ef; naninf32 = (ef == 8'hFF); endfunction
    // biased exponent field range of F's normal values, and the significand bits below M
    localparam integer BE_MIN_I = EMIN + 127, BE_MAX_I = EMAX + 127;
    localparam [7:0] BE_MIN = BE_MIN_I[7:0], BE_MAX = BE_MAX_I[7:0];
    localparam [22:0] LOWMASK = (23'd1 << (24 - M)) - 23'd1;
    function in_fmt;     // a value of F(M, X) (the caller excludes NaN)
        input [30:0] f;
        begin
            if (f[30:23] == 8'hFF)      in_fmt = 1'b1;   // +-Inf
            else if (f[30:0] == 31'd0)  in_fmt = 1'b1;   // +-0
            else in_fmt = f[30:23] >= BE_MIN && f[30:23] <= BE_MAX && (f[22:0] & LOWMASK) == 23'd0;
        end
    endfunction
    function rcp_fmt;    // +-0 or a normal binary32 with at most M significant bits
        input [30:0] f;
        rcp_fmt = (f[30:0] == 31'd0) || (f[30:23] != 8'd0 && (f[22:0] & LOWMASK) == 23'd0);
    endfunction
    // one axis' status bits (the ray's own checks are added below)
    localparam [7:0] MP = M[7:0], XP = X[7:0];
    localparam [12:0] CODE_LIM = 13'd1 << N;
    function [7:0] axis_st;
        input [30:0] rc, lb, ub;  // without the sign bits: no check reads them
        input [7:0]  e;
        input [11:0] r, sp;
        begin
            axis_st = 8'd0;
            if (naninf32(rc[30:23]) || nan32(lb) || nan32(ub)) axis_st = axis_st | ST_NAN_INF;
            if (a_mant == MP && a_texp == XP &&
                ((!naninf32(rc[30:23]) && !rcp_fmt(rc)) || (!nan32(lb) && !in_fmt(lb)) ||
                 (!nan32(ub) && !in_fmt(ub))))
                axis_st = axis_st | ST_BAD_FORMAT;
            if (e == 8'h80 || e == 8'h81 || e == 8'h7F) axis_st = axis_st | ST_BAD_SCALE;
            if ({1'b0, r} >= CODE_LIM || {1'b0, sp} >= CODE_LIM) axis_st = axis_st | ST_BAD_CODE;
            else if ({1'b0, r} + {1'b0, sp} >= CODE_LIM) axis_st = axis_st | ST_INVERTED;
        end
    endfunction
    wire [7:0] st_a = ((a_mant != MP || a_texp != XP) ? ST_BAD_PARAM : 8'd0) |
                      ((naninf32(a_tmin[30:23]) || nan32(a_tmax[30:0]) || a_tmax == 32'hFF800000) ? ST_NAN_INF : 8'd0) |
                      axis_st(a_rcp[0][30:0], a_lb[0][30:0], a_ub[0][30:0], a_e[0], a_r[0], a_sp[0]) |
                      axis_st(a_rcp[1][30:0], a_lb[1][30:0], a_ub[1][30:0], a_e[1], a_r[1], a_sp[1]) |
                      axis_st(a_rcp[2][30:0], a_lb[2][30:0], a_ub[2][30:0], a_e[2], a_r[2], a_sp[2]);

    // ---- issue: datapath u takes plane k = u II + ph (planes x_lb, x_ub, y_lb, y_ub, z_lb, z_ub) ----
    localparam integer SD = 6; // cbvh_rbi_step's depth
    wire [31:0] res [0:P-1];
    genvar g;
    generate
        for (g = 0; g < P; g = g + 1) begin : dp
            localparam integer K0 = g * II;
            wire [2:0] k = K0[2:0] + ph;        // the plane
            wire [1:0] ax = k[2:1];             // its axis
            wire       ub = k[0];               // 1: the upper plane, t_ub - s' 2^e rho
            wire [31:0] rc = a_rcp[ax];
            wire        par = (rc[30:0] == 31'd0);  // a parallel axis: offsets stepped with rho = 1
            // toward -Inf where the increment is >= 0: lower plane and rho >= +0, or upper plane and rho < 0
            cbvh_rbi_step #(.N(N), .M(M), .X(X)) step (
                .clk(clk), .t(ub ? a_ub[ax] : a_lb[ax]), .rho(par ? 32'h3F800000 : rc),
                .c(ub ? a_sp[ax][N-1:0] : a_r[ax][N-1:0]), .e(a_e[ax]), .sub(ub), .up(par ? ub : rc[31] ^ ub),
                .res(res[g]));
        end
    endgenerate

    // binary32 value order as an unsigned key: -0 and +0 get one key, and
    // unkey(key(f)) is f with -0 made +0 (the outputs' canonical zero)
    function [31:0] fkey; input [31:0] f; fkey = f[30:0] == 31'd0 ? 32'h80000000 : f[31] ? ~f : {1'b1, f[30:0]}; endfunction
    function [31:0] unkey; input [31:0] k; unkey = k[31] ? {1'b0, k[30:0]} : ~k; endfunction

    // valid and phase beside the datapaths in flip-flops; status, the keys of
    // tmin/tmax and the rho signs (A holds the test through its phases, so
    // the last phase carries them) in a block-RAM delay line
    reg        v_d  [0:SD-1];
    reg [2:0]  ph_d [0:SD-1];
    integer j;
    always @(posedge clk) begin
        v_d[0] <= a_v && last; ph_d[0] <= ph;
        for (j = 1; j < SD; j = j + 1) begin
            v_d[j] <= v_d[j-1]; ph_d[j] <= ph_d[j-1];
        end
    end
    wire [2:0] par_a = {a_rcp[2][30:0] == 31'd0, a_rcp[1][30:0] == 31'd0, a_rcp[0][30:0] == 31'd0};
    wire [77:0] side_d;
    cbvh_rbi_delay #(.W(78), .D(SD)) side (.clk(clk),
        .din({st_a, fkey(a_tmin), fkey(a_tmax), par_a, a_rcp[2][31], a_rcp[1][31], a_rcp[0][31]}), .dout(side_d));
    wire [7:0]  st_e = side_d[77:70];
    wire [31:0] kmin_e = side_d[69:38], kmax_e = side_d[37:6];
    wire [2:0]  pa = side_d[5:3];
    wire [2:0]  ng = side_d[2:0] & ~pa;   // the upper plane is the near one

    // ---- collect: the earlier phases' results wait; the last phase's join them ----
    /* verilator lint_off UNUSEDSIGNAL */ // at P = 6 no result waits: col is empty
    reg  [31:0] col [0:5];
    /* verilator lint_on UNUSEDSIGNAL */
    wire [31:0] cur [0:5];
    generate
        for (g = 0; g < 6; g = g + 1) begin : gather
            if (g % II == II - 1) begin : now
                assign cur[g] = res[g / II];
            end else begin : held
                localparam integer PHI = g % II;
                localparam [2:0] PHG = PHI[2:0];
                always @(posedge clk) if (ph_d[SD-1] == PHG) col[g] <= res[g / II];
                assign cur[g] = col[g];
            end
        end
    endgenerate
    wire [31:0] c_lb [0:2], c_ub [0:2];
    assign c_lb[0] = cur[0]; assign c_ub[0] = cur[1];
    assign c_lb[1] = cur[2]; assign c_ub[1] = cur[3];
    assign c_lb[2] = cur[4]; assign c_ub[2] = cur[5];

    // ---- near/far per axis as keys, t_near = max and t_far = min in two comparator levels, hit ----
    function [31:0] kmax; input [31:0] a, b; kmax = b > a ? b : a; endfunction
    function [31:0] kmin; input [31:0] a, b; kmin = b < a ? b : a; endfunction
    // a parallel axis takes no part in t_near, t_far (keys 0 and all ones) but
    // needs lower - o <= 0 <= upper - o
    localparam [31:0] K_ZERO = 32'h80000000;
    wire [31:0] n0 = pa[0] ? 32'd0 : fkey(ng[0] ? c_ub[0] : c_lb[0]), f0 = pa[0] ? ~32'd0 : fkey(ng[0] ? c_lb[0] : c_ub[0]);
    wire [31:0] n1 = pa[1] ? 32'd0 : fkey(ng[1] ? c_ub[1] : c_lb[1]), f1 = pa[1] ? ~32'd0 : fkey(ng[1] ? c_lb[1] : c_ub[1]);
    wire [31:0] n2 = pa[2] ? 32'd0 : fkey(ng[2] ? c_ub[2] : c_lb[2]), f2 = pa[2] ? ~32'd0 : fkey(ng[2] ? c_lb[2] : c_ub[2]);
    wire outside = (pa[0] && (fkey(c_lb[0]) > K_ZERO || fkey(c_ub[0]) < K_ZERO)) ||
                   (pa[1] && (fkey(c_lb[1]) > K_ZERO || fkey(c_ub[1]) < K_ZERO)) ||
                   (pa[2] && (fkey(c_lb[2]) > K_ZERO || fkey(c_ub[2]) < K_ZERO));

    // stage H1: the first comparator level; H2: the second; J: hit and the
    // outputs.  The six distances wait two clocks in a block-RAM delay line.
    reg        h_v, h_out;
    reg [7:0]  h_st;
    reg [31:0] h_n01, h_n2t, h_f01, h_f2t;
    always @(posedge clk) begin   // H1 (v_d: the test's last phase; ties keep tmin's key: the same value)
        h_v <= v_d[SD-1]; h_st <= st_e; h_out <= outside;
        h_n01 <= kmax(n0, n1); h_n2t <= kmax(kmin_e, n2);
        h_f01 <= kmin(f0, f1); h_f2t <= kmin(kmax_e, f2);
    end
    reg        i_v, i_out;
    reg [7:0]  i_st;
    reg [31:0] i_tn, i_tf;
    always @(posedge clk) begin   // H2
        i_v <= h_v; i_st <= h_st; i_out <= h_out;
        i_tn <= kmax(h_n2t, h_n01);
        i_tf <= kmin(h_f2t, h_f01);
    end
    wire [191:0] pl_d;
    cbvh_rbi_delay #(.W(192), .D(2)) planes (.clk(clk),
        .din({c_lb[0], c_ub[0], c_lb[1], c_ub[1], c_lb[2], c_ub[2]}), .dout(pl_d));
    wire i_hit = (i_st == 8'd0) && !i_out && !(i_tn > i_tf);
    always @(posedge clk) begin   // J: the outputs
        out_valid <= i_v;
        status <= i_st;
        hit <= i_hit;
        t_near <= i_hit ? unkey(i_tn) : 32'd0;
        t_far  <= i_hit ? unkey(i_tf) : 32'd0;
        x_c_lb <= i_hit ? pl_d[191:160] : 32'd0; x_c_ub <= i_hit ? pl_d[159:128] : 32'd0;
        y_c_lb <= i_hit ? pl_d[127:96] : 32'd0;  y_c_ub <= i_hit ? pl_d[95:64] : 32'd0;
        z_c_lb <= i_hit ? pl_d[63:32] : 32'd0;   z_c_ub <= i_hit ? pl_d[31:0] : 32'd0;
    end
endmodule

// One plane: res = RND(t + (-1)^sub c 2^e rho) into F(M, X), toward +Inf if
// up, else toward -Inf; t a value of F (or anything, when the unit rejects),
// rho +-0 or a normal binary32 with at most M significant bits.  Registered
// after each of six stages (B..G).
//
// The increment's magnitude is c rho 2^e = (cn rho_sig) 2^(e + E_rho - (M-1) - lz)
// with cn = c << lz normalised (N bits, lz its leading zeros), so the M x N
// product Q = cn rho_sig lies in [2^(W-2), 2^W), W = M + N: one conditional
// 1-bit shift normalises it.  t's M-bit significand is padded to W bits.  The
// larger magnitude ("big", exponent Eb) sits at the top of a G = W + 3 bit
// window; the smaller is shifted right by Eb - Es, the bits shifted out ORed
// into `lost`.  Bits are lost only for a shift above 3, and then the sm_al
// operand is below 2^(W-1) window units while big >= 2^(W+2): the sum or
// difference exceeds 2^(W+1) units, its M-bit rounding position is at least
// N + 2 >= 5 bits above the window's unit, and floor plus "a bit more"
// (difference: big - fl - 1 and the bit more) rounds as the exact value does
// (the argument of add_round in rtl-model/src/units/ray_box_incr.c).
/* verilator lint_off DECLFILENAME */ // the unit's plane, kept with it
module cbvh_rbi_step #(
    parameter integer N = 6,
    parameter integer M = 8,
    parameter integer X = 8
) (
    input  wire        clk,
    input  wire [31:0] t,
    input  wire [31:0] rho,
    input  wire [N-1:0] c,
    input  wire [7:0]  e,
    input  wire        sub,
    input  wire        up,
    output reg  [31:0] res
);
/* verilator lint_on DECLFILENAME */
    localparam integer W = M + N;
    localparam integer G = W + 3;
    localparam integer EMAX = (1 << (X - 1)) - 1;
    localparam integer EMIN = 2 - (1 << (X - 1));
    localparam integer LZW = 6;                        // bits of a leading-zero count (G + 1 <= 38)
    localparam [10:0] EZERO = 11'h400;                 // -1024: a zero operand's exponent
    localparam integer N1 = N - 1, BMIN_I = EMIN + 127, BMAX_I = EMAX + 127;
    localparam [LZW-1:0] LZ_N1 = N1[LZW-1:0], LZ_G = G[LZW-1:0];
    localparam signed [10:0] NS = N[10:0], GS = G[10:0], EMINS = EMIN[10:0], EMAXS = EMAX[10:0];
    localparam [7:0] BMIN = BMIN_I[7:0], BMAX = BMAX_I[7:0];

    function [LZW-1:0] lzc_n;   // leading zeros of an N-bit value (N for 0)
        input [N-1:0] v;
        integer i;
        reg found;
        begin
            lzc_n = N[LZW-1:0]; found = 1'b0;
            for (i = N - 1; i >= 0; i = i - 1)
                if (!found && v[i]) begin lzc_n = LZ_N1 - i[LZW-1:0]; found = 1'b1; end
        end
    endfunction
    // v << lz and lz, its leading zeros, in log2 steps (32, 16, ..., 1: a zero
    // test of the top s bits and a 2:1 mux each); v = 0 is the caller's case
    localparam [G:0] ONES = {(G+1){1'b1}};
    function [LZW+G:0] norm;
        input [G:0] v;
        reg [G:0] x;
        reg [LZW-1:0] n;
        integer s;
        begin
            x = v; n = {LZW{1'b0}};
            for (s = 32; s >= 1; s = s / 2)
                if (s <= G && (x & ~(ONES >> s)) == {(G+1){1'b0}}) begin
                    x = x << s;
                    n = n + s[LZW-1:0];
                end
            norm = {n, x};
        end
    endfunction

    // ---- B: decode, normalise the code, the M x N product ----
    wire [LZW-1:0] lzc = lzc_n(c);
    wire [N-1:0]   cn = c << lzc;
    wire [M-1:0]   rsig = {1'b1, rho[22 -: M-1]};
    reg  [W-1:0]   b_q;
    reg  [M-1:0]   b_tsig;
    reg  signed [10:0] b_et, b_ei;
    reg            b_tneg, b_tzero, b_tinf, b_ineg, b_izero, b_up;
    always @(posedge clk) begin
        b_q <= cn * rsig;
        b_tsig <= {1'b1, t[22 -: M-1]};
        b_et <= $signed({3'b000, t[30:23]}) - 11'sd127;
        // binade of the increment when the product's top bit is set
        b_ei <= $signed({{3{e[7]}}, e}) + $signed({3'b000, rho[30:23]}) - 11'sd127 + NS - $signed({5'd0, lzc});
        b_tneg <= t[31];
        b_tzero <= (t[30:0] == 31'd0);
        b_tinf <= (t[30:23] == 8'hFF);
        b_ineg <= rho[31] ^ sub;
        b_izero <= (c == {N{1'b0}}) || (rho[30:0] == 31'd0);
        b_up <= up;
    end

    // ---- C: normalise the product, compare magnitudes, swap ----
    wire [W-1:0] si = b_izero ? {W{1'b0}} : (b_q[W-1] ? b_q : (b_q << 1));
    wire signed [10:0] ei = b_izero ? $signed(EZERO) : (b_q[W-1] ? b_ei : b_ei - 11'sd1);
    wire [W-1:0] st = b_tzero ? {W{1'b0}} : ({b_tsig, {N{1'b0}}});
    wire signed [10:0] et = b_tzero ? $signed(EZERO) : b_et;
    // magnitudes as {exponent + 1024, significand}: unsigned order = magnitude order
    wire t_big = {et ^ 11'h400, st} >= {ei ^ 11'h400, si};
    wire signed [11:0] shd = t_big ? ($signed({et[10], et}) - $signed({ei[10], ei}))
                                   : ($signed({ei[10], ei}) - $signed({et[10], et}));
    reg  [W-1:0] c_sb, c_ss;
    reg  signed [10:0] c_eb;
    reg  [LZW-1:0] c_sh;
    reg  c_neg, c_sub, c_up, c_inf, c_tneg;
    always @(posedge clk) begin
        c_sb <= t_big ? st : si;
        c_ss <= t_big ? si : st;
        c_eb <= t_big ? et : ei;
        c_sh <= (shd > $signed({GS[10], GS})) ? LZ_G : shd[LZW-1:0];
        c_neg <= t_big ? b_tneg : b_ineg;
        c_sub <= b_tneg ^ b_ineg;
        c_up <= b_up;
        c_inf <= b_tinf;
        c_tneg <= b_tneg;
    end

    // ---- D: align the smaller operand, bits shifted out -> lost ----
    wire [G-1:0] sm_al = {c_ss, 3'b000};
    // the bits a right shift by c_sh drops: a thermometer code, bit i = (i < c_sh)
    wire [G-1:0] out_mask;
    genvar gi;
    generate for (gi = 0; gi < G; gi = gi + 1) begin : thermo
        localparam [LZW-1:0] GI = gi;
        assign out_mask[gi] = GI < c_sh;
    end endgenerate
    reg  [G-1:0] d_big, d_small;
    reg  d_lost;
    reg  signed [10:0] d_eb;
    reg  d_neg, d_sub, d_up, d_inf, d_tneg;
    always @(posedge clk) begin
        d_big <= {c_sb, 3'b000};
        d_small <= sm_al >> c_sh;
        d_lost <= (sm_al & out_mask) != {G{1'b0}};
        d_eb <= c_eb;
        d_neg <= c_neg; d_sub <= c_sub; d_up <= c_up; d_inf <= c_inf; d_tneg <= c_tneg;
    end

    // ---- E: add or subtract (big >= sm_al, so no sign change) ----
    reg  [G:0] e_r;
    reg  e_lost;
    reg  signed [10:0] e_eb;
    reg  e_neg, e_up, e_inf, e_tneg;
    always @(posedge clk) begin
        e_r <= d_sub ? ({1'b0, d_big} - {1'b0, d_small} - {{G{1'b0}}, d_lost}) : ({1'b0, d_big} + {1'b0, d_small});
        e_lost <= d_lost;
        e_eb <= d_eb;
        e_neg <= d_neg; e_up <= d_up; e_inf <= d_inf; e_tneg <= d_tneg;
    end

    // ---- F: normalise (bit G of the window weighs 2^(Eb + 1)) ----
    wire [LZW+G:0] nz = norm(e_r);
    wire [LZW-1:0] lz = nz[LZW+G:G+1];
    reg  [G:0] f_r;
    reg  signed [10:0] f_e;
    reg  f_zero, f_lost, f_neg, f_up, f_inf, f_tneg;
    always @(posedge clk) begin
        f_r <= nz[G:0];
        f_e <= e_eb + 11'sd1 - $signed({5'd0, lz});
        f_zero <= (e_r == {(G+1){1'b0}});
        f_lost <= e_lost; f_neg <= e_neg; f_up <= e_up; f_inf <= e_inf; f_tneg <= e_tneg;
    end

    // ---- G: round the M kept bits outward, F's range, pack ----
    wire [M-1:0] keep = f_r[G -: M];
    wire rem = (f_r[G-M:0] != {(G-M+1){1'b0}}) || f_lost;
    wire away = f_neg ^ f_up;
    wire [M:0] kr = {1'b0, keep} + {{M{1'b0}}, rem & away};
    wire carry = kr[M];
    wire signed [10:0] eq = carry ? f_e + 11'sd1 : f_e;
    wire [7:0] be = eq[7:0] + 8'd127;
    // the M-1 fraction bits at the top of binary32's 23 (a carry leaves them 0)
    wire [22:0] fx, fmax;
    generate
        if (M == 24) begin : frac_full
            assign fx = carry ? 23'd0 : kr[22:0];
            assign fmax = {23{1'b1}};
        end else begin : frac_short
            assign fx = carry ? 23'd0 : {kr[M-2:0], {(24-M){1'b0}}};
            assign fmax = {{(M-1){1'b1}}, {(24-M){1'b0}}};
        end
    endgenerate
    always @(posedge clk) begin
        if (f_inf) res <= {f_tneg, 8'hFF, 23'd0};                 // +-Inf + finite (a NaN t is rejected)
        else if (f_zero) res <= 32'd0;                             // exact zero
        else if (f_e < EMINS) res <= away ? {f_neg, BMIN, 23'd0} : 32'd0;
        else if (f_e > EMAXS) res <= away ? {f_neg, 8'hFF, 23'd0} : {f_neg, BMAX, fmax};
        else if (eq > EMAXS)  res <= {f_neg, 8'hFF, 23'd0};      // a carry past the largest binade
        else res <= {f_neg, be, fx};
    end
endmodule

// A D-clock delay line (2 <= D <= 8) in block RAM: written every clock,
// read D - 1 entries behind with a registered read.  Its first D outputs
// after power-up are whatever the RAM holds; the unit uses them only beside
// a valid test.
/* verilator lint_off DECLFILENAME */ // the unit's delay line, kept with it
module cbvh_rbi_delay #(parameter integer W = 8, parameter integer D = 6) (
    input  wire         clk,
    input  wire [W-1:0] din,
    output reg  [W-1:0] dout
);
/* verilator lint_on DECLFILENAME */
    localparam integer BACK = 9 - D;
    localparam [2:0] RA_OFF = BACK[2:0];
    (* ram_style = "block" *) reg [W-1:0] mem [0:7];
    reg  [2:0] wp = 3'd0;
    wire [2:0] ra = wp + RA_OFF;   // 3 bits: wraps (an index expression may not, in Icarus)
    always @(posedge clk) begin
        mem[wp] <= din;
        wp <= wp + 3'd1;
        dout <= mem[ra];
    end
endmodule
