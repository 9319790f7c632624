// The activity against a reference time (ClustererParams.activity_reference), as the fixed model
// computes it, in three parts that synth/activity_reference.py times apart, each registered on
// both sides, and `activity_reference`, which joins them for the check against the fixed model:
// - activity_reference_weight, once per event and outside every slot's recurrence (it may be
//   pipelined freely): m = (t - t_ref)·(1/T_half) + residual in steps of 1/64 half-life; the
//   weight 2^(m/64) = 2^4 decayed by 256 - m (the table and a shift: the constant 2^4 makes the
//   decay's product a shift); whether the reference must move (more than 4 half-lives, unfloored);
// - activity_reference_commit, the slot's recurrence: Ã + weight, saturated;
// - activity_reference_sweep, per slot in the filter step's sweep: Ã·2^-f >> i with the step's
//   one table entry and shift in registers, saturated to the activity's format.
`default_nettype none
module activity_reference_weight (clk, t, t_ref, residual, inv_t_half, weight, move);
`include "evclust_params.vh"
    localparam integer HEADROOM = 4;  // ClustererParams' REFERENCE_HALVINGS
    localparam integer REF_W = ACTIVITY_W + HEADROOM;
    localparam integer DROP = INV_T_HALF_FRAC - DECAY_TABLE_BITS;
    localparam integer TOP = HEADROOM << DECAY_TABLE_BITS;
    localparam integer PRODUCT_W = REF_W + DECAY_TABLE_W;
    input  wire                        clk;
    input  wire [T_LAST_W-1:0]         t, t_ref;
    input  wire [DECAY_RESIDUAL_W-1:0] residual;  // the reference's
    input  wire [INV_T_HALF_W-1:0]     inv_t_half;
    output reg  [REF_W-1:0]            weight;
    output reg                         move;

    reg [T_LAST_W-1:0]         t_q, t_ref_q;
    reg [DECAY_RESIDUAL_W-1:0] r_q;
    reg [INV_T_HALF_W-1:0]     inv_q;
    always @(posedge clk) begin
        t_q <= t;
        t_ref_q <= t_ref;
        r_q <= residual;
        inv_q <= inv_t_half;
    end
    // (2^(F_A + 4) · T[left mod 64]) >> (16 + left / 64), left = 256 - m.
    wire [DT_W-1:0] dt = t_q - t_ref_q;
    wire [63:0] steps = {{(64 - DT_W){1'b0}}, dt} * {{(64 - INV_T_HALF_W){1'b0}}, inv_q} + {{(64 - DECAY_RESIDUAL_W){1'b0}}, r_q};
    localparam [63:0] SPAN_TOP = 64'd4 << INV_T_HALF_FRAC;  // HEADROOM half-lives, unfloored
    wire [63:0] m = steps >> DROP;
    wire        over = steps > SPAN_TOP;
    wire [8:0]  left = TOP[8:0] - m[8:0];  // m <= 256 where used
    reg  [DECAY_TABLE_W-1:0] entry;
    integer e;
    always @* begin
        entry = {DECAY_TABLE_W{1'b0}};
        for (e = 0; e < (1 << DECAY_TABLE_BITS); e = e + 1)
            if ({26'd0, left[5:0]} == e) entry = DECAY_TABLE[e * DECAY_TABLE_W +: DECAY_TABLE_W];
    end
    wire [PRODUCT_W-1:0] raised = {{REF_W{1'b0}}, entry} << (ACTIVITY_FRAC + HEADROOM);
    wire [PRODUCT_W-1:0] w = raised >> (DECAY_TABLE_FRAC + left[8:6]);
    always @(posedge clk) begin
        weight <= over ? {REF_W{1'b0}} : w[REF_W-1:0];
        move <= over;
    end
endmodule

module activity_reference_commit (clk, activity, weight, committed);
`include "evclust_params.vh"
    localparam integer REF_W = ACTIVITY_W + 4;
    input  wire             clk;
    input  wire [REF_W-1:0] activity, weight;
    output reg  [REF_W-1:0] committed;
    reg [REF_W-1:0] a_q, w_q;
    always @(posedge clk) begin
        a_q <= activity;
        w_q <= weight;
    end
    wire [REF_W:0] sum = {1'b0, a_q} + {1'b0, w_q};
    always @(posedge clk) committed <= sum[REF_W] ? {REF_W{1'b1}} : sum[REF_W-1:0];
endmodule

module activity_reference_sweep (clk, activity, step_entry, step_shift, swept);
`include "evclust_params.vh"
    localparam integer REF_W = ACTIVITY_W + 4;
    localparam integer PRODUCT_W = REF_W + DECAY_TABLE_W;
    input  wire                     clk;
    input  wire [REF_W-1:0]         activity;
    input  wire [DECAY_TABLE_W-1:0] step_entry;  // set once a step
    input  wire [6:0]               step_shift;
    output reg  [ACTIVITY_W-1:0]    swept;
    reg [REF_W-1:0]         a_q;
    reg [DECAY_TABLE_W-1:0] entry_q;
    reg [6:0]               shift_q;
    always @(posedge clk) begin
        a_q <= activity;
        entry_q <= step_entry;
        shift_q <= step_shift;
    end
    wire [PRODUCT_W-1:0] scaled = a_q * entry_q;
    wire [PRODUCT_W-1:0] decayed = scaled >> shift_q;
    always @(posedge clk) swept <= decayed[PRODUCT_W-1:ACTIVITY_W] != 0 ? {ACTIVITY_W{1'b1}} : decayed[ACTIVITY_W-1:0];
endmodule

// The three joined as the check drives them: the commit adds the weight register's value.
module activity_reference (clk, activity, t, t_ref, residual, inv_t_half, step_entry, step_shift, weight, move, committed, swept);
`include "evclust_params.vh"
    localparam integer REF_W = ACTIVITY_W + 4;
    input  wire                        clk;
    input  wire [REF_W-1:0]            activity;
    input  wire [T_LAST_W-1:0]         t, t_ref;
    input  wire [DECAY_RESIDUAL_W-1:0] residual;
    input  wire [INV_T_HALF_W-1:0]     inv_t_half;
    input  wire [DECAY_TABLE_W-1:0]    step_entry;
    input  wire [6:0]                  step_shift;
    output wire [REF_W-1:0]            weight;
    output wire                        move;
    output wire [REF_W-1:0]            committed;
    output wire [ACTIVITY_W-1:0]       swept;
    activity_reference_weight w (.clk(clk), .t(t), .t_ref(t_ref), .residual(residual), .inv_t_half(inv_t_half), .weight(weight), .move(move));
    activity_reference_commit c (.clk(clk), .activity(activity), .weight(weight), .committed(committed));
    activity_reference_sweep s (.clk(clk), .activity(activity), .step_entry(step_entry), .step_shift(step_shift), .swept(swept));
endmodule
`default_nettype wire
