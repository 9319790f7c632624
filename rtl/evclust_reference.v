// The activity against a reference time (ACTIVITY_REFERENCE; model: fixed_model._reference_span,
// _reference_passed and _weight; docs/DESIGN.md, "Activity against a reference time"). Every
// slot's activity Ã is kept as of one reference time, the last filter step's, scaled up by
// 2^((t - t_ref)/T_half); an event at t adds the weight 2^((t - t_ref)/T_half), the same for
// every slot, so the update is an addition and the decay leaves the per-event recurrence.
//
// span = (t - t_ref) * (1/T_half) + the reference's residual counts 1/64 half-lives since the
// reference (unfloored); `passed` says Ã could outgrow its REFERENCE_HALVINGS bits of headroom
// (the core then moves the reference first); `steps` and `residual_out` are what moving the
// reference to t decays every activity by and leaves behind. The weight is 2^REFERENCE_HALVINGS
// decayed by the steps left to that top, so it is exactly 1 at the reference; a power of two
// times the table's entry, it needs no multiplier beyond the span's.
`default_nettype none
// Widths are the header's (evclust_params.vh), so the ports are declared after it.
module evclust_reference #(
    parameter integer WEIGHT_BITS = 29  // the activity's width plus REFERENCE_HALVINGS
) (t, t_ref, residual, inv_t_half, steps, residual_out, passed, weight);
`include "evclust_params.vh"
    input  wire [EV_T_W-1:0]           t;
    input  wire [EV_T_W-1:0]           t_ref;
    input  wire [DECAY_RESIDUAL_W-1:0] residual;      // the reference's
    input  wire [INV_T_HALF_W-1:0]     inv_t_half;    // 1/T_half, a run-time register
    output wire [63:0]                 steps;         // whole 1/64 half-lives since the reference
    output wire [DECAY_RESIDUAL_W-1:0] residual_out;  // what is left below one step
    output wire                        passed;        // more than REFERENCE_HALVINGS half-lives
    output wire [WEIGHT_BITS-1:0]      weight;        // 2^(steps/64) in the activity's format (when not passed)

    localparam integer DROP = INV_T_HALF_FRAC - DECAY_TABLE_BITS;  // the span's bits below one table step
    localparam [63:0] TOP = {32'd0, REFERENCE_HALVINGS[31:0]} << DECAY_TABLE_BITS;  // steps at the headroom's top
    localparam [63:0] HIGHEST_I = 64'd1 << (ACTIVITY_FRAC + REFERENCE_HALVINGS);    // the weight at the top
    localparam [WEIGHT_BITS-1:0] HIGHEST = HIGHEST_I[WEIGHT_BITS-1:0];

    wire [DT_W-1:0] dt = t - t_ref;  // modulo 2^32, as every time difference
    wire [63:0] span = {{(64 - DT_W){1'b0}}, dt} * {{(64 - INV_T_HALF_W){1'b0}}, inv_t_half}
                     + {{(64 - DECAY_RESIDUAL_W){1'b0}}, residual};
    assign steps = span >> DROP;
    assign residual_out = span[DECAY_RESIDUAL_W-1:0];  // DECAY_RESIDUAL_W == DROP
    assign passed = span > ({32'd0, REFERENCE_HALVINGS[31:0]} << INV_T_HALF_FRAC);
    // (the product by a power of two is a shift: synthesis makes no multiplier of it)
    evclust_decay_apply #(.ACTIVITY_BITS(WEIGHT_BITS)) to_top (.activity(HIGHEST), .m(TOP - steps), .decayed(weight));
endmodule
`default_nettype wire
