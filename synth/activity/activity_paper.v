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

// The paper's activity with the slot's t_last·(1/T_half) stored in its row when t_last is written,
// and the event's t·(1/T_half) made once per event outside the recurrence: the multiply leaves
// the slot's recurrence, the decay stays (its best pipelined form). The steps are the same integer
// as dt·(1/T_half): E - P mod 2^64, plus (1/T_half) << 32 when the 32-bit time wrapped.
module activity_paper_stored (clk, activity, event_product, slot_product, wrapped, residual, inv_t_half, committed, residual_out);
`include "evclust_params.vh"
    localparam integer DROP = INV_T_HALF_FRAC - DECAY_TABLE_BITS;
    localparam integer MAX_SHIFT = 62 - DECAY_TABLE_FRAC;
    input  wire                        clk;
    input  wire [ACTIVITY_W-1:0]       activity;
    input  wire [63:0]                 event_product;  // t·(1/T_half), once per event
    input  wire [63:0]                 slot_product;   // t_last·(1/T_half), from the slot's row
    input  wire                        wrapped;        // t < t_last: the 32-bit clock wrapped
    input  wire [DECAY_RESIDUAL_W-1:0] residual;
    input  wire [INV_T_HALF_W-1:0]     inv_t_half;
    output reg  [ACTIVITY_W-1:0]       committed;
    output reg  [DECAY_RESIDUAL_W-1:0] residual_out;

    reg [ACTIVITY_W-1:0]       a_q;
    reg [63:0]                 e_q, p_q;
    reg                        wrapped_q;
    reg [DECAY_RESIDUAL_W-1:0] r_q;
    reg [INV_T_HALF_W-1:0]     inv_q;
    always @(posedge clk) begin
        a_q <= activity;
        e_q <= event_product;
        p_q <= slot_product;
        wrapped_q <= wrapped;
        r_q <= residual;
        inv_q <= inv_t_half;
    end
    wire [63:0] steps = e_q - p_q + (wrapped_q ? {{(32 - INV_T_HALF_W + 32){1'b0}}, inv_q} << 32 : 64'd0)
                      + {{(64 - DECAY_RESIDUAL_W){1'b0}}, r_q};
    wire [63:0] m = steps >> DROP;
    wire [63:0] halvings = m >> DECAY_TABLE_BITS;
    reg  [DECAY_TABLE_W-1:0] fraction;
    integer e;
    always @* begin
        fraction = {DECAY_TABLE_W{1'b0}};
        for (e = 0; e < (1 << DECAY_TABLE_BITS); e = e + 1)
            if ({{(32 - DECAY_TABLE_BITS){1'b0}}, m[DECAY_TABLE_BITS-1:0]} == e) fraction = DECAY_TABLE[e * DECAY_TABLE_W +: DECAY_TABLE_W];
    end
    wire [ACTIVITY_W+DECAY_TABLE_W-1:0] scaled = a_q * fraction;
    wire [6:0] shift = {1'b0, halvings[5:0]} + DECAY_TABLE_FRAC[6:0];
    wire [ACTIVITY_W+DECAY_TABLE_W-1:0] shifted = scaled >> shift;
    wire [ACTIVITY_W-1:0] decayed = halvings > MAX_SHIFT ? {ACTIVITY_W{1'b0}} : shifted[ACTIVITY_W-1:0];
    wire [ACTIVITY_W:0] plus_one = {1'b0, decayed} + ({{ACTIVITY_W{1'b0}}, 1'b1} << ACTIVITY_FRAC);
    always @(posedge clk) begin
        committed <= plus_one[ACTIVITY_W] ? {ACTIVITY_W{1'b1}} : plus_one[ACTIVITY_W-1:0];
        residual_out <= steps[DECAY_RESIDUAL_W-1:0];
    end
endmodule
`default_nettype wire
