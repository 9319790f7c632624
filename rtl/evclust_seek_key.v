// One slot's seek key for an event at (x, y) (model: fixed_model._seek): {miss, L1 distance,
// slot}, the distance |x - Px| + |y - Py| in P's format (mod 2^SEEK_DISTANCE_W) and 0 on a
// miss. A hit is a live slot with the event within its reach on both axes. The reach,
// (R << (F_P - F_R)) + S + seek_scale * max(Rx, Ry), is the slot's own, and its window per axis
// (evclust_seek_window: {lo, hi, up, nf}) was taken as the slot was written (evclust_core), so
// that each axis costs two pixel-wide comparisons for the hit and two pixel-wide subtractions
// for the distance, not subtractions and comparisons of P-format words.
`default_nettype none
`include "evclust_require.vh"
module evclust_seek_key #(
    parameter integer XY_BITS = 9,       // the header's EV_XY_W (checked below)
    parameter integer CENTRE_BITS = 26,  // CENTRE_W
    parameter integer WINDOW_BITS = 46,  // evclust_seek_window's
    parameter integer SLOT_BITS = 4,
    parameter integer KEY_BITS = 32      // 1 + SEEK_DISTANCE_W + SLOT_BITS
) (
    input  wire [XY_BITS-1:0]     x,
    input  wire [XY_BITS-1:0]     y,
    input  wire                   live,
    input  wire [CENTRE_BITS-1:0] centre_x,
    input  wire [CENTRE_BITS-1:0] centre_y,
    input  wire [WINDOW_BITS-1:0] window_x,
    input  wire [WINDOW_BITS-1:0] window_y,
    input  wire [SLOT_BITS-1:0]   slot,
    output wire [KEY_BITS-1:0]    key
);
`include "evclust_params.vh"

    localparam integer FP = CENTRE_FRAC;
    localparam integer INT_W = CENTRE_BITS - FP;
    localparam integer LO_W = INT_W + 1;
    localparam integer DIST_W = SEEK_DISTANCE_W;
    generate
        if (XY_BITS != EV_XY_W || CENTRE_BITS != CENTRE_W || KEY_BITS != 1 + DIST_W + SLOT_BITS
            || INT_W < XY_BITS || WINDOW_BITS != 2 * LO_W + XY_BITS + FP) begin : widths_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_seek_key: a width differs from evclust_params.vh")
        end
    endgenerate
    localparam integer SUM_W = (CENTRE_BITS > DIST_W ? CENTRE_BITS : DIST_W) + 1;  // the carry, then the distance's own bits

    // One axis: {lo <= x <= hi, |x * 2^FP - P|}, the distance out of the window's up and nf or
    // the centre's own integer and fraction bits (evclust_seek_window says why both are exact).
    function automatic [CENTRE_BITS:0] axis;
        input [XY_BITS-1:0]     v;
        input [CENTRE_BITS-1:0] centre;
        input [WINDOW_BITS-1:0] window;
        reg [LO_W-1:0]    lo, up, ev;
        reg [XY_BITS-1:0] hi;
        reg [FP-1:0]      nf;
        reg [LO_W:0]      past;    // v - up, negative below the centre
        reg [INT_W-1:0]   below;  // floor(P / 2^FP) - v
        begin
            {lo, hi, up, nf} = window;
            ev = {{(LO_W - XY_BITS){1'b0}}, v};
            past = {1'b0, ev} - {1'b0, up};
            below = centre[FP +: INT_W] - ev[INT_W-1:0];
            axis = {lo <= ev && v <= hi, past[LO_W] ? {below, centre[FP-1:0]} : {past[INT_W-1:0], nf}};
        end
    endfunction

    wire [CENTRE_BITS:0] ax = axis(x, centre_x, window_x);
    wire [CENTRE_BITS:0] ay = axis(y, centre_y, window_y);
    wire hit = live && ax[CENTRE_BITS] && ay[CENTRE_BITS];
    /* verilator lint_off UNUSEDSIGNAL */  // the distance is taken mod 2^DIST_W, as the model's
    wire [SUM_W-1:0] sum = {{(SUM_W - CENTRE_BITS){1'b0}}, ax[CENTRE_BITS-1:0]} + {{(SUM_W - CENTRE_BITS){1'b0}}, ay[CENTRE_BITS-1:0]};
    /* verilator lint_on UNUSEDSIGNAL */
    wire [DIST_W-1:0] distance = sum[DIST_W-1:0];
    assign key = {!hit, hit ? distance : {DIST_W{1'b0}}, slot};
endmodule
`default_nettype wire
