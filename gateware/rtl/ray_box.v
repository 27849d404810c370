// cbvh unit 6: ray-box slab test on the exact grid planes (docs/traversal.md §3,
// §6, §7; rounding and packing as docs/datapath.md §2).
//
// Independent implementation from the written spec. Sequential: one shared
// datapath visits the six planes (x L, x H, y L, ..., z H) in turn.
//
// Per plane the exact numerator N = u + c*2^e - O (c = r for L, s for H) is
// built in a 288-bit two's complement register R whose bit i weighs 2^(i-149):
// every term is a multiple of 2^-149 and |N| < 2^128 + 2^136 + 2^128 < 2^137.
// R is nine 32-bit chunks; a pass rotates R right by one chunk per cycle
// through a 32-bit adder, so the LSB chunk is always the one being updated and
// carries ripple from pass cycle to pass cycle:
//   FORM  3 passes (u, c*2^e, -O), each term cut into its 32-bit chunks by a
//         shifter (27 cycles)
//   NEG   one pass R = -R when N < 0 (9 cycles)
//   ROT   plain rotations until the highest nonzero chunk is on top (<= 8)
//   DIV   restoring division of R (MSB first, one bit per cycle) by the 24-bit
//         significand of D until the quotient has M significant bits; sticky =
//         remainder != 0 or any unread bit of R (<= ~80 cycles)
//   ROUND the M-bit truncation plus sticky is rounded once (toward -Inf for
//         t_near, +Inf for t_far) on the coarser of the M-bit and the binary32
//         grid (both powers of two, nested), with IEEE directed overflow
//         (3 cycles: exponent, both candidate results, the choice)
// A plane's operands and the three FORM terms are latched when the plane
// starts, and the running t_near/t_far are compared one cycle after they are
// updated, so that no path crosses two of these steps: the unit closes at
// about 15 MHz on the iCE40UP5K, above the board's 12 MHz clock.
// D = 0 axes only need the signs of L - O and H - O (FORM alone).
//
// Handshake: start is a one-cycle pulse, inputs stay stable until done; busy is
// high while a vector runs; done is a one-cycle pulse in the first cycle in
// which hit/t_near/t_far/status hold the result; they stay valid until the
// next start.

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_ray_box (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,
    output wire        busy,
    output reg         done,
    input  wire [31:0] ox, oy, oz,
    input  wire [31:0] dx, dy, dz,
    input  wire [31:0] tmin, tmax,
    input  wire [7:0]  mant,
    input  wire [31:0] x_u,
    input  wire [7:0]  x_scale,
    input  wire [11:0] x_r, x_s,
    input  wire [31:0] y_u,
    input  wire [7:0]  y_scale,
    input  wire [11:0] y_r, y_s,
    input  wire [31:0] z_u,
    input  wire [7:0]  z_scale,
    input  wire [11:0] z_r, z_s,
    output reg         hit,
    output reg  [31:0] t_near,
    output reg  [31:0] t_far,
    output reg  [7:0]  status
);
/* verilator lint_on DECLFILENAME */

    // --------------------------------------------------------------- helpers
    function is_nan;
        input [30:0] f;
        begin
            is_nan = (&f[30:23]) & (|f[22:0]);
        end
    endfunction

    function bad_scale;     // 8-bit two's complement outside [-126, 126]
        input [7:0] e;
        begin
            bad_scale = (e == 8'h7F) | (e == 8'h80) | (e == 8'h81);
        end
    endfunction

    // ---------------------------------------------------------------- status
    wire ray_bad, st_zero_dir;
    cbvh_ray_check u_ray (.ox(ox), .oy(oy), .oz(oz), .dx(dx), .dy(dy), .dz(dz), .tmin(tmin), .tmax(tmax),
                          .nan_inf(ray_bad), .zero_dir(st_zero_dir));
    wire st_nan_inf = ray_bad |
                      is_nan(x_u[30:0]) | (x_u == 32'h7F800000) |
                      is_nan(y_u[30:0]) | (y_u == 32'h7F800000) |
                      is_nan(z_u[30:0]) | (z_u == 32'h7F800000);
    // INVERTED per axis only when that axis's codes are in range (§3)
    wire st_inverted = ((x_r >= x_s) & (x_r <= 12'd1024) & (x_s <= 12'd1024)) |
                       ((y_r >= y_s) & (y_r <= 12'd1024) & (y_s <= 12'd1024)) |
                       ((z_r >= z_s) & (z_r <= 12'd1024) & (z_s <= 12'd1024));
    wire st_bad_scale = bad_scale(x_scale) | bad_scale(y_scale) | bad_scale(z_scale);
    wire st_bad_param = (mant < 8'd3) | (mant > 8'd24);
    wire st_bad_code = (x_r > 12'd1024) | (x_s > 12'd1024) | (y_r > 12'd1024) |
                       (y_s > 12'd1024) | (z_r > 12'd1024) | (z_s > 12'd1024);
    // §3: ZERO_DIR only for a ray without NaN/Inf (cbvh_ray_check); every
    // other applicable bit is ORed
    wire [7:0] st_all = {st_zero_dir, 2'b00, st_bad_code, st_bad_param,
                         st_bad_scale, st_inverted, st_nan_inf};

    // ------------------------------------------------------------- sequencer
    localparam [3:0] S_IDLE = 4'd0, S_PLANE = 4'd1, S_FORM = 4'd2, S_POST = 4'd3,
                     S_NEG = 4'd4, S_ROT = 4'd5, S_DIV = 4'd6, S_ROUND = 4'd7,
                     S_UPD = 4'd8, S_NEXT = 4'd9, S_FIN = 4'd10,
                     S_EXP = 4'd11, S_RND = 4'd12;
    reg [3:0]   state;
    reg [1:0]   axis;       // 0 x, 1 y, 2 z
    reg         plane;      // 0: L = u + r 2^e, 1: H = u + s 2^e
    reg [1:0]   ti;         // FORM term: 0 u, 1 c 2^e, 2 -O
    reg [3:0]   j;          // chunk index within a pass / rotation count
    reg         cy;         // carry between chunks of a pass
    reg         nz;         // the last FORM/NEG pass wrote a nonzero chunk
    reg [3:0]   hc;         // ... highest such chunk
    reg         sgn_n;      // sign of N
    reg [287:0] R;
    reg [23:0]  rem;        // division remainder, < D significand
    reg [23:0]  q;          // quotient bits so far
    reg [7:0]   t;          // division steps taken
    reg         sticky;
    reg [31:0]  res;        // rounded plane distance
    reg [31:0]  near_r, far_r;
    reg         miss;

    assign busy = (state != S_IDLE);

    // per-axis operands, selected by axis/plane and latched in S_PLANE so that
    // no path runs from the axis counter through the operand muxes (timing)
    reg [31:0] o_m, d_m, u_m;
    reg [7:0]  e_m;
    reg [11:0] r_m, s_m;
    always @* begin
        case (axis)
            2'd1:    begin o_m = oy; d_m = dy; u_m = y_u; e_m = y_scale; r_m = y_r; s_m = y_s; end
            2'd2:    begin o_m = oz; d_m = dz; u_m = z_u; e_m = z_scale; r_m = z_r; s_m = z_s; end
            default: begin o_m = ox; d_m = dx; u_m = x_u; e_m = x_scale; r_m = x_r; s_m = x_s; end
        endcase
    end
    reg        d_zero, d_neg;
    reg [23:0] d_sig;       // D = d_sig * 2^d_exp
    reg [11:0] d_exp;
    wire [4:0]  m_bits = mant[4:0];                         // 3..24 once checked
    // plane roles: D > 0: L near, H far; D < 0: H near, L far
    wire near_role = (plane == d_neg);

    // ---------------------------------------------- FORM term chunk extractor
    // a binary32 x = sig * 2^(pos - 149) with pos = max(E, 1) - 1; the exponent
    // field 255 of u = -Inf gives 2^23 * 2^105 = -2^128 (§3). The three terms
    // (u, c 2^e with c = r for L and s for H, -O) are latched in S_PLANE.
    wire [11:0] code_m = plane ? s_m : r_m;                 // <= 1024 once checked
    reg  [23:0] tsig_u, tsig_c, tsig_o;
    reg  [9:0]  tpos24_u, tpos24_c, tpos24_o;                // pos + 24
    reg         tneg_u, tneg_o;
    wire [23:0] tsig   = (ti == 2'd0) ? tsig_u : (ti == 2'd1) ? tsig_c : tsig_o;
    wire [9:0]  tpos24 = (ti == 2'd0) ? tpos24_u : (ti == 2'd1) ? tpos24_c : tpos24_o;
    wire        tneg   = (ti == 2'd0) ? tneg_u : (ti == 2'd2) & tneg_o;
    // bits [32j, 32j + 32) of tsig << tpos: with tt = tpos + 24 - 32j the chunk
    // is (tsig * 2^32 >> (56 - tt)) mod 2^32 when 0 <= tt <= 55, else zero
    wire [9:0]  j32    = {1'b0, j, 5'd0};
    wire [9:0]  tt     = tpos24 - j32;
    wire        t_in   = (tpos24 >= j32) && (tt <= 10'd55);
    wire [5:0]  t_sh   = 6'd56 - tt[5:0];
    wire [55:0] t_ext  = {tsig, 32'd0} >> t_sh;
    wire [31:0] t_chunk = t_in ? t_ext[31:0] : 32'd0;

    // ------------------------------------------------ chunk adder (all passes)
    wire        p_form = (state == S_FORM);
    wire        p_neg  = (state == S_NEG);
    wire [31:0] add_a  = p_neg ? ~R[31:0] : R[31:0];
    wire [31:0] add_b  = p_form ? (tneg ? ~t_chunk : t_chunk) : 32'd0;
    // a pass starts with carry 1 when it subtracts (two's complement)
    wire        cin0   = p_form ? tneg : p_neg;
    wire        add_c  = (state == S_ROT) ? 1'b0 : ((j == 4'd0) ? cin0 : cy);
    wire [32:0] add_s  = {1'b0, add_a} + {1'b0, add_b} + {32'd0, add_c};
    wire        chunk_nz = |add_s[31:0];

    // ---------------------------------------------------------- division step
    wire [24:0] rem2   = {rem, R[287]};
    wire        q_bit  = (rem2 >= {1'b0, d_sig});
    wire [23:0] rem2m  = rem2[23:0] - d_sig;     // < d_sig when q_bit
    wire [23:0] rem_n  = q_bit ? rem2m : rem2[23:0];
    wire [23:0] q_n    = {q[22:0], q_bit};
    wire        q_full = q_n[m_bits - 5'd1];
    wire [7:0]  t_n    = t + 8'd1;

    // rotations that bring chunk hc to the top; the value is then N * 2^(32 sh)
    wire [3:0]  rot_n  = (hc == 4'd8) ? 4'd0 : (hc + 4'd1);
    wire [3:0]  sh     = 4'd8 - hc;

    // ------------------------------------------------------------- rounding
    // |N / D| = (q + f) * 2^X, f in [0, 1) (f > 0 iff sticky), q in [2^(M-1), 2^M),
    // X = 139 - t - 32 sh - eD (R's top bit weighs 2^137 before the shifts)
    // Three cycles (timing): S_EXP latches X, S_RND both candidate results
    // (normal, and below 2^-126 the kept and lost bits), S_ROUND the choice.
    wire [11:0] x_exp_n = 12'd139 - {4'd0, t} - {3'd0, sh, 5'd0} - d_exp;
    reg  [11:0] x_exp;
    wire [11:0] k_exp = x_exp + {7'd0, m_bits} - 12'd1;       // exponent of q's top bit
    wire        q_neg = sgn_n ^ d_neg;
    wire        up    = ~near_role;                            // far: toward +Inf
    wire        away  = up ? ~q_neg : q_neg;                   // magnitude grows
    wire        r_norm = ($signed(k_exp) >= -12'sd126);
    // normal: round on the M-bit grid (exact in binary32 for M <= 24)
    wire [24:0] m_n    = {1'b0, q} + {24'd0, away & sticky};
    wire        m_cy   = m_n[m_bits];                          // rounded up to 2^M
    wire [11:0] k_r    = k_exp + {11'd0, m_cy};
    wire [24:0] m_al   = m_n << (5'd24 - m_bits);              // top bit at 24 (or 25 cut)
    wire [22:0] n_frac = m_cy ? 23'd0 : m_al[22:0];
    wire [11:0] n_bexp = k_r + 12'd127;
    wire        n_ovf  = ($signed(k_r) > 12'sd127);
    wire [30:0] n_body = n_ovf ? (away ? 31'h7F800000 : 31'h7F7FFFFF) : {n_bexp[7:0], n_frac};
    // below 2^-126: the grid is 2^max(X, -149); ss = X + 149
    wire [11:0] ss     = x_exp + 12'd149;
    wire        ss_pos = ~ss[11];
    wire [11:0] dr_w   = -ss;
    wire [4:0]  dr     = (dr_w > 12'd24) ? 5'd25 : dr_w[4:0];  // >= 25: all of q dropped
    wire [48:0] q_sh   = {q, 25'd0} >> dr;
    wire [23:0] q_kept = q_sh[48:25];
    wire        q_lost = |q_sh[24:0];
    wire [30:0] s_up   = {6'd0, m_n} << ss[4:0];               // ss <= 23 - M here
    reg  [30:0] n_body_r, s_up_r;
    reg  [23:0] q_kept_r;
    reg         q_lost_r, ss_pos_r, r_norm_r;
    wire [23:0] s_inc  = {23'd0, away & (sticky | q_lost_r)};
    wire [30:0] s_dn   = {7'd0, q_kept_r + s_inc};
    wire [30:0] s_body = ss_pos_r ? s_up_r : s_dn;
    wire [30:0] body   = r_norm_r ? n_body_r : s_body;
    wire [31:0] rnd    = (body == 31'd0) ? 32'd0 : {q_neg, body};
    // bits computed by the full-width expressions above that are never needed
    wire unused_bits = &{1'b0, t_ext[55:32], m_al[24:23], n_bexp[11:8]};

    // ---------------------------------------------------------- accumulators
    wire res_gt_near, far_gt_res, near_gt_far;
    cbvh_f32_gt u_gt_near (.a(res), .b(near_r), .gt(res_gt_near));
    cbvh_f32_gt u_gt_far  (.a(far_r), .b(res), .gt(far_gt_res));
    cbvh_f32_gt u_gt_nf   (.a(near_r), .b(far_r), .gt(near_gt_far));
    wire [31:0] near_u = (near_role && res_gt_near) ? res : near_r;
    wire [31:0] far_u  = (!near_role && far_gt_res) ? res : far_r;
    wire        last_plane = (axis == 2'd2) && plane;

    always @(posedge clk) begin
        done <= 1'b0;
        if (rst) begin
            state  <= S_IDLE;
            hit    <= 1'b0;
            t_near <= 32'd0;
            t_far  <= 32'd0;
            status <= 8'd0;
        end else begin
            case (state)
                S_IDLE: if (start) begin
                    status <= st_all;
                    hit    <= 1'b0;
                    t_near <= 32'd0;
                    t_far  <= 32'd0;
                    if (st_all != 8'd0) begin
                        done <= 1'b1;               // reject: other outputs zero
                    end else begin
                        near_r <= tmin;
                        far_r  <= tmax;
                        miss   <= 1'b0;
                        axis   <= 2'd0;
                        plane  <= 1'b0;
                        state  <= S_PLANE;
                    end
                end
                S_PLANE: begin
                    tsig_u   <= {|u_m[30:23], u_m[22:0]};
                    tpos24_u <= (u_m[30:23] == 8'd0) ? 10'd24 : ({2'd0, u_m[30:23]} + 10'd23);
                    tneg_u   <= u_m[31];
                    tsig_c   <= {12'd0, code_m};
                    tpos24_c <= {{2{e_m[7]}}, e_m} + 10'd173;    // e in [-126, 126]: 23..299
                    tsig_o   <= {|o_m[30:23], o_m[22:0]};
                    tpos24_o <= (o_m[30:23] == 8'd0) ? 10'd24 : ({2'd0, o_m[30:23]} + 10'd23);
                    tneg_o   <= ~o_m[31];                        // the term is -O
                    d_zero <= (d_m[30:0] == 31'd0);
                    d_neg  <= d_m[31];
                    d_sig  <= {|d_m[30:23], d_m[22:0]};
                    d_exp  <= (d_m[30:23] == 8'd0) ? -12'sd149 : ({4'd0, d_m[30:23]} - 12'd150);
                    R  <= 288'd0;
                    ti <= 2'd0;
                    j  <= 4'd0;
                    state <= S_FORM;
                end
                S_FORM, S_NEG, S_ROT: begin
                    if (state == S_ROT && j == rot_n) begin
                        rem <= 24'd0;
                        q   <= 24'd0;
                        t   <= 8'd0;
                        state <= S_DIV;
                    end else begin
                        R  <= {add_s[31:0], R[287:32]};
                        cy <= add_s[32];
                        j  <= j + 4'd1;
                        if (state != S_ROT) begin
                            nz <= ((j == 4'd0) ? 1'b0 : nz) | chunk_nz;
                            if (chunk_nz)
                                hc <= j;
                            else if (j == 4'd0)
                                hc <= 4'd0;
                        end
                        if (state != S_ROT && j == 4'd8) begin
                            j <= 4'd0;
                            if (state == S_NEG)
                                state <= S_ROT;
                            else if (ti == 2'd2)
                                state <= S_POST;
                            else
                                ti <= ti + 2'd1;
                        end
                    end
                end
                S_POST: begin
                    sgn_n <= R[287];
                    j <= 4'd0;
                    if (d_zero) begin
                        // parallel axis: L <= O <= H exactly (faces included)
                        if (plane ? R[287] : (~R[287] & nz))
                            miss <= 1'b1;
                        state <= (plane ? R[287] : (~R[287] & nz)) ? S_FIN : S_NEXT;
                    end else if (!nz) begin
                        res   <= 32'd0;            // N = 0: the distance is +0
                        state <= S_UPD;
                    end else begin
                        state <= R[287] ? S_NEG : S_ROT;
                    end
                end
                S_DIV: begin
                    R   <= {R[286:0], 1'b0};
                    rem <= rem_n;
                    q   <= q_n;
                    t   <= t_n;
                    if (q_full) begin
                        sticky <= (|rem_n) | (|R[286:0]);
                        state  <= S_EXP;
                    end
                end
                S_EXP: begin
                    x_exp <= x_exp_n;
                    state <= S_RND;
                end
                S_RND: begin
                    n_body_r <= n_body;
                    s_up_r   <= s_up;
                    q_kept_r <= q_kept;
                    q_lost_r <= q_lost;
                    ss_pos_r <= ss_pos;
                    r_norm_r <= r_norm;
                    state    <= S_ROUND;
                end
                S_ROUND: begin
                    res   <= rnd;
                    state <= S_UPD;
                end
                S_UPD: begin
                    near_r <= near_u;
                    far_r  <= far_u;
                    state  <= S_NEXT;
                end
                S_NEXT: begin
                    // the running max only grows and the min only shrinks
                    // (compared here, not in S_UPD: one compare per cycle)
                    if (near_gt_far) begin
                        miss  <= 1'b1;
                        state <= S_FIN;
                    end else if (last_plane) begin
                        state <= S_FIN;
                    end else begin
                        if (plane) axis <= axis + 2'd1;
                        plane <= ~plane;
                        state <= S_PLANE;
                    end
                end
                S_FIN: begin
                    if (!miss && !near_gt_far) begin
                        hit    <= 1'b1;
                        // a zero distance leaves as +0 (tmin/tmax may be -0; §3)
                        t_near <= (near_r[30:0] == 31'd0) ? 32'd0 : near_r;
                        t_far  <= (far_r[30:0] == 31'd0) ? 32'd0 : far_r;
                    end
                    done  <= 1'b1;
                    state <= S_IDLE;
                end
                default: state <= S_IDLE;
            endcase
        end
    end
endmodule

// The ray's own rejects, one rule for the ray-box and ray-sphere units
// (traversal.md §3, §10.2): NaN/Inf in o, d or tmin, NaN or -Inf in tmax
// (+Inf is an unbounded ray); a zero direction (components +-0) only for a
// ray without NaN/Inf.
/* verilator lint_off DECLFILENAME */ // shared by two units, kept with the first
module cbvh_ray_check (
    // whole binary32 words, as on every port; the check reads only some fields
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [31:0] ox, oy, oz,
    input  wire [31:0] dx, dy, dz,
    input  wire [31:0] tmin, tmax,
    /* verilator lint_on UNUSEDSIGNAL */
    output wire        nan_inf,
    output wire        zero_dir
);
/* verilator lint_on DECLFILENAME */
    assign nan_inf = (&ox[30:23]) | (&oy[30:23]) | (&oz[30:23]) |
                     (&dx[30:23]) | (&dy[30:23]) | (&dz[30:23]) | (&tmin[30:23]) |
                     ((&tmax[30:23]) & (|tmax[22:0])) | (tmax == 32'hFF800000);
    assign zero_dir = ~nan_inf & (dx[30:0] == 31'd0) & (dy[30:0] == 31'd0) & (dz[30:0] == 31'd0);
endmodule

// a > b in value order for binary32 without NaN (-0 = +0, -Inf and +Inf
// allowed), by order keys; shared by the ray units (kept with the first).
/* verilator lint_off DECLFILENAME */
module cbvh_f32_gt (
    input  wire [31:0] a,
    input  wire [31:0] b,
    output wire        gt
);
/* verilator lint_on DECLFILENAME */
    function [31:0] fkey;   // -0 and +0 get the same key
        input [31:0] f;
        begin
            if (f[30:0] == 31'd0)   fkey = 32'h80000000;
            else if (f[31])         fkey = ~f;
            else                    fkey = {1'b1, f[30:0]};
        end
    endfunction
    assign gt = fkey(a) > fkey(b);
endmodule
