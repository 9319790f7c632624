// Unsigned restoring division, one quotient bit per cycle: floor(numerator / denominator), as
// the model's `//` on non-negative integers (the merge's activity-weighted centre). Off the
// per-event path: done rises NUM_W cycles after start (a merge holds the sweep NUM_W + 3 cycles).
`default_nettype none
module evclust_udiv #(
    parameter integer NUM_W = 32,
    parameter integer DEN_W = 16
) (
    input  wire             clk,
    input  wire             rst,
    input  wire             start,        // takes the operands; done rises NUM_W cycles later
    input  wire [NUM_W-1:0] numerator,
    input  wire [DEN_W-1:0] denominator,  // not zero
    output reg              done,         // quotient valid, until the next start
    output reg  [NUM_W-1:0] quotient,
    output wire [DEN_W-1:0] remainder_out  // numerator - quotient * denominator, with done
`ifdef FORMAL
    ,
    output wire [$clog2(NUM_W + 1)-1:0] f_count  // the steps still to go (the core's proofs' invariants)
`endif
);
    localparam integer COUNT_W = $clog2(NUM_W + 1);
    localparam [COUNT_W-1:0] LAST = NUM_W[COUNT_W-1:0];

    reg [NUM_W-1:0]   dividend;    // bits not yet brought down, MSB first
    reg [DEN_W-1:0]   divisor;
    reg [DEN_W-1:0]   remainder;   // < divisor: the shift makes it one bit wider, the step narrows it again
    reg [COUNT_W-1:0] count;

    wire [DEN_W:0] shifted = {remainder, dividend[NUM_W-1]};
    wire           fits = shifted >= {1'b0, divisor};
    wire [DEN_W:0] reduced = shifted - {1'b0, divisor};
    wire           busy = count != {COUNT_W{1'b0}};
    assign remainder_out = remainder;
`ifdef FORMAL
    assign f_count = count;
`endif

    always @(posedge clk) begin
        if (rst) begin
            count <= {COUNT_W{1'b0}};
            done <= 1'b0;
            quotient <= {NUM_W{1'b0}};
            dividend <= {NUM_W{1'b0}};
            divisor <= {DEN_W{1'b0}};
            remainder <= {DEN_W{1'b0}};
        end else if (start) begin
            dividend <= numerator;
            divisor <= denominator;
            remainder <= {DEN_W{1'b0}};
            quotient <= {NUM_W{1'b0}};
            count <= LAST;
            done <= 1'b0;
        end else if (busy) begin
            remainder <= fits ? reduced[DEN_W-1:0] : shifted[DEN_W-1:0];
            quotient <= {quotient[NUM_W-2:0], fits};
            dividend <= dividend << 1;
            count <= count - 1'b1;
            done <= count == {{(COUNT_W - 1){1'b0}}, 1'b1};
        end
    end
endmodule
`default_nettype wire
