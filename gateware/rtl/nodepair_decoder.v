// cbvh unit 4 (decode direction): node-pair decoder (docs/datapath.md §9, §10).
// Purely combinational: field extraction, the format checks and six axis
// decoders (cbvh_axis_decoder, unit 3), one per child and axis, each with the
// node's context of its axis.
//
// Independent implementation from the written spec. Node layout (W = 64 for
// N <= 6, 96 for N >= 7; P = min(32, W - 6N - 1)), LSB = bit 0 of byte 0:
//   [2aN, 2aN+N) lower code of axis a, [2aN+N, 2aN+2N) upper code,
//   6N leaf, [6N+1, 6N+1+P) pointer, above: reserved (must be zero).
// The pair is node 0 then node 1, little-endian; on the wire W/16 32-bit words
// (word0 = bytes 0..3). word4/word5 exist only for N >= 7.
//
// Decisions where §9 is not explicit (checked against the golden vectors where
// they pin them):
//   * "empty" = leaf = 1 and pointer = 2^P - 1, whatever the codes. An empty
//     marker with non-zero codes is BAD_FORMAT and its codes are not decoded:
//     its axis units' INVERTED is not reported (pinned by the all-ones pairs).
//     Reserved bits set do not stop a non-empty child from being decoded: its
//     INVERTED is reported with BAD_FORMAT (pinned: status 0x22).
//   * the node's context is checked first, even when both children are empty,
//     as §9's "both directions reject the same contexts" suggests; a rejected
//     context gives its bits alone (§9 now says so, and generator 3 pins it:
//     the model had no such check until this implementation showed the gap).
//   * c*_flags = {empty, leaf}; an empty child outputs flags 3, its pointer
//     2^P - 1 and zero codes, scales and bounds.
//   * otherwise status = BAD_FORMAT (bit 5) OR the six axis units' statuses;
//     with any reject bit every other output is zero.

