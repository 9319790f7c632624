// Step 1, the seek (model: fixed_model._seek, and the lowest free slot of _slot_for_new): every
// slot's key for the event at once (evclust_seek_key), and the two smallest of the seek keys and
// of the free-slot keys {taken, slot} by comparator trees (evclust_top2). The smallest seek key is
// the nearest live slot in reach, ties to the lower slot; its runner-up lets stage B replace
// the slot written as the event entered (docs/RTL.md: the one-event-per-clock pipeline).
`default_nettype none
`include "evclust_require.vh"
module evclust_seek #(
    parameter integer N = 16,
    parameter integer XY_BITS = 9,
    parameter integer CENTRE_BITS = 26,
    parameter integer WINDOW_BITS = 46,  // evclust_seek_window's
    parameter integer SLOT_BITS = 4,
    parameter integer KEY_BITS = 32
) (
    input  wire [XY_BITS-1:0]       x,
    input  wire [XY_BITS-1:0]       y,
    input  wire [N-1:0]             valid,     // slot i at bit i, and likewise below
    input  wire [N*CENTRE_BITS-1:0] centre_x,
    input  wire [N*CENTRE_BITS-1:0] centre_y,
    input  wire [N*WINDOW_BITS-1:0] window_x,  // each slot's seek window (evclust_seek_window)
    input  wire [N*WINDOW_BITS-1:0] window_y,
    output wire [KEY_BITS-1:0]      seek_first,
    output wire [KEY_BITS-1:0]      seek_second,
    output wire [SLOT_BITS:0]       free_first,   // {taken, slot}
    output wire [SLOT_BITS:0]       free_second
);
    wire [N*KEY_BITS-1:0]    seek_keys;
    wire [N*(SLOT_BITS+1)-1:0] free_keys;
    genvar s;
    generate
        for (s = 0; s < N; s = s + 1) begin : slot
            localparam [SLOT_BITS-1:0] INDEX = s;
            evclust_seek_key #(
                .XY_BITS(XY_BITS), .CENTRE_BITS(CENTRE_BITS), .WINDOW_BITS(WINDOW_BITS), .SLOT_BITS(SLOT_BITS), .KEY_BITS(KEY_BITS)
            ) slot_key (
                .x(x), .y(y), .live(valid[s]),
                .centre_x(centre_x[s*CENTRE_BITS +: CENTRE_BITS]), .centre_y(centre_y[s*CENTRE_BITS +: CENTRE_BITS]),
                .window_x(window_x[s*WINDOW_BITS +: WINDOW_BITS]), .window_y(window_y[s*WINDOW_BITS +: WINDOW_BITS]),
                .slot(INDEX), .key(seek_keys[s*KEY_BITS +: KEY_BITS])
            );
            assign free_keys[s*(SLOT_BITS+1) +: SLOT_BITS+1] = {valid[s], INDEX};
        end
    endgenerate
    evclust_top2 #(.N(N), .KEY_W(KEY_BITS)) seek_tree (.keys(seek_keys), .first(seek_first), .second(seek_second));
    evclust_top2 #(.N(N), .KEY_W(SLOT_BITS + 1)) free_tree (.keys(free_keys), .first(free_first), .second(free_second));
endmodule
`default_nettype wire
