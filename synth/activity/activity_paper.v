// The paper's activity datapath as evclust_core has it, registered on both sides so that place and
// route times it alone (synth/activity_reference.py). Per event, in the recurrence: decay from the
// slot's own time (evclust_decay: dt·(1/T_half) + residual, the 2^-i/64 table, A·2^-f, a shift),
// then plus one, saturated. The same unit decays each slot in the filter step's sweep.
`default_nettype none
module activity_paper (clk, activity, t, t_last, residual, inv_t_half, committed, swept, residual_out);
`include "evclust_params.vh"
    input  wire                        clk;
    input  wire [ACTIVITY_W-1:0]       activity;
    input  wire [T_LAST_W-1:0]         t, t_last;
    input  wire [DECAY_RESIDUAL_W-1:0] residual;
    input  wire [INV_T_HALF_W-1:0]     inv_t_half;  // a run-time register
    output reg  [ACTIVITY_W-1:0]       committed;   // decayed + 1, saturated: the commit's new activity
    output reg  [ACTIVITY_W-1:0]       swept;       // decayed: the sweep's
    output reg  [DECAY_RESIDUAL_W-1:0] residual_out;

    reg [ACTIVITY_W-1:0]       a_q;
    reg [T_LAST_W-1:0]         t_q, t_last_q;
    reg [DECAY_RESIDUAL_W-1:0] r_q;
    reg [INV_T_HALF_W-1:0]     inv_q;
    always @(posedge clk) begin
        a_q <= activity;
        t_q <= t;
        t_last_q <= t_last;
        r_q <= residual;
        inv_q <= inv_t_half;
    end
    wire [ACTIVITY_W-1:0]       decayed;
    wire [DECAY_RESIDUAL_W-1:0] r_next;
    wire [DT_W-1:0]             dt = t_q - t_last_q;
    evclust_decay #(.ACTIVITY_BITS(ACTIVITY_W), .DT_BITS(DT_W), .RESIDUAL_BITS(DECAY_RESIDUAL_W), .INV_T_HALF_BITS(INV_T_HALF_W)) decay (
        .activity(a_q), .dt(dt), .residual(r_q), .use_residual(1'b1), .inv_t_half(inv_q), .decayed(decayed), .residual_out(r_next)
    );
    wire [ACTIVITY_W:0] plus_one = {1'b0, decayed} + ({{ACTIVITY_W{1'b0}}, 1'b1} << ACTIVITY_FRAC);
    always @(posedge clk) begin
        committed <= plus_one[ACTIVITY_W] ? {ACTIVITY_W{1'b1}} : plus_one[ACTIVITY_W-1:0];
        swept <= decayed;
        residual_out <= r_next;
    end
endmodule
`default_nettype wire
