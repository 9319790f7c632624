// Unsigned restoring division in a pipeline: STEP quotient bits per stage, one division taken
// per enabled cycle, the quotient ready ceil(Q_W / STEP) enabled cycles later. The caller gives
// the dividend as its top part, already reduced below the divisor (`remainder_in` < divisor:
// the quotient then fits Q_W bits), and the Q_W bits still to bring down. A tag rides along.
// The filter sweep's MCM bias correction (docs/RTL.md: the sweep tail).
`default_nettype none
module evclust_pipediv #(
    parameter integer Q_W = 38,    // quotient bits
    parameter integer DEN_W = 21,  // divisor bits
    parameter integer STEP = 4,    // quotient bits per stage
    parameter integer TAG_W = 8
) (
    input  wire             clk,
    input  wire             rst,           // clears the tags (a tag may mark an entry live)
    input  wire             en,            // the pipeline moves
    input  wire [DEN_W-1:0] remainder_in,  // < divisor
    input  wire [Q_W-1:0]   bits_in,       // the dividend's low Q_W bits, MSB first
    input  wire [DEN_W-1:0] divisor,       // not zero
    input  wire [TAG_W-1:0] tag_in,
    output wire [Q_W-1:0]   quotient,
    output wire [TAG_W-1:0] tag_out
`ifdef FORMAL
    ,
    output wire [(Q_W + STEP - 1) / STEP * TAG_W - 1:0] f_tags  // stage r's tag at [(r - 1) * TAG_W]: the core's proofs' invariants
`endif
);
    localparam integer STAGES = (Q_W + STEP - 1) / STEP;
    localparam integer FIRST = Q_W - (STAGES - 1) * STEP;  // the first stage takes what is left over

    reg [DEN_W-1:0] rem_q [0:STAGES];
    reg [Q_W-1:0]   bits_q [0:STAGES];  // not yet brought down (top), quotient so far (bottom)
    reg [DEN_W-1:0] div_q [0:STAGES];
    reg [TAG_W-1:0] tag_q [0:STAGES];

    // One stage: STEP shift-subtract steps (FIRST in stage 1), each bringing down the top bit
    // and shifting a quotient bit in at the bottom: after Q_W steps the word is the quotient.
    reg [DEN_W-1:0] rem_next [1:STAGES];
    reg [Q_W-1:0]   bits_next [1:STAGES];
    reg [DEN_W:0]   shifted;
    integer st, b;
    always @* begin
        for (st = 1; st <= STAGES; st = st + 1) begin
            rem_next[st] = rem_q[st-1];
            bits_next[st] = bits_q[st-1];
            for (b = 0; b < (st == 1 ? FIRST : STEP); b = b + 1) begin
                shifted = {rem_next[st], bits_next[st][Q_W-1]};
                bits_next[st] = {bits_next[st][Q_W-2:0], shifted >= {1'b0, div_q[st-1]}};
                rem_next[st] = shifted >= {1'b0, div_q[st-1]} ? shifted[DEN_W-1:0] - div_q[st-1] : shifted[DEN_W-1:0];
            end
        end
    end

    always @* begin  // stage 0: the operands as given
        rem_q[0] = remainder_in;
        bits_q[0] = bits_in;
        div_q[0] = divisor;
        tag_q[0] = tag_in;
    end

    integer r;
    always @(posedge clk) begin
        if (en) begin
            for (r = 1; r <= STAGES; r = r + 1) begin
                rem_q[r] <= rem_next[r];
                bits_q[r] <= bits_next[r];
                div_q[r] <= div_q[r-1];
            end
        end
        for (r = 1; r <= STAGES; r = r + 1)
            if (rst)
                tag_q[r] <= {TAG_W{1'b0}};
            else if (en)
                tag_q[r] <= tag_q[r-1];
    end

    assign quotient = bits_q[STAGES];
    assign tag_out = tag_q[STAGES];
`ifdef FORMAL
    genvar f_r;
    generate
        for (f_r = 1; f_r <= STAGES; f_r = f_r + 1) begin : f_stage
            assign f_tags[(f_r - 1) * TAG_W +: TAG_W] = tag_q[f_r];
        end
    endgenerate
`endif
endmodule
`default_nettype wire
