// A * 2^(-m/64), floored (model: arith.decay_apply): the low DECAY_TABLE_BITS bits of m index
// the 2^-(i/64) table, the rest are whole halvings. One multiplier and one barrel shifter, no
// exponential. evclust_decay puts it behind dt * (1/T_half); against a reference time
// (ACTIVITY_REFERENCE) the filter step's sweep gives every slot the step's one m.
`default_nettype none
module evclust_decay_apply #(
    parameter integer ACTIVITY_BITS = 25
) (
    input  wire [ACTIVITY_BITS-1:0] activity,
    input  wire [63:0]              m,         // 1/64 half-lives
    output wire [ACTIVITY_BITS-1:0] decayed
);
`include "evclust_params.vh"

    localparam integer ENTRY_W = DECAY_TABLE_W;
    // A shift beyond this leaves nothing of A (the model's `total > 62` test).
    localparam integer MAX_SHIFT = 62 - DECAY_TABLE_FRAC;
    localparam [6:0] FRACTION_SHIFT = DECAY_TABLE_FRAC[6:0];
    localparam [63:0] MAX_HALVINGS = {32'd0, MAX_SHIFT[31:0]};

    wire [63:0] halvings = m >> DECAY_TABLE_BITS;
    wire [DECAY_TABLE_BITS-1:0] index = m[DECAY_TABLE_BITS-1:0];
    // A multiplexer over the entries: an index times the entry width would be a multiply that
    // synthesis maps to a DSP block.
    reg [ENTRY_W-1:0] fraction;
    integer e;
    always @* begin
        fraction = {ENTRY_W{1'b0}};
        for (e = 0; e < (1 << DECAY_TABLE_BITS); e = e + 1)
            if ({{(32 - DECAY_TABLE_BITS){1'b0}}, index} == e)
                fraction = DECAY_TABLE[e * ENTRY_W +: ENTRY_W];
    end
    wire [ACTIVITY_BITS+ENTRY_W-1:0] scaled = activity * fraction;
    wire [6:0] shift = {1'b0, halvings[5:0]} + FRACTION_SHIFT;  // <= 62 where used
    wire [ACTIVITY_BITS+ENTRY_W-1:0] shifted = scaled >> shift;

    // (an entry is at most 1.0 and the shift at least its fraction bits: A's width holds the rest)
    assign decayed = halvings > MAX_HALVINGS ? {ACTIVITY_BITS{1'b0}} : shifted[ACTIVITY_BITS-1:0];
endmodule
`default_nettype wire
