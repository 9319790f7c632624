// The two smallest of N unsigned keys, by a balanced tree of comparators (log2 N levels).
// The seek packs {miss, distance, slot} (the nearest slot in the window, ties to the lower one)
// and {taken, slot} (the lowest free slot) into keys, so the keys are distinct and "smallest"
// is the model's choice. The runner-up lets the next stage replace one slot whose state
// changed under the search (docs/RTL.md: the one-event-per-clock pipeline).
`default_nettype none
module evclust_top2 #(
    parameter integer N = 16,
    parameter integer KEY_W = 8
) (
    input  wire [N*KEY_W-1:0] keys,    // key i in bits [i*KEY_W +: KEY_W]
    output wire [KEY_W-1:0]   first,   // the smallest key
    output wire [KEY_W-1:0]   second   // the smallest of the others (all ones when N = 1)
);
    localparam integer LEAVES = N > 1 ? 1 << $clog2(N) : 2;
    localparam [KEY_W-1:0] NONE = {KEY_W{1'b1}};  // larger than any real key

    // A heap-ordered tree: node i has children 2i and 2i + 1; the leaves are LEAVES .. 2 LEAVES - 1.
    reg [KEY_W-1:0] best [1:2*LEAVES-1];
    reg [KEY_W-1:0] next [1:2*LEAVES-1];
    integer i;
    always @* begin
        for (i = 0; i < LEAVES; i = i + 1) begin
            best[LEAVES + i] = i < N ? keys[i*KEY_W +: KEY_W] : NONE;
            next[LEAVES + i] = NONE;
        end
        for (i = LEAVES - 1; i >= 1; i = i - 1) begin
            if (best[2*i] <= best[2*i+1]) begin  // the left wins: the runner-up is the right's best or the left's second
                best[i] = best[2*i];
                next[i] = best[2*i+1] < next[2*i] ? best[2*i+1] : next[2*i];
            end else begin
                best[i] = best[2*i+1];
                next[i] = best[2*i] < next[2*i+1] ? best[2*i] : next[2*i+1];
            end
        end
    end
    assign first = best[1];
    assign second = next[1];
endmodule
`default_nettype wire
