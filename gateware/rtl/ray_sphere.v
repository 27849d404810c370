// cbvh unit 9: closed ball vs segment, decided exactly (docs/traversal.md §10,
// status bits §6 / §10.2).
//
// Independent implementation from the written spec. Sequential: one 32x24-bit
// multiplier and one 32-bit adder evaluate the signs of the spec's exact
// polynomials (§10.1) monomial by monomial into a wide accumulator.
//
// Every binary32 input x is sig * 2^(pos - 149) (sig 24 bits with the hidden
// bit, pos = max(E, 1) - 1 in 0..253). With w = c - o, the four decisions of
// §10.1 are signs of polynomials of degree <= 4 in the inputs, expanded into
// monomials kappa * x1 * ... * xk (kappa = +-1 or +-2, k = 2..4):
//   Q(T)  = B - T*A       = sum_i c_i d_i - o_i d_i - T d_i d_i                (9)
//   E(T)  = |T*d - w|^2 - r^2
//         = sum_i T T d_i d_i + c_i c_i + o_i o_i - 2 T d_i c_i + 2 T d_i o_i
//                 - 2 c_i o_i,  - r r                                         (19)
//   D     = |w x d|^2 - r^2 A, with (w x d) for (j, k) = (y, z), (z, x), (x, y)
//           = c_j d_k - o_j d_k - c_k d_j + o_k d_j squared out, - r r d_i d_i  (33)
// Every monomial is an integer multiple of 2^-596 (four factors of 2^-149), so
// the accumulator is a two's complement integer in units of 2^-596: bit
// position of a monomial s = sum pos + 149 * (4 - k) + (kappa = +-2), <= 1013,
// its magnitude < 2^96, the sum of <= 33 of them < 2^1115: 35 words of 32 bits
// (1120 bits) hold every sum with its sign.
//   tmin > tmax (value order, -0 = +0)    -> miss
//   Q(tmin) < 0                            -> hit iff E(tmin) <= 0
//   tmax finite and -Q(tmax) < 0           -> hit iff E(tmax) <= 0
//   otherwise                              -> hit iff D <= 0
// "X <= 0" is tested as "X - 1 < 0" (X is an integer in these units): the
// accumulator starts at -1 for E and D, at 0 for Q.
//
// Per monomial: FETCH (zero factor: skipped), MUL (the 24-bit significands
// multiplied in 32-bit words: 1 + 2 + 3 cycles for four factors), ACC0 (first
// accumulator read), ACC (the product shifted by s mod 32, added to words
// s / 32 ... one word per cycle, two's complement for negative monomials; the
// carry ripples on only while the rest is not neutral). The accumulator is a
// 64 x 32-bit synchronous-read RAM (two iCE40 EBRs) with one "written" bit
// per word, so clearing it to 0 or -1 takes one cycle. Cycles per vector:
// 1 (reject, empty segment) to about 2,130 (Q(tmin), Q(tmax), D with every
// carry rippling to the top word); the committed vectors take 235 on average,
// 722 at most.
//
// Readings of the spec where it leaves a choice (traversal.md §10):
// * "tmin > tmax (as binary32 keys)": value order, -0 = +0 (§1), so
//   [+0, -0] is the point t = 0, not an empty segment;
// * a reject wins over an empty segment: its status is reported (hit 0);
// * "ZERO_DIR only when the ray has no NaN/Inf": the ray is o, d, tmin, tmax
//   and tmax = +Inf is valid, i.e. ZERO_DIR unless NAN_INF is set (as the
//   ray-box unit); BAD_PARAM does not suppress it;
// * status bit positions as cbvh_ray_box: NAN_INF 0, BAD_PARAM 3, ZERO_DIR 7.
//
// Handshake (as cbvh_ray_box): start is a one-cycle pulse, inputs stay stable
// until done; busy is high while a vector runs; done is a one-cycle pulse in
// the first cycle in which hit/status hold the result; they stay valid until
// the next start.

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_ray_sphere (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,
    output wire        busy,
    output reg         done,
    input  wire [31:0] ox, oy, oz,
    input  wire [31:0] dx, dy, dz,
    input  wire [31:0] tmin, tmax,
    input  wire [31:0] cx, cy, cz,
    input  wire [31:0] r,
    output reg         hit,
    output reg  [7:0]  status
);
/* verilator lint_on DECLFILENAME */

    // --------------------------------------------------------------- helpers
    function is_naninf;     // exponent field all ones
        input [7:0] ef;
        begin
            is_naninf = &ef;
        end
    endfunction

    // ---------------------------------------------------------------- status
    // §10.2: NAN_INF (bit 0) for the ray, BAD_PARAM (bit 3) for c and r,
    // ZERO_DIR (bit 7) only for a ray without NaN/Inf; bits ORed
    wire ray_bad, st_zero_dir;
    cbvh_ray_check u_ray (.ox(ox), .oy(oy), .oz(oz), .dx(dx), .dy(dy), .dz(dz), .tmin(tmin), .tmax(tmax),
                          .nan_inf(ray_bad), .zero_dir(st_zero_dir));
    wire st_bad_param = is_naninf(cx[30:23]) | is_naninf(cy[30:23]) | is_naninf(cz[30:23]) |
                        is_naninf(r[30:23]) |
                        (r[31] & (r[30:0] != 31'd0));
    wire [7:0] st_all = {st_zero_dir, 3'b000, st_bad_param, 2'b00, ray_bad};
    wire empty_seg;
    cbvh_f32_gt u_empty (.a(tmin), .b(tmax), .gt(empty_seg));
    wire tmax_inf  = (tmax == 32'h7F800000);

    // --------------------------------------------------------------- factors
    // factor ids of the monomial ROM; T is tmin or tmax (tsel)
    localparam [3:0] F_OX = 4'd0, F_OY = 4'd1, F_OZ = 4'd2,
                     F_CX = 4'd3, F_CY = 4'd4, F_CZ = 4'd5,
                     F_DX = 4'd6, F_DY = 4'd7, F_DZ = 4'd8,
                     F_T  = 4'd9, F_R  = 4'd10, F_1 = 4'd15;
    reg tsel;               // 0: T = tmin, 1: T = tmax

    // factor value = 0 (the monomial vanishes), per id; F_1 and unused ids are not
    wire t_zero = tsel ? (tmax[30:0] == 31'd0) : (tmin[30:0] == 31'd0);
    wire [15:0] zmask = {5'd0, r[30:0] == 31'd0, t_zero,
                         dz[30:0] == 31'd0, dy[30:0] == 31'd0, dx[30:0] == 31'd0,
                         cz[30:0] == 31'd0, cy[30:0] == 31'd0, cx[30:0] == 31'd0,
                         oz[30:0] == 31'd0, oy[30:0] == 31'd0, ox[30:0] == 31'd0};

    // ------------------------------------------------------------ monomial ROM
    // entry: {end, neg, two, k[2:0], f1, f2, f3, f4}; value (-1)^neg * 2^two * f1 ... fk
    localparam [5:0] PC_Q = 6'd0, PC_E = 6'd10, PC_D = 6'd30;   // program starts
    function [21:0] mono;
        input neg, two;
        input [2:0] k;
        input [3:0] f1, f2, f3, f4;
        begin
            mono = {1'b0, neg, two, k, f1, f2, f3, f4};
        end
    endfunction
    localparam [21:0] M_END = {1'b1, 21'd0};

    reg [5:0] pc;
    reg [21:0] ent;
    always @* begin
        case (pc)
            // Q(T) = sum_i c_i d_i - o_i d_i - T d_i d_i
            6'd0:  ent = mono(1'b0, 1'b0, 3'd2, F_CX, F_DX, F_1,  F_1);
            6'd1:  ent = mono(1'b1, 1'b0, 3'd2, F_OX, F_DX, F_1,  F_1);
            6'd2:  ent = mono(1'b1, 1'b0, 3'd3, F_T,  F_DX, F_DX, F_1);
            6'd3:  ent = mono(1'b0, 1'b0, 3'd2, F_CY, F_DY, F_1,  F_1);
            6'd4:  ent = mono(1'b1, 1'b0, 3'd2, F_OY, F_DY, F_1,  F_1);
            6'd5:  ent = mono(1'b1, 1'b0, 3'd3, F_T,  F_DY, F_DY, F_1);
            6'd6:  ent = mono(1'b0, 1'b0, 3'd2, F_CZ, F_DZ, F_1,  F_1);
            6'd7:  ent = mono(1'b1, 1'b0, 3'd2, F_OZ, F_DZ, F_1,  F_1);
            6'd8:  ent = mono(1'b1, 1'b0, 3'd3, F_T,  F_DZ, F_DZ, F_1);
            6'd9:  ent = M_END;
            // E(T) = |T d - c + o|^2 - r^2
            6'd10: ent = mono(1'b0, 1'b0, 3'd4, F_T,  F_T,  F_DX, F_DX);
            6'd11: ent = mono(1'b0, 1'b0, 3'd2, F_CX, F_CX, F_1,  F_1);
            6'd12: ent = mono(1'b0, 1'b0, 3'd2, F_OX, F_OX, F_1,  F_1);
            6'd13: ent = mono(1'b1, 1'b1, 3'd3, F_T,  F_DX, F_CX, F_1);
            6'd14: ent = mono(1'b0, 1'b1, 3'd3, F_T,  F_DX, F_OX, F_1);
            6'd15: ent = mono(1'b1, 1'b1, 3'd2, F_CX, F_OX, F_1,  F_1);
            6'd16: ent = mono(1'b0, 1'b0, 3'd4, F_T,  F_T,  F_DY, F_DY);
            6'd17: ent = mono(1'b0, 1'b0, 3'd2, F_CY, F_CY, F_1,  F_1);
            6'd18: ent = mono(1'b0, 1'b0, 3'd2, F_OY, F_OY, F_1,  F_1);
            6'd19: ent = mono(1'b1, 1'b1, 3'd3, F_T,  F_DY, F_CY, F_1);
            6'd20: ent = mono(1'b0, 1'b1, 3'd3, F_T,  F_DY, F_OY, F_1);
            6'd21: ent = mono(1'b1, 1'b1, 3'd2, F_CY, F_OY, F_1,  F_1);
            6'd22: ent = mono(1'b0, 1'b0, 3'd4, F_T,  F_T,  F_DZ, F_DZ);
            6'd23: ent = mono(1'b0, 1'b0, 3'd2, F_CZ, F_CZ, F_1,  F_1);
            6'd24: ent = mono(1'b0, 1'b0, 3'd2, F_OZ, F_OZ, F_1,  F_1);
            6'd25: ent = mono(1'b1, 1'b1, 3'd3, F_T,  F_DZ, F_CZ, F_1);
            6'd26: ent = mono(1'b0, 1'b1, 3'd3, F_T,  F_DZ, F_OZ, F_1);
            6'd27: ent = mono(1'b1, 1'b1, 3'd2, F_CZ, F_OZ, F_1,  F_1);
            6'd28: ent = mono(1'b1, 1'b0, 3'd2, F_R,  F_R,  F_1,  F_1);
            6'd29: ent = M_END;
            // D = |w x d|^2 - r^2 A; component (j, k) = (y, z)
            6'd30: ent = mono(1'b0, 1'b0, 3'd4, F_CY, F_CY, F_DZ, F_DZ);
            6'd31: ent = mono(1'b0, 1'b0, 3'd4, F_OY, F_OY, F_DZ, F_DZ);
            6'd32: ent = mono(1'b0, 1'b0, 3'd4, F_CZ, F_CZ, F_DY, F_DY);
            6'd33: ent = mono(1'b0, 1'b0, 3'd4, F_OZ, F_OZ, F_DY, F_DY);
            6'd34: ent = mono(1'b1, 1'b1, 3'd4, F_CY, F_OY, F_DZ, F_DZ);
            6'd35: ent = mono(1'b1, 1'b1, 3'd4, F_CY, F_CZ, F_DY, F_DZ);
            6'd36: ent = mono(1'b0, 1'b1, 3'd4, F_CY, F_OZ, F_DY, F_DZ);
            6'd37: ent = mono(1'b0, 1'b1, 3'd4, F_OY, F_CZ, F_DY, F_DZ);
            6'd38: ent = mono(1'b1, 1'b1, 3'd4, F_OY, F_OZ, F_DY, F_DZ);
            6'd39: ent = mono(1'b1, 1'b1, 3'd4, F_CZ, F_OZ, F_DY, F_DY);
            // (j, k) = (z, x)
            6'd40: ent = mono(1'b0, 1'b0, 3'd4, F_CZ, F_CZ, F_DX, F_DX);
            6'd41: ent = mono(1'b0, 1'b0, 3'd4, F_OZ, F_OZ, F_DX, F_DX);
            6'd42: ent = mono(1'b0, 1'b0, 3'd4, F_CX, F_CX, F_DZ, F_DZ);
            6'd43: ent = mono(1'b0, 1'b0, 3'd4, F_OX, F_OX, F_DZ, F_DZ);
            6'd44: ent = mono(1'b1, 1'b1, 3'd4, F_CZ, F_OZ, F_DX, F_DX);
            6'd45: ent = mono(1'b1, 1'b1, 3'd4, F_CZ, F_CX, F_DZ, F_DX);
            6'd46: ent = mono(1'b0, 1'b1, 3'd4, F_CZ, F_OX, F_DZ, F_DX);
            6'd47: ent = mono(1'b0, 1'b1, 3'd4, F_OZ, F_CX, F_DZ, F_DX);
            6'd48: ent = mono(1'b1, 1'b1, 3'd4, F_OZ, F_OX, F_DZ, F_DX);
            6'd49: ent = mono(1'b1, 1'b1, 3'd4, F_CX, F_OX, F_DZ, F_DZ);
            // (j, k) = (x, y)
            6'd50: ent = mono(1'b0, 1'b0, 3'd4, F_CX, F_CX, F_DY, F_DY);
            6'd51: ent = mono(1'b0, 1'b0, 3'd4, F_OX, F_OX, F_DY, F_DY);
            6'd52: ent = mono(1'b0, 1'b0, 3'd4, F_CY, F_CY, F_DX, F_DX);
            6'd53: ent = mono(1'b0, 1'b0, 3'd4, F_OY, F_OY, F_DX, F_DX);
            6'd54: ent = mono(1'b1, 1'b1, 3'd4, F_CX, F_OX, F_DY, F_DY);
            6'd55: ent = mono(1'b1, 1'b1, 3'd4, F_CX, F_CY, F_DX, F_DY);
            6'd56: ent = mono(1'b0, 1'b1, 3'd4, F_CX, F_OY, F_DX, F_DY);
            6'd57: ent = mono(1'b0, 1'b1, 3'd4, F_OX, F_CY, F_DX, F_DY);
            6'd58: ent = mono(1'b1, 1'b1, 3'd4, F_OX, F_OY, F_DX, F_DY);
            6'd59: ent = mono(1'b1, 1'b1, 3'd4, F_CY, F_OY, F_DX, F_DX);
            // - r^2 A
            6'd60: ent = mono(1'b1, 1'b0, 3'd4, F_R,  F_R,  F_DX, F_DX);
            6'd61: ent = mono(1'b1, 1'b0, 3'd4, F_R,  F_R,  F_DY, F_DY);
            6'd62: ent = mono(1'b1, 1'b0, 3'd4, F_R,  F_R,  F_DZ, F_DZ);
            default: ent = M_END;
        endcase
    end
    wire       e_end = ent[21];
    wire       e_neg = ent[20];
    wire       e_two = ent[19];
    wire [2:0] e_k   = ent[18:16];
    wire [3:0] e_f1 = ent[15:12], e_f2 = ent[11:8], e_f3 = ent[7:4], e_f4 = ent[3:0];
    wire       e_zero = zmask[e_f1] | zmask[e_f2] | zmask[e_f3] | zmask[e_f4];

    // -------------------------------------------------- sequencer and datapath
    localparam [3:0] S_IDLE = 4'd0, S_INIT = 4'd1, S_FETCH = 4'd2, S_MUL = 4'd3,
                     S_ACC0 = 4'd4, S_ACC = 4'd5, S_SIGN0 = 4'd6, S_SIGN1 = 4'd7;
    localparam [1:0] PH_Q0 = 2'd0, PH_Q1 = 2'd1, PH_E = 2'd2, PH_D = 2'd3;
    reg [3:0]  state;
    reg [1:0]  phase;
    reg        negate;      // negate every monomial (-Q(tmax))
    reg        fill;        // value of unwritten accumulator words: 0 or all ones
    reg [1:0]  j;           // factor slot being multiplied in
    reg [1:0]  i;           // word of the product
    reg [1:0]  len;         // words of the product so far (1..3)
    reg [31:0] p0, p1, p2;  // product magnitude, < 2^96
    reg [23:0] mcy;         // multiplier carry between words
    reg [9:0]  s;           // bit position of the monomial in the accumulator
    reg        neg;         // sign of the monomial
    reg [5:0]  aw;          // accumulator word being updated
    reg [1:0]  kk;          // product word feeding it (3: none left)
    reg [31:0] spill;       // bits of the previous product word shifted past its word
    reg        acy;         // accumulator carry between words

    assign busy = (state != S_IDLE);

    // factor of slot j (MUL)
    reg [3:0] fid;
    always @* begin
        case (j)
            2'd0:    fid = e_f1;
            2'd1:    fid = e_f2;
            2'd2:    fid = e_f3;
            default: fid = e_f4;
        endcase
    end
    reg [31:0] fv;          // the binary32 behind factor fid
    always @* begin
        case (fid)
            F_OX: fv = ox;   F_OY: fv = oy;   F_OZ: fv = oz;
            F_CX: fv = cx;   F_CY: fv = cy;   F_CZ: fv = cz;
            F_DX: fv = dx;   F_DY: fv = dy;   F_DZ: fv = dz;
            F_T:  fv = tsel ? tmax : tmin;
            default: fv = r;    // F_R (F_1 is never multiplied in)
        endcase
    end
    wire [23:0] fsig = {|fv[30:23], fv[22:0]};
    wire [9:0]  fpos = (fv[30:23] == 8'd0) ? 10'd0 : ({2'd0, fv[30:23]} - 10'd1);
    wire        fsgn = fv[31];

    // 32 x 24 multiplier: word i of the product times the factor, plus carry
    reg [31:0] pw;
    always @* begin
        case (i)
            2'd0:    pw = p0;
            2'd1:    pw = p1;
            default: pw = p2;
        endcase
    end
    wire [55:0] mprod = pw * fsig + {32'd0, mcy};

    // s of a monomial before its factors: 149 per missing factor, +1 for kappa = 2
    reg [9:0] s_init;
    always @* begin
        case (e_k)
            3'd2:    s_init = 10'd298;
            3'd3:    s_init = 10'd149;
            default: s_init = 10'd0;
        endcase
    end

    // ---------------------------------------------------------- accumulator
    // 64 x 32 RAM, synchronous read (acc_rd is the word addressed in the
    // previous cycle), one write port; acc_ok marks the words written since the
    // last clear, the others read as fill
    reg  [31:0] acc_mem [0:63];
    reg  [31:0] acc_rd;
    reg         acc_rdok;
    reg  [63:0] acc_ok;
    reg  [5:0]  acc_ra;
    wire        acc_we = (state == S_ACC);
    wire [31:0] acc_wd;
    always @(posedge clk) begin
        if (acc_we)
            acc_mem[aw] <= acc_wd;
        acc_rd <= acc_mem[acc_ra];
    end
    wire [31:0] acc_v = acc_rdok ? acc_rd : {32{fill}};

    always @* begin
        case (state)
            S_ACC0:  acc_ra = {1'b0, s[9:5]};
            S_ACC:   acc_ra = aw + 6'd1;
            default: acc_ra = 6'd34;    // S_SIGN0: the top word
        endcase
    end

    // addend word: product word kk shifted left by s mod 32, plus the spill of
    // the word below; negative monomials are added as ~magnitude + 1
    reg [31:0] pk;
    always @* begin
        case (kk)
            2'd0:    pk = p0;
            2'd1:    pk = p1;
            2'd2:    pk = p2;
            default: pk = 32'd0;
        endcase
    end
    wire [63:0] px      = {32'd0, pk} << s[4:0];
    wire [31:0] add_m   = px[31:0] | spill;
    wire [31:0] add_b   = neg ? ~add_m : add_m;
    wire [32:0] add_s   = {1'b0, acc_v} + {1'b0, add_b} + {32'd0, acy};
    assign      acc_wd  = add_s[31:0];
    wire        hi_zero = (kk == 2'd0) ? ((p1 == 32'd0) && (p2 == 32'd0)) :
                          (kk == 2'd1) ? (p2 == 32'd0) : 1'b1;
    // the words above add only the sign extension and the carry: neutral when
    // the carry equals the sign (0 + 0 + 0, or ~0 + ~0... + 1)
    wire        acc_last = (hi_zero && (px[63:32] == 32'd0) && (add_s[32] == neg)) || (aw == 6'd34);

    // ------------------------------------------------------------- control
    // start phase: accumulator clear value, T, negation
    task begin_phase;
        input [1:0] ph;
        input       ts;
        begin
            phase  <= ph;
            tsel   <= ts;
            negate <= (ph == PH_Q1);
            fill   <= (ph == PH_E) || (ph == PH_D);
            j      <= 2'd0;
            pc     <= (ph == PH_E) ? PC_E : (ph == PH_D) ? PC_D : PC_Q;
            state  <= S_INIT;
        end
    endtask

    always @(posedge clk) begin
        done <= 1'b0;
        if (rst) begin
            state  <= S_IDLE;
            hit    <= 1'b0;
            status <= 8'd0;
            acc_ok <= 64'd0;
            acc_rdok <= 1'b0;
        end else begin
            acc_rdok <= acc_ok[acc_ra];
            case (state)
                S_IDLE: if (start) begin
                    status <= st_all;
                    hit    <= 1'b0;
                    if (st_all != 8'd0 || empty_seg)
                        done <= 1'b1;           // reject or empty segment: miss
                    else
                        begin_phase(PH_Q0, 1'b0);
                end
                S_INIT: begin
                    acc_ok <= 64'd0;
                    state  <= S_FETCH;
                end
                S_FETCH: begin
                    if (e_end) begin
                        state <= S_SIGN0;
                    end else if (e_zero) begin
                        pc <= pc + 6'd1;
                    end else begin
                        // slot 0 loads the product; the others multiply it
                        // (j = 0 here: fv is slot 0)
                        p0    <= {8'd0, fsig};
                        p1    <= 32'd0;
                        p2    <= 32'd0;
                        len   <= 2'd1;
                        s     <= s_init + fpos + {9'd0, e_two};
                        neg   <= e_neg ^ fsgn ^ negate;
                        j     <= 2'd1;
                        i     <= 2'd0;
                        mcy   <= 24'd0;
                        state <= S_MUL;
                    end
                end
                S_MUL: begin
                    case (i)
                        2'd0:    p0 <= mprod[31:0];
                        2'd1:    p1 <= mprod[31:0];
                        default: p2 <= mprod[31:0];
                    endcase
                    if (i == 2'd0) begin
                        s   <= s + fpos;
                        neg <= neg ^ fsgn;
                    end
                    if (i == len - 2'd1) begin
                        // the carry out becomes the next word (zero past 96 bits)
                        case (len)
                            2'd1:    p1 <= {8'd0, mprod[55:32]};
                            2'd2:    p2 <= {8'd0, mprod[55:32]};
                            default: ;
                        endcase
                        if (len != 2'd3)
                            len <= len + 2'd1;
                        i   <= 2'd0;
                        mcy <= 24'd0;
                        j   <= j + 2'd1;
                        if ({1'b0, j} + 3'd1 == e_k)
                            state <= S_ACC0;
                    end else begin
                        i   <= i + 2'd1;
                        mcy <= mprod[55:32];
                    end
                end
                S_ACC0: begin
                    aw    <= {1'b0, s[9:5]};
                    kk    <= 2'd0;
                    spill <= 32'd0;
                    acy   <= neg;
                    state <= S_ACC;
                end
                S_ACC: begin
                    acc_ok[aw] <= 1'b1;
                    if (acc_last) begin
                        pc    <= pc + 6'd1;
                        j     <= 2'd0;
                        state <= S_FETCH;
                    end else begin
                        aw    <= aw + 6'd1;
                        if (kk != 2'd3)
                            kk <= kk + 2'd1;
                        spill <= px[63:32];
                        acy   <= add_s[32];
                    end
                end
                S_SIGN0: state <= S_SIGN1;
                S_SIGN1: begin
                    // acc_v is the top word: its bit 31 is the sign of the sum
                    case (phase)
                        PH_Q0:
                            if (acc_v[31])              // t* < tmin
                                begin_phase(PH_E, 1'b0);
                            else if (!tmax_inf)
                                begin_phase(PH_Q1, 1'b1);
                            else
                                begin_phase(PH_D, 1'b0);
                        PH_Q1:
                            if (acc_v[31])              // t* > tmax
                                begin_phase(PH_E, 1'b1);
                            else
                                begin_phase(PH_D, 1'b0);
                        default: begin                  // E or D: hit iff <= 0
                            hit   <= acc_v[31];
                            done  <= 1'b1;
                            state <= S_IDLE;
                        end
                    endcase
                end
                default: state <= S_IDLE;
            endcase
        end
    end

endmodule
