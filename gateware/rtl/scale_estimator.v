// cbvh unit 1: scale estimator (docs/datapath.md §5), combinational.
//
//   e = smallest integer >= e_min such that floor(q/2^e) + 1 - floor(p/2^e) <= 2^N
//
// Method (the "exponent of q - p" of §5, constant time, no wide integers):
//   1. Align p and q to the larger of their exponents, x, on the grid 2^(x-1),
//      truncating the smaller one with a sticky bit (as an FP adder does), and
//      form d = q - p in 27 bits. This gives d's sign, d = 0 and m = floor(log2 d)
//      exactly (argument below).
//   2. e0 = m + 1 - N. At e0 the box spans cells in (2^(N-1), 2^N + 1]; at e0 + 1
//      it always fits (<= 2^(N-1) + 1 cells). So e = max(e_min, e0 + nofit), or
//      e_min when d = 0 (one cell at every scale).
//   3. nofit <=> cells = 2^N + 1 <=> cells = 1 (mod 2^N) <=> floor(q/2^e0) and
//      floor(p/2^e0) agree in their low N bits. Both floors come out of the
//      aligned two's complement values by the same arithmetic shift.
//
// Why the sticky bit is exact enough: it is only set when the smaller operand
// moves down by >= 2 binades; then |d| > 2^(x+22). The truncated-plus-sticky
// value lies in the same open interval between multiples of 2^x as the true
// one (or equals the true one on a multiple), so every comparison against a
// multiple of 2^x (sign, powers 2^t >= 2^x, floors at 2^e0 >= 2^(x+13)) is exact.
// With 0 or 1 binade of difference nothing is truncated (exact cancellation).
//
// The file name is fixed by the gateware layout, the module name by the cbvh_ prefix.
/* verilator lint_off DECLFILENAME */
module cbvh_scale_estimator #(
    parameter integer N     = 6,    // quant_bits, 3..10
    parameter integer E_MIN = -30   // min_scale, -126..126
) (
    input  wire [31:0] lb,          // p (binary32 bit pattern)
    input  wire [31:0] ub,          // q
    output wire [7:0]  scale,       // e, two's complement
    output wire [6:0]  status       // §10
);

    // §10: N or e_min out of range is a reject (only reachable by a bad instance).
    localparam BAD_PARAM = (N < 3) || (N > 10) || (E_MIN < -126) || (E_MIN > 126);
    localparam [9:0] E_MIN10 = E_MIN[9:0];
    localparam [9:0] BIAS_N  = 10'd150 + N[9:0];   // exp = ef - 150; e0 = x + msb - N

    // ---------------------------------------------------------------- §2 break
    // value = (-1)^sign * sig * 2^(ef - 150); subnormals use ef = 1 (exp = -149).
    wire        p_norm = |lb[30:23];
    wire        q_norm = |ub[30:23];
    wire [23:0] p_sig  = {p_norm, lb[22:0]};
    wire [23:0] q_sig  = {q_norm, ub[22:0]};
    wire [7:0]  p_ef   = p_norm ? lb[30:23] : 8'd1;
    wire [7:0]  q_ef   = q_norm ? ub[30:23] : 8'd1;

    wire naninf = (&lb[30:23]) | (&ub[30:23]);

    // ---------------------------------------------------------------- 1. d = q - p
    wire [8:0] ediff = {1'b0, q_ef} - {1'b0, p_ef};      // two's complement
    wire       q_up  = ~ediff[8];                        // q_ef >= p_ef
    wire [7:0] x_ef  = q_up ? q_ef : p_ef;               // x = x_ef - 150
    wire [7:0] p_sh  = q_up ? ediff[7:0] : 8'd0;         // binades p moves down
    wire [7:0] q_sh  = q_up ? 8'd0 : (8'd0 - ediff[7:0]);

    // Lowest set bit of a significand (24 if zero).
    function [4:0] trailing_zeros24;
        input [23:0] v;
        integer i;
        begin
            trailing_zeros24 = 5'd24;
            for (i = 23; i >= 0; i = i - 1)
                if (v[i]) trailing_zeros24 = i[4:0];
        end
    endfunction

    // sig * 2^(ef - x + 1) in units of 2^(x-1): truncated, sticky ORed into the LSB.
    // Bits shifted out of {sig, 0} are non-zero iff its lowest set bit (tz + 1)
    // lies below the shift distance.
    function [24:0] align;
        input [23:0] sig;
        input [7:0]  sh;
        reg   [4:0]  sh_c;
        reg          sticky;
        begin
            sh_c   = (sh > 8'd25) ? 5'd25 : sh[4:0];          // 25 clears all of sig
            sticky = (|sig) && (({3'b000, trailing_zeros24(sig)} + 8'd1) < sh);
            align  = ({sig, 1'b0} >> sh_c) | {24'd0, sticky};
        end
    endfunction

    // Signed aligned values (|value| < 2^25) and their difference (|d| < 2^26).
    // -0 gives magnitude 0, so it is the value zero.
    wire [24:0] p_al = align(p_sig, p_sh);
    wire [24:0] q_al = align(q_sig, q_sh);
    wire [26:0] p_s  = lb[31] ? (27'd0 - {2'b00, p_al}) : {2'b00, p_al};
    wire [26:0] q_s  = ub[31] ? (27'd0 - {2'b00, q_al}) : {2'b00, q_al};
    wire [26:0] d    = q_s - p_s;

    wire d_neg  = d[26];            // q < p as values (lb > ub)
    wire d_zero = ~|d;              // p = q

    // Leading one of d (d > 0): m = (x - 1) + msb.
    function [4:0] msb26;
        input [25:0] v;
        integer i;
        begin
            msb26 = 5'd0;
            for (i = 0; i < 26; i = i + 1)
                if (v[i]) msb26 = i[4:0];
        end
    endfunction

    wire [4:0] msb = msb26(d[25:0]);

    // ---------------------------------------------------------------- 2. e0
    // e0 = m + 1 - N = (x_ef - 150) + msb - N, 10-bit two's complement.
    wire [9:0] e0 = {2'b00, x_ef} + {5'd0, msb} - BIAS_N;

    // ---------------------------------------------------------------- 3. fit at e0
    // 2^e0 = 2^(x-1) * 2^(msb - N + 1): the low N bits of floor(v / 2^e0) are
    // bits [msb - N + 1, msb] of v's aligned two's complement value (arithmetic
    // shift = floor, also for negative v). With N - 1 zeros appended that is
    // the window [msb, msb + N); it may start below bit 0 when d is tiny, but
    // then nothing was truncated and the zeros are exact.
    function [N-1:0] floor_lo;
        input [26:0] v;
        input [4:0]  pos;
        reg   [63:0] v_ext;                      // >= 26 + N bits; 64 keeps pos a plain 6-bit index
        begin
            v_ext    = {{(38-N){v[26]}}, v, {(N-1){1'b0}}};
            floor_lo = v_ext[{1'b0, pos} +: N];  // pos + N - 1 <= 25 + N - 1: in range
        end
    endfunction

    wire [N-1:0] k_lo  = floor_lo(p_s, msb);     // k = floor(p / 2^e0)
    wire [N-1:0] lm_lo = floor_lo(q_s, msb);     // l - 1 = floor(q / 2^e0)
    wire         nofit = (lm_lo == k_lo);        // cells = l - k = 2^N + 1

    // ---------------------------------------------------------------- result
    wire [9:0] e1     = e0 + {9'd0, nofit};
    wire       e1_low = $signed(e1) < $signed(E_MIN10);
    wire [7:0] e      = (d_zero | e1_low) ? E_MIN10[7:0] : e1[7:0];  // in [e_min, 126]

    wire inverted = ~naninf & d_neg;             // NaN/Inf reports only NAN_INF
    wire reject   = BAD_PARAM | naninf | inverted;

    assign scale  = reject ? 8'd0 : e;
    assign status = BAD_PARAM ? 7'b000_1000 : {5'd0, inverted, naninf};

endmodule
/* verilator lint_on DECLFILENAME */
