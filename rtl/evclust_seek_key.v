// One slot's seek key for an event at (x, y) (model: fixed_model._seek): {miss, L1 distance,
// slot}, the distance |x - Px| + |y - Py| in P's format (mod 2^SEEK_DISTANCE_W) and 0 on a
// miss. A hit is a live slot with the event within its reach on both axes; the reach,
// (R << (F_P - F_R)) + S + seek_scale * max(Rx, Ry), is the slot's own, computed as it was
// written (evclust_core). The differences are taken at the words' own width: a difference of
// 64-bit words would need a 64-bit carry chain per slot for its sign.
`default_nettype none
`include "evclust_require.vh"
module evclust_seek_key #(
    parameter integer XY_BITS = 9,       // the header's EV_XY_W (checked below)
    parameter integer CENTRE_BITS = 26,  // CENTRE_W
    parameter integer REACH_BITS = 26,   // the core's stored reach
    parameter integer SLOT_BITS = 4,
    parameter integer KEY_BITS = 32      // 1 + SEEK_DISTANCE_W + SLOT_BITS
) (
    input  wire [XY_BITS-1:0]     x,
    input  wire [XY_BITS-1:0]     y,
    input  wire                   live,
    input  wire [CENTRE_BITS-1:0] centre_x,
    input  wire [CENTRE_BITS-1:0] centre_y,
    input  wire [REACH_BITS-1:0]  reach_x,
    input  wire [REACH_BITS-1:0]  reach_y,
    input  wire [SLOT_BITS-1:0]   slot,
    output wire [KEY_BITS-1:0]    key
);
`include "evclust_params.vh"

    generate
        if (XY_BITS != EV_XY_W || CENTRE_BITS != CENTRE_W || KEY_BITS != 1 + SEEK_DISTANCE_W + SLOT_BITS) begin : widths_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_seek_key: a width differs from evclust_params.vh")
        end
    endgenerate

    localparam integer FP = CENTRE_FRAC;
    localparam integer DIST_W = SEEK_DISTANCE_W;
    // An event's coordinate in P's format, or a centre: wide enough for both and the distance.
    localparam integer XY_P_W = XY_BITS + FP > CENTRE_BITS ? XY_BITS + FP : CENTRE_BITS;
    localparam integer WIDEST = XY_P_W > DIST_W ? (XY_P_W > REACH_BITS ? XY_P_W : REACH_BITS) : (DIST_W > REACH_BITS ? DIST_W : REACH_BITS);
    localparam integer GAP_W = WIDEST + 1;  // one bit more than any operand: every extension below is non-empty

    wire [GAP_W-1:0] ex = {{(GAP_W - XY_BITS){1'b0}}, x} << FP;
    wire [GAP_W-1:0] ey = {{(GAP_W - XY_BITS){1'b0}}, y} << FP;
    wire [GAP_W-1:0] cx = {{(GAP_W - CENTRE_BITS){1'b0}}, centre_x};
    wire [GAP_W-1:0] cy = {{(GAP_W - CENTRE_BITS){1'b0}}, centre_y};
    // |a - b| as one subtraction and a negation when it borrowed (two carry chains, not three).
    wire [GAP_W:0]   sub_x = {1'b0, ex} - {1'b0, cx};
    wire [GAP_W:0]   sub_y = {1'b0, ey} - {1'b0, cy};
    wire [GAP_W-1:0] dx = sub_x[GAP_W] ? ~sub_x[GAP_W-1:0] + 1'b1 : sub_x[GAP_W-1:0];
    wire [GAP_W-1:0] dy = sub_y[GAP_W] ? ~sub_y[GAP_W-1:0] + 1'b1 : sub_y[GAP_W-1:0];
    wire hit = live && dx <= {{(GAP_W - REACH_BITS){1'b0}}, reach_x} && dy <= {{(GAP_W - REACH_BITS){1'b0}}, reach_y};
    wire [DIST_W-1:0] distance = dx[DIST_W-1:0] + dy[DIST_W-1:0];
    assign key = {!hit, hit ? distance : {DIST_W{1'b0}}, slot};
endmodule
`default_nettype wire
