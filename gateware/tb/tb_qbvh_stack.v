// Testbench for cbvh_qbvh_stack: runs one golden vector file (docs/vectors.md).
//   iverilog -g2005 -P tb_qbvh_stack.N=6 -P tb_qbvh_stack.E_MIN=-30 ...
//   vvp sim +vec=vectors/qbvh_stack-N6-ms-30.vec
// The unit does not depend on N or e_min (docs/qbvh.md): the parameters are only
// checked against the file's header, as the runner passes them from it.
// No `timescale: the RTL has none either, so both use the simulator default unit.
module tb_qbvh_stack;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    reg  [3:0]  op, hit_mask;
    reg  [31:0] first, t0, t1, t2, t3, entry;
    wire [31:0] node, next_entry;
    wire        write;
    wire [7:0]  order;
    wire [3:0]  nhit;
    wire [7:0]  status;

    cbvh_qbvh_stack dut (
        .op(op), .first(first), .hit_mask(hit_mask),
        .t0(t0), .t1(t1), .t2(t2), .t3(t3), .entry(entry),
        .node(node), .next_entry(next_entry), .write(write),
        .order(order), .nhit(nhit), .status(status)
    );

    localparam [8*24-1:0] VF_TB = "tb_qbvh_stack", VF_UNIT = "qbvh_stack";
    localparam integer VF_ENC = 0, VF_MODULO = 0;
    `include "vecfile.vh"

    reg [31:0] v_op, v_first, v_mask, v_t0, v_t1, v_t2, v_t3, v_entry;
    reg [31:0] v_node, v_next, v_write, v_order, v_nhit, v_status;


    initial begin
        vf_open;

        // ---- vectors: "OP FIRST HIT_MASK T0 T1 T2 T3 ENTRY NODE NEXT_ENTRY WRITE ORDER NHIT STATUS"
        // (the "->" is only in the fields header)
        vf_read_line;
        while (vf_rc != 0) begin
            {v_op, v_first, v_mask, v_t0, v_t1, v_t2, v_t3, v_entry, v_node, v_next, v_write, v_order,
                v_nhit, v_status} =
                {vf_w[0], vf_w[1], vf_w[2], vf_w[3], vf_w[4], vf_w[5], vf_w[6], vf_w[7], vf_w[8], vf_w[9],
                vf_w[10], vf_w[11], vf_w[12], vf_w[13]};
            if (vf_nw != 14)
                $fatal(1, "tb_qbvh_stack: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            // inputs wider than their port cannot be driven faithfully
            if (v_op[31:4] != 0 || v_mask[31:4] != 0)
                $fatal(1, "tb_qbvh_stack: %0s:%0d: op or hit_mask wider than 4 bits", vf_path, vf_lineno);
            op       = v_op[3:0];
            first    = v_first;
            hit_mask = v_mask[3:0];
            t0       = v_t0;
            t1       = v_t1;
            t2       = v_t2;
            t3       = v_t3;
            entry    = v_entry;
            #1;
            vf_nvec = vf_nvec + 1;
            if (node !== v_node || next_entry !== v_next ||
                write !== v_write[0] || v_write[31:1] != 0 ||
                order !== v_order[7:0] || v_order[31:8] != 0 ||
                nhit !== v_nhit[3:0] || v_nhit[31:4] != 0 ||
                status !== v_status[7:0] || v_status[31:8] != 0) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10)
                    $display("mismatch line %0d: inputs op=%h first=%h hit_mask=%h t=%h %h %h %h entry=%h expected node=%h next_entry=%h write=%h order=%h nhit=%h status=%h got node=%h next_entry=%h write=%h order=%h nhit=%h status=%h",
                             vf_lineno, v_op[3:0], v_first, v_mask[3:0], v_t0, v_t1, v_t2, v_t3, v_entry,
                             v_node, v_next, v_write[3:0], v_order[7:0], v_nhit[3:0], v_status[7:0],
                             node, next_entry, {3'b000, write}, order, nhit, status);
            end
            vf_read_line;
        end
        vf_finish;
    end
endmodule
