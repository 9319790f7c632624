// Activity decay A * 2^(-dt/T_half) (model: arith.decay_steps + arith.decay_apply).
// n = dt * (1/T_half) + residual counts 1/64 half-lives; its bits below one step are handed
// back as the new residual, so many short decays add up to one long one. The integer part
// of m = n / 2^DROP shifts, its low 6 bits index the 2^-(i/64) table (evclust_decay_apply).
// Without the residual (eviction's comparison) it is arith.decay.
`default_nettype none
`include "evclust_require.vh"
module evclust_decay #(
    parameter integer ACTIVITY_BITS = 25,  // the header's ACTIVITY_W (checked below)
    parameter integer DT_BITS = 32,
    parameter integer RESIDUAL_BITS = 32,
    parameter integer INV_T_HALF_BITS = 38
) (
    input  wire [ACTIVITY_BITS-1:0]   activity,
    input  wire [DT_BITS-1:0]         dt,
    input  wire [RESIDUAL_BITS-1:0]   residual,
    input  wire                       use_residual,
    input  wire [INV_T_HALF_BITS-1:0] inv_t_half,  // 1/T_half, a run-time register
    output wire [ACTIVITY_BITS-1:0]   decayed,
    output wire [RESIDUAL_BITS-1:0]   residual_out
);
`include "evclust_params.vh"

    generate
        if (ACTIVITY_BITS != ACTIVITY_W || DT_BITS != DT_W || RESIDUAL_BITS != DECAY_RESIDUAL_W || INV_T_HALF_BITS != INV_T_HALF_W) begin : widths_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_decay: a width differs from evclust_params.vh")
        end
    endgenerate

    localparam integer DROP = INV_T_HALF_FRAC - DECAY_TABLE_BITS;  // n's bits below one table step

    wire [63:0] steps = {{(64 - DT_W){1'b0}}, dt} * {{(64 - INV_T_HALF_W){1'b0}}, inv_t_half}
                      + (use_residual ? {{(64 - DECAY_RESIDUAL_W){1'b0}}, residual} : 64'd0);
    evclust_decay_apply #(.ACTIVITY_BITS(ACTIVITY_BITS)) apply (.activity(activity), .m(steps >> DROP), .decayed(decayed));
    assign residual_out = steps[DECAY_RESIDUAL_W-1:0];  // DECAY_RESIDUAL_W == DROP
endmodule
`default_nettype wire
