// evclust_stage_reg: the pipeline register between a leaf module's two stages (evclust_update,
// evclust_palette). STAGES = 2: `q` is `d` as it was at the last `advance` (cleared by a
// synchronous `rst`; tie `rst` low where the stage's contents never reach an output unqualified).
// STAGES = 1: `q` is `d`, and the clock and controls are unused.
`default_nettype none
module evclust_stage_reg #(
    parameter integer W = 1,
    parameter integer STAGES = 1  // 1: a wire; 2: a register
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         advance,
    input  wire [W-1:0] d,
    output wire [W-1:0] q
);
    generate
        if (STAGES == 2) begin : registered
            reg [W-1:0] operands;
            always @(posedge clk)
                if (rst)
                    operands <= {W{1'b0}};
                else if (advance)
                    operands <= d;
            assign q = operands;
        end else begin : direct
            assign q = d;
            wire unused_controls = &{1'b0, clk, rst, advance};
        end
    endgenerate
endmodule
`default_nettype wire