// The file name is fixed by the project layout (nodepair_decoder.v).
/* verilator lint_off DECLFILENAME */
module cbvh_nodepair_decoder #(
    parameter integer N      = 6,
    parameter integer E_MIN  = -30,
    parameter integer MODULO = 1
) (
    input  wire [7:0]   x_parent_scale,
    input  wire [7:0]   x_scale,
    input  wire [11:0]  x_node_lb_mod,
    input  wire [31:0]  x_node_clb,
    input  wire [7:0]   y_parent_scale,
    input  wire [7:0]   y_scale,
    input  wire [11:0]  y_node_lb_mod,
    input  wire [31:0]  y_node_clb,
    input  wire [7:0]   z_parent_scale,
    input  wire [7:0]   z_scale,
    input  wire [11:0]  z_node_lb_mod,
    input  wire [31:0]  z_node_clb,
    input  wire [31:0]  word0,
    input  wire [31:0]  word1,
    input  wire [31:0]  word2,
    input  wire [31:0]  word3,
    input  wire [31:0]  word4,     // N >= 7 only (ignored for N <= 6)
    input  wire [31:0]  word5,     // N >= 7 only (ignored for N <= 6)
    output wire [1:0]   c0_flags,  // {empty, leaf}
    output wire [31:0]  c0_ptr,
    output wire [N-1:0] c0_x_lb_mod,
    output wire [N-1:0] c0_x_ub_mod,
    output wire [7:0]   c0_x_child_scale,
    output wire [31:0]  c0_x_clb,
    output wire [31:0]  c0_x_cub,
    output wire [N-1:0] c0_y_lb_mod,
    output wire [N-1:0] c0_y_ub_mod,
    output wire [7:0]   c0_y_child_scale,
    output wire [31:0]  c0_y_clb,
    output wire [31:0]  c0_y_cub,
    output wire [N-1:0] c0_z_lb_mod,
    output wire [N-1:0] c0_z_ub_mod,
    output wire [7:0]   c0_z_child_scale,
    output wire [31:0]  c0_z_clb,
    output wire [31:0]  c0_z_cub,
    output wire [1:0]   c1_flags,
    output wire [31:0]  c1_ptr,
    output wire [N-1:0] c1_x_lb_mod,
    output wire [N-1:0] c1_x_ub_mod,
    output wire [7:0]   c1_x_child_scale,
    output wire [31:0]  c1_x_clb,
    output wire [31:0]  c1_x_cub,
    output wire [N-1:0] c1_y_lb_mod,
    output wire [N-1:0] c1_y_ub_mod,
    output wire [7:0]   c1_y_child_scale,
    output wire [31:0]  c1_y_clb,
    output wire [31:0]  c1_y_cub,
    output wire [N-1:0] c1_z_lb_mod,
    output wire [N-1:0] c1_z_ub_mod,
    output wire [7:0]   c1_z_child_scale,
    output wire [31:0]  c1_z_clb,
    output wire [31:0]  c1_z_cub,
    output wire [6:0]   status
);
    localparam integer W      = (N <= 6) ? 64 : 96;     // node bits
    localparam integer P      = (W - 6 * N - 1 < 32) ? (W - 6 * N - 1) : 32;
    localparam integer LEAF   = 6 * N;                   // leaf bit
    localparam integer PTR_LO = 6 * N + 1;               // pointer lsb
    localparam integer RES_LO = 6 * N + 1 + P;           // first reserved bit (may be W)

    // The pair as one vector; node c is bits [cW, cW + W).
    wire [191:0] pair = {word5, word4, word3, word2, word1, word0};
    generate
        if (W == 64) begin : g_w64
            // word4/word5 are not part of a 16-byte pair (N <= 6)
            wire unused_words = ^pair[191:128];
        end
    endgenerate

    // per-axis context, axis a at [8a +: 8], [12a +: 12], [32a +: 32]
    wire [23:0] ctx_ps  = {z_parent_scale, y_parent_scale, x_parent_scale};
    wire [23:0] ctx_sc  = {z_scale, y_scale, x_scale};
    wire [35:0] ctx_nlm = {z_node_lb_mod, y_node_lb_mod, x_node_lb_mod};
    wire [95:0] ctx_clb = {z_node_clb, y_node_clb, x_node_clb};

    // -------------------------------------------------- fields and formats
    wire [1:0]  leaf, empty, fmt_bad;
    wire [63:0] ptr;                     // child c at [32c +: 32]
    // axis unit outputs, unit i = 3c + a
    wire [6*N-1:0] d_lbm, d_ubm;         // [N*i +: N]
    wire [47:0]    d_cs;                 // [8*i +: 8]
    wire [191:0]   d_clb, d_cub;         // [32*i +: 32]
    wire [41:0]    d_st;                 // [7*i +: 7]

    genvar c, a;
    generate
        for (c = 0; c < 2; c = c + 1) begin : g_child
            wire [W-1:0]   nd        = pair[c*W +: W];
            wire [6*N-1:0] codes     = nd[6*N-1:0];
            wire [P-1:0]   pfield    = nd[PTR_LO +: P];       // PTR_LO + P <= W
            wire [W-1:0]   above_ptr = nd >> RES_LO;          // reserved bits (0 if none)
            assign leaf[c]  = nd[LEAF];
            assign empty[c] = leaf[c] & (&pfield);            // pointer = 2^P - 1
            if (P < 32) begin : g_ptr_ext
                assign ptr[32*c +: 32] = {{(32 - P){1'b0}}, pfield};
            end else begin : g_ptr_full
                assign ptr[32*c +: 32] = pfield;
            end
            // reserved bits set, or an empty marker with non-zero codes
            assign fmt_bad[c] = (|above_ptr) | (empty[c] & (|codes));

            for (a = 0; a < 3; a = a + 1) begin : g_axis
                cbvh_axis_decoder #(.N(N), .E_MIN(E_MIN), .MODULO(MODULO)) u_axis (
                    .parent_scale(ctx_ps[8*a +: 8]), .scale(ctx_sc[8*a +: 8]),
                    .node_lb_mod(ctx_nlm[12*a +: 12]), .node_clb(ctx_clb[32*a +: 32]),
                    .lb_code({{(12 - N){1'b0}}, codes[2*a*N +: N]}),
                    .ub_code({{(12 - N){1'b0}}, codes[2*a*N + N +: N]}),
                    .lb_mod(d_lbm[N*(3*c + a) +: N]), .ub_mod(d_ubm[N*(3*c + a) +: N]),
                    .child_scale(d_cs[8*(3*c + a) +: 8]),
                    .clb(d_clb[32*(3*c + a) +: 32]), .cub(d_cub[32*(3*c + a) +: 32]),
                    .status(d_st[7*(3*c + a) +: 7]));
            end
        end
    endgenerate

    // ----------------------------------------------------------------- status
    // An empty child is not decoded: its axis units' INVERTED (zero codes) is
    // dropped, their context faults (BAD_PARAM, BAD_SCALE, BAD_CODE of
    // node_lb_mod, NAN_INF) are kept. Child codes are N bits here, so BAD_CODE
    // from an axis unit always means the context's node_lb_mod.
    localparam [6:0] INV = 7'h02;
    wire [6:0] m0 = empty[0] ? ~INV : 7'h7F;
    wire [6:0] m1 = empty[1] ? ~INV : 7'h7F;
    wire [6:0] ax_st = ((d_st[6:0] | d_st[13:7] | d_st[20:14]) & m0) |
                       ((d_st[27:21] | d_st[34:28] | d_st[41:35]) & m1);
    wire bad_format = |fmt_bad;
    // §9: the context is checked first, as on encode; a rejected context gives
    // its bits alone. Child 0's three axis units see the three contexts, and
    // their NAN_INF, BAD_SCALE, BAD_PARAM and BAD_CODE (child codes are N bits
    // here) can only come from the context.
    localparam [6:0] CTX = 7'h1D;
    wire [6:0] ctx_st = (d_st[6:0] | d_st[13:7] | d_st[20:14]) & CTX;
    assign status = (|ctx_st) ? ctx_st : (ax_st | {1'b0, bad_format, 5'd0});
    wire reject = |status[5:0];                      // bit 6 (NO_FIT) is not a reject

    // ---------------------------------------------------------------- outputs
    // zero on a reject; an empty child: flags 3, pointer 2^P - 1, zero bounds
    wire k0 = ~reject & ~empty[0];
    wire k1 = ~reject & ~empty[1];
    wire [6*N-1:0] knn = {{(3*N){k1}}, {(3*N){k0}}};
    wire [47:0]    k8  = {{24{k1}}, {24{k0}}};
    wire [191:0]   k32 = {{96{k1}}, {96{k0}}};
    wire [6*N-1:0] o_lbm = d_lbm & knn;
    wire [6*N-1:0] o_ubm = d_ubm & knn;
    wire [47:0]    o_cs  = d_cs & k8;
    wire [191:0]   o_clb = d_clb & k32;
    wire [191:0]   o_cub = d_cub & k32;

    assign c0_flags = reject ? 2'b00 : {empty[0], leaf[0]};
    assign c0_ptr   = reject ? 32'd0 : ptr[31:0];
    assign c1_flags = reject ? 2'b00 : {empty[1], leaf[1]};
    assign c1_ptr   = reject ? 32'd0 : ptr[63:32];

    assign c0_x_lb_mod = o_lbm[N*0 +: N]; assign c0_x_ub_mod = o_ubm[N*0 +: N];
    assign c0_y_lb_mod = o_lbm[N*1 +: N]; assign c0_y_ub_mod = o_ubm[N*1 +: N];
    assign c0_z_lb_mod = o_lbm[N*2 +: N]; assign c0_z_ub_mod = o_ubm[N*2 +: N];
    assign c1_x_lb_mod = o_lbm[N*3 +: N]; assign c1_x_ub_mod = o_ubm[N*3 +: N];
    assign c1_y_lb_mod = o_lbm[N*4 +: N]; assign c1_y_ub_mod = o_ubm[N*4 +: N];
    assign c1_z_lb_mod = o_lbm[N*5 +: N]; assign c1_z_ub_mod = o_ubm[N*5 +: N];

    assign c0_x_child_scale = o_cs[7:0];   assign c0_y_child_scale = o_cs[15:8];
    assign c0_z_child_scale = o_cs[23:16]; assign c1_x_child_scale = o_cs[31:24];
    assign c1_y_child_scale = o_cs[39:32]; assign c1_z_child_scale = o_cs[47:40];

    assign c0_x_clb = o_clb[31:0];    assign c0_x_cub = o_cub[31:0];
    assign c0_y_clb = o_clb[63:32];   assign c0_y_cub = o_cub[63:32];
    assign c0_z_clb = o_clb[95:64];   assign c0_z_cub = o_cub[95:64];
    assign c1_x_clb = o_clb[127:96];  assign c1_x_cub = o_cub[127:96];
    assign c1_y_clb = o_clb[159:128]; assign c1_y_cub = o_cub[159:128];
    assign c1_z_clb = o_clb[191:160]; assign c1_z_cub = o_cub[191:160];
endmodule
