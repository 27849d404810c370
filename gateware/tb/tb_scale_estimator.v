// Testbench for cbvh_scale_estimator: runs one golden vector file (docs/vectors.md).
//   iverilog -g2005 -P tb_scale_estimator.N=6 -P tb_scale_estimator.E_MIN=-30 ...
//   vvp sim +vec=vectors/scale_estimate-N6-ms-30.vec
// No `timescale: the RTL has none either, so both use the simulator default unit.
module tb_scale_estimator;
    parameter integer N     = 6;
    parameter integer E_MIN = -30;

    reg  [31:0] lb, ub;
    wire [7:0]  scale;
    wire [6:0]  status;

    cbvh_scale_estimator #(.N(N), .E_MIN(E_MIN)) dut (
        .lb(lb), .ub(ub), .scale(scale), .status(status)
    );

    localparam [8*24-1:0] VF_TB = "tb_scale_estimator", VF_UNIT = "scale_estimate";
    localparam integer VF_ENC = 0, VF_MODULO = 0;
    `include "vecfile.vh"

    reg [31:0] v_lb, v_ub, v_scale, v_status;


    initial begin
        vf_open;

        // ---- vectors: "LB UB SCALE STATUS" (the "->" is only in the fields header)
        vf_read_line;
        while (vf_rc != 0) begin
            {v_lb, v_ub, v_scale, v_status} = {vf_w[0], vf_w[1], vf_w[2], vf_w[3]};
            if (vf_nw != 4)
                $fatal(1, "tb_scale_estimator: %0s:%0d: malformed vector line", vf_path, vf_lineno);
            lb = v_lb;
            ub = v_ub;
            #1;
            vf_nvec = vf_nvec + 1;
            if (scale !== v_scale[7:0] || status !== v_status[6:0] || v_status[31:7] != 0) begin
                vf_nfail = vf_nfail + 1;
                if (vf_nfail <= 10)
                    $display("mismatch line %0d: inputs lb=%h ub=%h expected scale=%h status=%h got scale=%h status=%h",
                             vf_lineno, v_lb, v_ub, v_scale[7:0], v_status[7:0], scale, {1'b0, status});
            end
            vf_read_line;
        end
        vf_finish;
    end
endmodule
