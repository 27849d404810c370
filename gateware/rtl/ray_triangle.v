// cbvh unit 7: watertight ray-triangle test with exact edge functions
// (docs/traversal.md §4, exact arithmetic and the single rounding §2, status
// bits §6).
//
// Independent implementation from the written spec. Sequential: one 24x8-bit
// multiplier and one 32-bit adder compute the spec's exact quantities as sums
// of monomials in a wide accumulator (block RAM), then a word-serial
// non-restoring divider produces t, b1 and b2.
//
// Reformulation (exact identities, so the outputs are the spec's bits). With
// P_i = v_i - o and [a, b, c] = a . (b x c), the sheared edge functions of
// §4 are U = |d_kz| [d, P2, P1], V = |d_kz| [d, P0, P2], W = |d_kz| [d, P1, P0]
// (the shear's permutation is a rotation, or a rotation and a swap exactly
// when d_kz < 0), and t = T / (d_kz det) = [P0, P2, P1] / det' because
// o + t d = b0 v0 + b1 v1 + b2 v2 is the hit point of the ray's line. The
// positive factor |d_kz| changes no sign and cancels in every quotient, so
// the unit computes, in binary32 factors (o drops out of det'):
//   U' = [d, v2, v1] + [d, v1, o] + [d, o, v2]                (18 monomials)
//   V' = [d, v0, v2] + [d, v2, o] + [d, o, v0]                (18)
//   W' = [d, v1, v0] + [d, v0, o] + [d, o, v1]                (18)
//   det' = [d, v2, v1] + [d, v0, v2] + [d, v1, v0] = U' + V' + W'   (18)
//   Nt = [v0, v2, v1] - [o, v2, v1] - [v0, o, v1] - [v0, v2, o]      (24)
//   miss if U', V', W' have both strict signs, det' = 0, or Nt and det'
//   do not have the same strict sign (t > 0);
//   t = RD(Nt / det'), b1 = RD(V' / det'), b2 = RD(W' / det').
// Every binary32 x is sig * 2^(pos - 149) (sig 24 bits with the hidden bit,
// pos = max(E, 1) - 1 <= 253), so every monomial of three factors is an
// integer multiple of 2^-447 below 2^(72 + 759) = 2^831, and each sum of at
// most 24 of them lies below 2^836: a 27-word (864-bit) two's complement
// accumulator holds it exactly.
//
// On a hit every quotient is >= 0, so RD is truncation: no sticky bit is
// needed. Each magnitude is normalised by one word-serial funnel-shift pass
// (det' to its leading one at bit 860, the numerator at 859); 25 steps of a
// non-restoring division (R = 2R -+ D, one 27-word pass each) give the
// quotient bits of weight 2^0 ... 2^-24 of the normalised ratio, which
// rounds down to a normal binary32, a subnormal, +0 or (t only) FLT_MAX
// (IEEE overflow toward -Inf).
//
// Sequence per vector: clear the five accumulators (160 cycles); 96
// monomials (a zero factor skips it in one cycle; otherwise 11 cycles of
// multiply and 2 + 3..27 of accumulate); five sign/zero scans (28 cycles
// each); on a hit, for det', Nt, V', W': negation if det' < 0, a leading-one
// scan, a shift pass, and for the three numerators 25 division passes (28
// cycles each). 1 cycle (reject) to about 6,500 (a hit with every carry
// rippling to the top word); the committed vectors take 1,838 on average,
// 4,613 at most.
//
// Readings of the spec where it leaves a choice (traversal.md §4, §6):
// * status bit positions as cbvh_ray_box: NAN_INF 0, ZERO_DIR 7; ZERO_DIR
//   only when no input (ray or vertex) is NaN/Inf;
// * a miss outputs t = b1 = b2 = +0; a quotient below 2^-149 rounds down to
//   +0 (still a hit: the exact t > 0 decides); t above FLT_MAX is FLT_MAX.
//
// Handshake (as cbvh_ray_box): start is a one-cycle pulse, inputs stay stable
// until done; busy is high while a vector runs; done is a one-cycle pulse in
// the first cycle in which hit/t/b1/b2/status hold the result; they stay valid
// until the next start.

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_ray_triangle (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,
    output wire        busy,
    output reg         done,
    input  wire [31:0] ox, oy, oz,
    input  wire [31:0] dx, dy, dz,
    input  wire [31:0] v0x, v0y, v0z,
    input  wire [31:0] v1x, v1y, v1z,
    input  wire [31:0] v2x, v2y, v2z,
    output reg         hit,
    output reg  [31:0] t,
    output reg  [31:0] b1,
    output reg  [31:0] b2,
    output reg  [7:0]  status
);
/* verilator lint_on DECLFILENAME */

    // --------------------------------------------------------------- helpers
    function [4:0] msb32;       // index of the leading one (x != 0)
        input [31:0] x;
        integer b;
        begin
            msb32 = 5'd0;
            for (b = 0; b < 32; b = b + 1)
                if (x[b]) msb32 = b[4:0];
        end
    endfunction

    // ---------------------------------------------------------------- status
    // §4: NaN/Inf in any input -> NAN_INF (bit 0); d = 0 -> ZERO_DIR (bit 7),
    // only when no input is NaN/Inf
    wire st_nan_inf = (&ox[30:23]) | (&oy[30:23]) | (&oz[30:23]) |
                      (&dx[30:23]) | (&dy[30:23]) | (&dz[30:23]) |
                      (&v0x[30:23]) | (&v0y[30:23]) | (&v0z[30:23]) |
                      (&v1x[30:23]) | (&v1y[30:23]) | (&v1z[30:23]) |
                      (&v2x[30:23]) | (&v2y[30:23]) | (&v2z[30:23]);
    wire st_zero_dir = ~st_nan_inf & (dx[30:0] == 31'd0) & (dy[30:0] == 31'd0) & (dz[30:0] == 31'd0);
    wire [7:0] st_all = {st_zero_dir, 6'd0, st_nan_inf};

    // --------------------------------------------------------------- factors
    // factor ids: vector base + component (0 x, 1 y, 2 z)
    localparam [3:0] B_O = 4'd0, B_D = 4'd3, B_V0 = 4'd6, B_V1 = 4'd9, B_V2 = 4'd12;
    wire [14:0] zmask = {v2z[30:0] == 31'd0, v2y[30:0] == 31'd0, v2x[30:0] == 31'd0,
                         v1z[30:0] == 31'd0, v1y[30:0] == 31'd0, v1x[30:0] == 31'd0,
                         v0z[30:0] == 31'd0, v0y[30:0] == 31'd0, v0x[30:0] == 31'd0,
                         dz[30:0] == 31'd0,  dy[30:0] == 31'd0,  dx[30:0] == 31'd0,
                         oz[30:0] == 31'd0,  oy[30:0] == 31'd0,  ox[30:0] == 31'd0};

    // ------------------------------------------------------ triple-product ROM
    // entry tp: {slot[2:0], neg, a, b, c}: (-1)^neg [a, b, c] added to slot
    // slots: 0 U', 1 V', 2 W', 3 det', 4 Nt; 5 the division remainder
    localparam [2:0] SL_U = 3'd0, SL_V = 3'd1, SL_W = 3'd2, SL_DET = 3'd3, SL_NT = 3'd4, SL_R = 3'd5;
    reg [3:0]  tp;          // triple product
    reg [2:0]  mi;          // its monomial, 0..5
    reg        pend;        // past the last monomial
    reg [15:0] ent;
    always @* begin
        case (tp)
            4'd0:  ent = {SL_U,   1'b0, B_D,  B_V2, B_V1};
            4'd1:  ent = {SL_U,   1'b0, B_D,  B_V1, B_O};
            4'd2:  ent = {SL_U,   1'b0, B_D,  B_O,  B_V2};
            4'd3:  ent = {SL_V,   1'b0, B_D,  B_V0, B_V2};
            4'd4:  ent = {SL_V,   1'b0, B_D,  B_V2, B_O};
            4'd5:  ent = {SL_V,   1'b0, B_D,  B_O,  B_V0};
            4'd6:  ent = {SL_W,   1'b0, B_D,  B_V1, B_V0};
            4'd7:  ent = {SL_W,   1'b0, B_D,  B_V0, B_O};
            4'd8:  ent = {SL_W,   1'b0, B_D,  B_O,  B_V1};
            4'd9:  ent = {SL_DET, 1'b0, B_D,  B_V2, B_V1};
            4'd10: ent = {SL_DET, 1'b0, B_D,  B_V0, B_V2};
            4'd11: ent = {SL_DET, 1'b0, B_D,  B_V1, B_V0};
            4'd12: ent = {SL_NT,  1'b0, B_V0, B_V2, B_V1};
            4'd13: ent = {SL_NT,  1'b1, B_O,  B_V2, B_V1};
            4'd14: ent = {SL_NT,  1'b1, B_V0, B_O,  B_V1};
            default: ent = {SL_NT, 1'b1, B_V0, B_V2, B_O};
        endcase
    end
    wire [2:0] m_slot = ent[15:13];
    // [a, b, c] = sum over the permutations (i, j, k) of sgn * a_i b_j c_k
    reg [1:0] ci, cj, ck;
    always @* begin
        case (mi)
            3'd0:    begin ci = 2'd0; cj = 2'd1; ck = 2'd2; end   // +
            3'd1:    begin ci = 2'd0; cj = 2'd2; ck = 2'd1; end   // -
            3'd2:    begin ci = 2'd1; cj = 2'd2; ck = 2'd0; end   // +
            3'd3:    begin ci = 2'd1; cj = 2'd0; ck = 2'd2; end   // -
            3'd4:    begin ci = 2'd2; cj = 2'd0; ck = 2'd1; end   // +
            default: begin ci = 2'd2; cj = 2'd1; ck = 2'd0; end   // -
        endcase
    end
    wire [3:0] fa = ent[11:8] + {2'd0, ci};
    wire [3:0] fb = ent[7:4]  + {2'd0, cj};
    wire [3:0] fc = ent[3:0]  + {2'd0, ck};
    wire       m_neg  = ent[12] ^ mi[0];
    wire       m_zero = zmask[fa] | zmask[fb] | zmask[fc];

    // ------------------------------------------------------------- sequencer
    localparam [4:0] S_IDLE = 5'd0,  S_CLR = 5'd1,  S_FETCH = 5'd2, S_MA = 5'd3,
                     S_MB0  = 5'd4,  S_MB = 5'd5,   S_ACC0 = 5'd6,  S_ACC = 5'd7,
                     S_SC0  = 5'd8,  S_SC = 5'd9,   S_DEC = 5'd10,  S_JOB = 5'd11,
                     S_NG0  = 5'd12, S_NG = 5'd13,  S_LA = 5'd14,   S_SF0 = 5'd15,
                     S_SF   = 5'd16, S_DV0 = 5'd17, S_DV = 5'd18,   S_RND = 5'd19,
                     S_NEXT = 5'd20;
    reg [4:0]   state;
    reg [7:0]   clr;        // clear address
    reg [3:0]   fid;        // factor being read
    reg [23:0]  ma;         // first factor's significand
    reg [47:0]  p48;        // product of the first two, shifted out 8 bits a step
    reg [2:0]   mc;         // multiplier step
    reg [24:0]  ph;         // product: high part ...
    reg [47:0]  pl;         // ... and the low bits, shifted in 8 a step
    reg [9:0]   sh;         // bit position of the monomial (units of 2^-447)
    reg         mneg;       // sign of the monomial
    reg [2:0]   mslot;
    reg [3:0]   fb_r, fc_r; // its second and third factors (tp, mi move on)
    reg [4:0]   aw;         // accumulator word
    reg [2:0]   kk;         // product word feeding it (4: none left)
    reg         acy;        // carry between words
    reg [4:0]   wi;         // word of a pass
    reg [2:0]   scs;        // slot of a scan / negate / shift pass
    reg         jobs;       // 0: sign scans of U', V', W', det', Nt; 1: quotients
    reg [4:0]   sgn, nzv;   // signs and nonzero flags of the five sums
    reg         nzf;        // scan: a nonzero word seen
    reg [4:0]   lw;         // ... the highest one
    reg [31:0]  lval;       // ... and its value
    reg [1:0]   job;        // 0 det', 1 Nt -> t, 2 V' -> b1, 3 W' -> b2
    reg         detneg;     // det' < 0: every magnitude is negated first
    reg [9:0]   la;         // leading one of the magnitude being normalised
    reg [9:0]   lb;         // ... of det'
    reg [31:0]  prev;       // shift pass: previous source word
    reg         rvalid;     // shift pass: the word being read exists
    reg         pbit;       // division: top bit of the previous remainder word
    reg         sub;        // division: this step subtracts (R >= 0)
    reg [4:0]   step;       // division step
    reg [24:0]  qb;         // quotient bits b0 ... b24

    assign busy = (state != S_IDLE);

    // slot of the current job
    reg [2:0] job_slot;
    always @* begin
        case (job)
            2'd0:    job_slot = SL_DET;
            2'd1:    job_slot = SL_NT;
            2'd2:    job_slot = SL_V;
            default: job_slot = SL_W;
        endcase
    end

    // factor value of fid
    always @* begin
        case (state)
            S_MA:         fid = fb_r;
            S_MB0, S_MB:  fid = fc_r;
            default:      fid = fa;
        endcase
    end
    reg [31:0] fv;
    always @* begin
        case (fid)
            4'd0:  fv = ox;   4'd1:  fv = oy;   4'd2:  fv = oz;
            4'd3:  fv = dx;   4'd4:  fv = dy;   4'd5:  fv = dz;
            4'd6:  fv = v0x;  4'd7:  fv = v0y;  4'd8:  fv = v0z;
            4'd9:  fv = v1x;  4'd10: fv = v1y;  4'd11: fv = v1z;
            4'd12: fv = v2x;  4'd13: fv = v2y;  default: fv = v2z;
        endcase
    end
    wire [23:0] fsig = {|fv[30:23], fv[22:0]};
    wire [9:0]  fpos = (fv[30:23] == 8'd0) ? 10'd0 : ({2'd0, fv[30:23]} - 10'd1);
    wire        fsgn = fv[31];

    // the one multiplier, 24 x 8 bits, least significant chunk first:
    // S_MA: ma * fsig(b) in 3 steps, S_MB: fsig(c) * p48 in 6 steps; each step
    // adds the partial product to the high part and shifts 8 finished bits
    // into the low part. The product of three is {ph[23:0], pl} (< 2^72).
    reg [23:0] mul_x;
    reg [7:0]  mul_y;
    always @* begin
        if (state == S_MA) begin
            mul_x = ma;
            case (mc)
                3'd0:    mul_y = fsig[7:0];
                3'd1:    mul_y = fsig[15:8];
                default: mul_y = fsig[23:16];
            endcase
        end else begin
            mul_x = fsig;
            mul_y = p48[7:0];
        end
    end
    wire [31:0] mprod = mul_x * mul_y;
    wire [32:0] msum  = {8'd0, ph} + {1'd0, mprod};

    // ------------------------------------------------------------- memories
    // A: 256 x 32, synchronous read: slot s word w at {s, w}
    // D: 32 x 32, the normalised |det'|
    reg  [31:0] mem_a [0:255];
    reg  [31:0] mem_d [0:31];
    reg  [31:0] a_rd, d_rd;
    reg  [7:0]  a_ra;
    reg  [7:0]  a_wa;
    reg  [31:0] a_wd;
    reg         a_we;
    reg         d_we;
    always @(posedge clk) begin
        if (a_we)
            mem_a[a_wa] <= a_wd;
        a_rd <= mem_a[a_ra];
        if (d_we)
            mem_d[wi] <= a_wd;
        d_rd <= mem_d[a_ra[4:0]];
    end

    // shift pass amounts: target bit 860 (det') or 859 (numerators)
    wire [9:0]  l_sh = ((job == 2'd0) ? 10'd860 : 10'd859) - la;
    wire [4:0]  wq   = l_sh[9:5];
    wire [4:0]  br   = l_sh[4:0];
    wire [31:0] cur  = rvalid ? a_rd : 32'd0;

    // product words (word kk and the one below it feed the funnel shifter)
    reg [31:0] pw_hi, pw_lo;
    always @* begin
        case (kk)
            3'd0:    begin pw_hi = pl[31:0];                pw_lo = 32'd0; end
            3'd1:    begin pw_hi = {ph[15:0], pl[47:32]};   pw_lo = pl[31:0]; end
            3'd2:    begin pw_hi = {24'd0, ph[23:16]};      pw_lo = {ph[15:0], pl[47:32]}; end
            3'd3:    begin pw_hi = 32'd0;                   pw_lo = {24'd0, ph[23:16]}; end
            default: begin pw_hi = 32'd0;                   pw_lo = 32'd0; end
        endcase
    end
    // one funnel shifter: accumulator word kk of the product << sh mod 32, or
    // the shift pass's word
    wire        f_acc = (state == S_ACC);
    wire [63:0] fun   = {f_acc ? pw_hi : cur, f_acc ? pw_lo : prev} << (f_acc ? sh[4:0] : br);
    wire [31:0] pk    = fun[63:32];
    // the product (< 2^72) shifted by sh mod 32 ends in word 2, or 3 when sh mod 32 > 24
    wire        hi_zero = (kk >= ((sh[4:0] > 5'd24) ? 3'd3 : 3'd2));
    // one 32-bit adder for every pass
    reg  [31:0] add_a, add_b;
    reg         add_c;
    wire [32:0] add_s = {1'b0, add_a} + {1'b0, add_b} + {32'd0, add_c};
    always @* begin
        case (state)
            S_ACC: begin add_a = a_rd; add_b = mneg ? ~pk : pk; add_c = acy; end
            S_NG:  begin add_a = ~a_rd; add_b = 32'd0; add_c = acy; end
            default: begin  // S_DV: 2R -+ D
                add_a = {a_rd[30:0], pbit}; add_b = sub ? ~d_rd : d_rd; add_c = acy;
            end
        endcase
    end
    wire acc_last = (hi_zero && (add_s[32] == mneg)) || (aw == 5'd26);

    // memory ports per state
    always @* begin
        a_we = 1'b0;
        d_we = 1'b0;
        a_wa = {SL_R, wi};
        a_wd = add_s[31:0];
        a_ra = 8'd0;
        case (state)
            S_CLR: begin a_we = 1'b1; a_wa = clr; a_wd = 32'd0; end
            S_ACC0: a_ra = {mslot, sh[9:5]};
            S_ACC: begin a_we = 1'b1; a_wa = {mslot, aw}; a_ra = {mslot, aw + 5'd1}; end
            S_SC0: a_ra = {scs, 5'd26};
            S_SC:  a_ra = {scs, wi - 5'd1};
            S_NG0: a_ra = {scs, 5'd0};
            S_NG:  begin a_we = 1'b1; a_wa = {scs, wi}; a_ra = {scs, wi + 5'd1}; end
            S_SF0: a_ra = {scs, 5'd0 - wq};
            S_SF:  begin
                a_we = (job != 2'd0);
                d_we = (job == 2'd0);
                a_wd = fun[63:32];
                a_ra = {scs, wi + 5'd1 - wq};
            end
            S_DV0: a_ra = {SL_R, 5'd0};
            S_DV:  begin a_we = 1'b1; a_ra = {SL_R, wi + 5'd1}; end
            default: ;
        endcase
    end

    // ------------------------------------------------------------- rounding
    // q = (qb / 2^24) * 2^(la - lb), qb in [2^23, 2^25)
    wire [11:0] e_base = {2'd0, la} - {2'd0, lb};
    wire [11:0] e_out  = qb[24] ? e_base : (e_base - 12'd1);
    wire [23:0] sig    = qb[24] ? qb[24:1] : qb[23:0];
    wire [11:0] e_bias = e_out + 12'd127;
    wire [11:0] k_sub  = e_base + 12'd149;          // subnormal: floor(q 2^149) = qb >> (24 - k)
    wire [4:0]  k_sh   = 5'd24 - k_sub[4:0];
    wire [24:0] q_sub  = qb >> k_sh;
    reg  [31:0] rnd;
    // bits computed by the full-width expressions above that are never needed
    wire unused_bits = &{1'b0, fun[31:0], sig[23], e_bias[11:8]};
    always @* begin
        if ($signed(e_out) > 12'sd127)
            rnd = 32'h7F7FFFFF;                     // overflow toward -Inf
        else if ($signed(e_out) >= -12'sd126)
            rnd = {1'b0, e_bias[7:0], sig[22:0]};
        else if ($signed(k_sub) < 12'sd0)
            rnd = 32'd0;
        else
            rnd = {7'd0, q_sub};
    end

    // decision after the sign scans
    wire e_pos = |(nzv[2:0] & ~sgn[2:0]);
    wire e_neg = |(nzv[2:0] & sgn[2:0]);
    wire miss  = (e_pos & e_neg) | ~nzv[3] | ~nzv[4] | (sgn[3] != sgn[4]);

    always @(posedge clk) begin
        done <= 1'b0;
        if (rst) begin
            state  <= S_IDLE;
            hit    <= 1'b0;
            t      <= 32'd0;
            b1     <= 32'd0;
            b2     <= 32'd0;
            status <= 8'd0;
        end else begin
            case (state)
                S_IDLE: if (start) begin
                    status <= st_all;
                    hit    <= 1'b0;
                    t      <= 32'd0;
                    b1     <= 32'd0;
                    b2     <= 32'd0;
                    if (st_all != 8'd0) begin
                        done <= 1'b1;               // reject: other outputs zero
                    end else begin
                        clr   <= 8'd0;
                        state <= S_CLR;
                    end
                end
                S_CLR: begin
                    clr <= clr + 8'd1;
                    if (clr == {SL_NT, 5'd31}) begin
                        tp    <= 4'd0;
                        mi    <= 3'd0;
                        pend  <= 1'b0;
                        state <= S_FETCH;
                    end
                end
                // ---------------------------------------------- monomials
                S_FETCH: begin
                    if (pend) begin
                        jobs  <= 1'b0;
                        scs   <= SL_U;
                        state <= S_SC0;
                    end else begin
                        mi <= (mi == 3'd5) ? 3'd0 : (mi + 3'd1);
                        if (mi == 3'd5) begin
                            tp <= tp + 4'd1;
                            if (tp == 4'd15)
                                pend <= 1'b1;
                        end
                        if (!m_zero) begin
                            ma    <= fsig;
                            sh    <= fpos;
                            mneg  <= m_neg ^ fsgn;
                            mslot <= m_slot;
                            fb_r  <= fb;
                            fc_r  <= fc;
                            ph    <= 25'd0;
                            mc    <= 3'd0;
                            state <= S_MA;
                        end
                    end
                end
                S_MA, S_MB: begin
                    ph  <= msum[32:8];
                    pl  <= {msum[7:0], pl[47:8]};
                    p48 <= {8'd0, p48[47:8]};
                    mc  <= mc + 3'd1;
                    if (mc == 3'd0) begin
                        sh   <= sh + fpos;
                        mneg <= mneg ^ fsgn;
                    end
                    if (state == S_MA && mc == 3'd2)
                        state <= S_MB0;
                    if (state == S_MB && mc == 3'd5)
                        state <= S_ACC0;
                end
                S_MB0: begin
                    p48   <= {ph[23:0], pl[47:24]};    // the product of two
                    ph    <= 25'd0;
                    mc    <= 3'd0;
                    state <= S_MB;
                end
                S_ACC0: begin
                    aw    <= sh[9:5];
                    kk    <= 3'd0;
                    acy   <= mneg;
                    state <= S_ACC;
                end
                S_ACC: begin
                    if (acc_last) begin
                        state <= S_FETCH;
                    end else begin
                        aw  <= aw + 5'd1;
                        if (kk != 3'd4)
                            kk <= kk + 3'd1;
                        acy <= add_s[32];
                    end
                end
                // ------------------------------------------- scans (26 .. 0)
                S_SC0: begin
                    wi    <= 5'd26;
                    nzf   <= 1'b0;
                    state <= S_SC;
                end
                S_SC: begin
                    if (wi == 5'd26 && !jobs)
                        sgn[scs] <= a_rd[31];
                    if (!nzf && a_rd != 32'd0) begin
                        nzf  <= 1'b1;
                        lw   <= wi;
                        lval <= a_rd;
                    end
                    if (wi != 5'd0) begin
                        wi <= wi - 5'd1;
                    end else if (!jobs) begin
                        nzv[scs] <= nzf | (a_rd != 32'd0);
                        if (scs == SL_NT) begin
                            state <= S_DEC;
                        end else begin
                            scs   <= scs + 3'd1;
                            state <= S_SC0;
                        end
                    end else begin
                        state <= S_LA;
                    end
                end
                S_DEC: begin
                    if (miss) begin
                        done  <= 1'b1;
                        state <= S_IDLE;
                    end else begin
                        detneg <= sgn[3];
                        jobs   <= 1'b1;
                        job    <= 2'd0;
                        state  <= S_JOB;
                    end
                end
                // ---------------------------------------------- quotients
                S_JOB: begin
                    scs   <= job_slot;
                    state <= detneg ? S_NG0 : S_SC0;
                end
                S_NG0: begin
                    wi    <= 5'd0;
                    acy   <= 1'b1;
                    state <= S_NG;
                end
                S_NG: begin
                    acy <= add_s[32];
                    wi  <= wi + 5'd1;
                    if (wi == 5'd26)
                        state <= S_SC0;
                end
                S_LA: begin
                    if (!nzf) begin
                        // a zero numerator (V' or W'): the weight is +0
                        state <= S_NEXT;
                    end else begin
                        la <= {lw, msb32(lval)};
                        if (job == 2'd0)
                            lb <= {lw, msb32(lval)};
                        state <= S_SF0;
                    end
                end
                S_SF0: begin
                    wi     <= 5'd0;
                    prev   <= 32'd0;
                    rvalid <= (wq == 5'd0);
                    state  <= S_SF;
                end
                S_SF: begin
                    prev   <= cur;
                    rvalid <= ((wi + 5'd1) >= wq);
                    wi     <= wi + 5'd1;
                    if (wi == 5'd26) begin
                        if (job == 2'd0) begin
                            state <= S_NEXT;
                        end else begin
                            step  <= 5'd0;
                            sub   <= 1'b1;
                            state <= S_DV0;
                        end
                    end
                end
                S_DV0: begin
                    wi    <= 5'd0;
                    pbit  <= 1'b0;
                    acy   <= sub;
                    state <= S_DV;
                end
                S_DV: begin
                    pbit <= a_rd[31];
                    acy  <= add_s[32];
                    wi   <= wi + 5'd1;
                    if (wi == 5'd26) begin
                        qb   <= {qb[23:0], ~add_s[31]};
                        sub  <= ~add_s[31];
                        step <= step + 5'd1;
                        state <= (step == 5'd24) ? S_RND : S_DV0;
                    end
                end
                S_RND: begin
                    case (job)
                        2'd1:    t  <= rnd;
                        2'd2:    b1 <= rnd;
                        default: b2 <= rnd;
                    endcase
                    state <= S_NEXT;
                end
                S_NEXT: begin
                    if (job == 2'd3) begin
                        hit   <= 1'b1;
                        done  <= 1'b1;
                        state <= S_IDLE;
                    end else begin
                        job   <= job + 2'd1;
                        state <= S_JOB;
                    end
                end
                default: state <= S_IDLE;
            endcase
        end
    end
endmodule
