// cbvh unit 8: QBVH stack entry (docs/qbvh.md §1-§2), combinational.
//
// Entry:  bit 31..30 o2 | 29..28 o1 | 27..26 o0 | 25..0 first-child ID.
//
// op = 0, sort + push:
//   Sort the four children on the key (missed, t, index) with the paper's
//   5-comparator network, pairs (0,1) (2,3) | (0,2) (1,3) | (1,2). t is a
//   binary32 bit pattern ordered as a value (-0 = +0, +-Inf allowed); a missed
//   child's t never reaches a decision (two missed lanes compare by index,
//   a hit lane always precedes a missed one), so NaN/Inf there do not matter.
//   The key is a total order, so the network gives the unique sorted order.
//   node = first + order[0] (0 if nothing hit); nhit >= 2: write = 1 and
//   next_entry = first | o0 << 26 | o1 << 28 | o2 << 30 with o0 = order[1],
//   o1 = order[2] or o0, o2 = order[3] or o1 (a repeat marks the end).
// op = 1, pop:
//   id = entry[25:0], o = entry[27:26], m = entry[31:28]; node = id + o
//   (27 bits, no wrap); write = (m[1:0] != o); next_entry = offsets
//   (o1, o2, o2) when write, else 0 (errata Q3, Q4: unsigned, o2 copied).
//   The push inputs (first, hit_mask, t0..t3) are ignored.
//
// Status (datapath.md §10 bit numbers): bit 3 BAD_PARAM (op > 1), bit 4
// BAD_CODE (push: first >= 2^26, checked for every hit count), bit 0 NAN_INF
// (push: the t of a hit child is NaN). One bit per input, checked in the
// order BAD_PARAM, NAN_INF, BAD_CODE (qbvh.md §2); any reject zeroes every other output,
// order included. hit_mask is 4 bits on the wire, so "hit_mask > 15" cannot
// occur at this port. Nothing depends on N or e_min: no parameters.
//
// The file name is fixed by the gateware layout, the module name by the cbvh_ prefix.
/* verilator lint_off DECLFILENAME */
module cbvh_qbvh_stack (
    input  wire [3:0]  op,          // 0 = sort + push, 1 = pop
    input  wire [31:0] first,       // push: first-child ID of the sibling group
    input  wire [3:0]  hit_mask,    // push: bit c = child c hit
    input  wire [31:0] t0,          // push: binary32 hit times
    input  wire [31:0] t1,
    input  wire [31:0] t2,
    input  wire [31:0] t3,
    input  wire [31:0] entry,       // pop: top-of-stack entry
    output wire [31:0] node,
    output wire [31:0] next_entry,
    output wire        write,
    output wire [7:0]  order,       // sorted child indices, nearest in bits 1..0
    output wire [3:0]  nhit,
    output wire [7:0]  status
);

    // ---------------------------------------------------------------- key order
    // Lane = {missed, t[31:0], index[1:0]} (35 bits).
    // t_lt / t_eq: binary32 value order on non-NaN patterns, -0 = +0.
    function t_lt;
        input [31:0] a;
        input [31:0] b;
        reg          mag_lt, both_zero;
        begin
            mag_lt    = a[30:0] < b[30:0];
            both_zero = (a[30:0] == 31'd0) && (b[30:0] == 31'd0);
            case ({a[31], b[31]})
                2'b00:   t_lt = mag_lt;                              // both >= +0
                2'b11:   t_lt = ~mag_lt && (a[30:0] != b[30:0]);      // both <= -0
                2'b10:   t_lt = ~both_zero;                          // a neg, b pos
                default: t_lt = 1'b0;                                // a pos, b neg
            endcase
        end
    endfunction

    function t_eq;
        input [31:0] a;
        input [31:0] b;
        begin
            t_eq = (a[30:0] == b[30:0]) && ((a[31] == b[31]) || (a[30:0] == 31'd0));
        end
    endfunction

    // key(a) > key(b): the comparator must swap the two lanes.
    function after;
        input [34:0] a;
        input [34:0] b;
        reg          ma, mb;
        begin
            ma = a[34];
            mb = b[34];
            if (ma != mb)
                after = ma;                                  // missed after hit
            else if (ma)
                after = a[1:0] > b[1:0];                     // both missed: index
            else
                after = t_lt(b[33:2], a[33:2]) ||
                        (t_eq(a[33:2], b[33:2]) && (a[1:0] > b[1:0]));
        end
    endfunction

    // ---------------------------------------------------------------- network
    wire [34:0] l0 = {~hit_mask[0], t0, 2'd0};
    wire [34:0] l1 = {~hit_mask[1], t1, 2'd1};
    wire [34:0] l2 = {~hit_mask[2], t2, 2'd2};
    wire [34:0] l3 = {~hit_mask[3], t3, 2'd3};

    // stage 1: (0,1), (2,3)
    wire        s01 = after(l0, l1);
    wire        s23 = after(l2, l3);
    wire [34:0] a0  = s01 ? l1 : l0;
    wire [34:0] a1  = s01 ? l0 : l1;
    wire [34:0] a2  = s23 ? l3 : l2;
    wire [34:0] a3  = s23 ? l2 : l3;
    // stage 2: (0,2), (1,3)
    wire        s02 = after(a0, a2);
    wire        s13 = after(a1, a3);
    wire [34:0] b2  = s02 ? a0 : a2;
    wire [34:0] b1  = s13 ? a3 : a1;
    // lanes 0 and 3 are final after stage 2: only their indices are kept
    wire [1:0]  ord0 = s02 ? a2[1:0] : a0[1:0];
    wire [1:0]  ord3 = s13 ? a1[1:0] : a3[1:0];
    // stage 3: (1,2)
    wire        s12 = after(b1, b2);
    wire [1:0]  ord1 = s12 ? b2[1:0] : b1[1:0];
    wire [1:0]  ord2 = s12 ? b1[1:0] : b2[1:0];

    // ---------------------------------------------------------------- push
    wire [2:0] cnt = {2'd0, hit_mask[0]} + {2'd0, hit_mask[1]} +
                     {2'd0, hit_mask[2]} + {2'd0, hit_mask[3]};
    wire       ge1 = |hit_mask;
    wire       ge2 = (cnt >= 3'd2);
    wire       ge3 = (cnt >= 3'd3);
    wire       all = &hit_mask;

    wire [1:0]  po0 = ord1;
    wire [1:0]  po1 = ge3 ? ord2 : po0;
    wire [1:0]  po2 = all ? ord3 : po1;
    wire [26:0] push_node  = ge1 ? ({1'b0, first[25:0]} + {25'd0, ord0}) : 27'd0;
    wire [31:0] push_entry = ge2 ? {po2, po1, po0, first[25:0]} : 32'd0;

    // ---------------------------------------------------------------- pop
    wire [25:0] id  = entry[25:0];
    wire [1:0]  o   = entry[27:26];
    wire [3:0]  m   = entry[31:28];
    wire        pop_write  = (m[1:0] != o);
    wire [26:0] pop_node   = {1'b0, id} + {25'd0, o};
    wire [31:0] pop_entry  = pop_write ? {m[3:2], m[3:2], m[1:0], id} : 32'd0;

    // ---------------------------------------------------------------- status
    function is_nan;                            // sign bit irrelevant
        input [30:0] x;
        begin
            is_nan = (&x[30:23]) && (x[22:0] != 23'd0);
        end
    endfunction

    wire is_push   = (op == 4'd0);
    wire is_pop    = (op == 4'd1);
    wire bad_param = ~is_push && ~is_pop;
    wire bad_code  = is_push && (first[31:26] != 6'd0);
    wire nan_inf   = is_push && ((hit_mask[0] && is_nan(t0[30:0])) || (hit_mask[1] && is_nan(t1[30:0])) ||
                                 (hit_mask[2] && is_nan(t2[30:0])) || (hit_mask[3] && is_nan(t3[30:0])));
    wire reject    = bad_param || bad_code || nan_inf;

    // one bit, in the order of qbvh.md section 2: the sort's NaN check comes
    // before the push's ID check
    assign status = bad_param ? 8'h08 :
                    nan_inf   ? 8'h01 :
                    bad_code  ? 8'h10 : 8'h00;

    wire ok_push = is_push && ~reject;
    wire ok_pop  = is_pop;                      // a pop never rejects

    assign node       = ok_push ? {5'd0, push_node}  : ok_pop ? {5'd0, pop_node} : 32'd0;
    assign next_entry = ok_push ? push_entry         : ok_pop ? pop_entry        : 32'd0;
    assign write      = ok_push ? ge2                : ok_pop ? pop_write        : 1'b0;
    assign order      = ok_push ? {ord3, ord2, ord1, ord0} : 8'd0;
    assign nhit       = ok_push ? {1'b0, cnt}        : 4'd0;

endmodule
