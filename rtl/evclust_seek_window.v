// One axis of a slot's seek window, taken once as the slot is written (evclust_core), so that
// the seek's per-slot key (evclust_seek_key) compares and subtracts pixel-wide words instead of
// P-format ones. For a centre P in P's format (FP fraction bits) and the slot's reach R, an
// event at pixel x is within reach exactly when |x * 2^FP - P| <= R, that is when
//   lo = max(0, ceil((P - R) / 2^FP)) <= x <= hi = min(2^EV_XY_W - 1, floor((P + R) / 2^FP)),
// and with up = ceil(P / 2^FP) and nf = -P mod 2^FP the distance is
//   |x * 2^FP - P| = {x - up, nf} when x >= up, else {floor(P / 2^FP) - x, P mod 2^FP},
// both concatenations exact (model: fixed_model._seek's hit and its L1 distance).
// window = {lo, hi, up, nf}: lo and up take the centre's integer bits and one more (both reach
// 2^(CENTRE_W - FP)); hi is a pixel coordinate.
`default_nettype none
`include "evclust_require.vh"
module evclust_seek_window #(
    parameter integer XY_BITS = 9,       // the header's EV_XY_W (checked below)
    parameter integer CENTRE_BITS = 26,  // CENTRE_W
    parameter integer REACH_BITS = 26,   // the core's reach word
    parameter integer WINDOW_BITS = 46   // 2 * (CENTRE_BITS - CENTRE_FRAC + 1) + XY_BITS + CENTRE_FRAC
) (
    input  wire [CENTRE_BITS-1:0] centre,
    input  wire [REACH_BITS-1:0]  reach,
    output wire [WINDOW_BITS-1:0] window
);
`include "evclust_params.vh"

    localparam integer FP = CENTRE_FRAC;
    localparam integer INT_W = CENTRE_BITS - FP;  // the centre's integer bits
    localparam integer LO_W = INT_W + 1;
    generate
        if (XY_BITS != EV_XY_W || CENTRE_BITS != CENTRE_W || INT_W < XY_BITS || WINDOW_BITS != 2 * LO_W + XY_BITS + FP) begin : widths_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_seek_window: a width differs from evclust_params.vh")
        end
    endgenerate

    // P - R and P + R, one bit wider than either word and the carry
    localparam integer SUM_W = (CENTRE_BITS > REACH_BITS ? CENTRE_BITS : REACH_BITS) + 2;
    wire [SUM_W-1:0] p = {{(SUM_W - CENTRE_BITS){1'b0}}, centre};
    wire [SUM_W-1:0] r = {{(SUM_W - REACH_BITS){1'b0}}, reach};
    wire [SUM_W-1:0] round_up = {{(SUM_W - FP){1'b0}}, {FP{1'b1}}};  // 2^FP - 1: a ceiling by a floor

    /* verilator lint_off UNUSEDSIGNAL */  // a ceiling's fraction bits, and the bits above it (zero)
    wire [SUM_W-1:0] near_up, p_up;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [SUM_W-1:0] near = p - r;                   // negative (top bit) when the reach passes pixel 0
    assign near_up = near + round_up;
    wire [LO_W-1:0]  lo = near[SUM_W-1] || near == {SUM_W{1'b0}} ? {LO_W{1'b0}} : near_up[FP +: LO_W];

    wire [SUM_W-1:0] far = (p + r) >> FP;
    wire [XY_BITS-1:0] last = {XY_BITS{1'b1}};
    wire [XY_BITS-1:0] hi = far > {{(SUM_W - XY_BITS){1'b0}}, last} ? last : far[XY_BITS-1:0];

    assign p_up = p + round_up;
    wire [LO_W-1:0]  up = p_up[FP +: LO_W];
    wire [FP-1:0]    nf = {FP{1'b0}} - centre[FP-1:0];

    assign window = {lo, hi, up, nf};
endmodule
`default_nettype wire
