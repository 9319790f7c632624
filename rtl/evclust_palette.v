// Palette vote of one event (model: fixed_model._nearest_palette, _mixing_palette and the vote
// in _update). All PALETTE_SIZE entries in parallel.
//  - nearest: the entry nearest in L1, luminance weighted by w_Y; ties go to the lower index;
//  - mixing: among the entries whose background-to-entry segment passes within the tolerance
//    of the event's colour, the nearest; q = clamp(u.w / |w|^2, 0, 1) from 1/|w|^2 (inv_ww,
//    refreshed at filter steps), so there is no divider here;
//  - the vote: 1, or the event's L1 contrast to the background, rounded half up.
//
// Two halves. Stage 1, from the event and the background: each entry's end distance and q (the
// products u.w and u.w / |w|^2), the order of the entries by end distance (every pair compared
// at once, so choosing needs no chain of comparisons), the nearest entry and the vote. Stage 2:
// each entry's distance to its segment, (u << F_q) - q w weighted, against the tolerance, and
// the nearest entry within it.
// STAGES = 1: combinational. STAGES = 2: a register (enabled by `advance`) between the halves,
// so the class and vote belong to the event of the last advance (the core with
// update_delay = 2 loads it as the event enters stage H). The run-time registers are read by
// both halves: they are quasi-static (written while the core is idle).
`default_nettype none
`include "evclust_require.vh"
module evclust_palette #(
    parameter integer P = 8,            // entries: the header's PALETTE_SIZE (checked below)
    parameter integer CLASS_W = 3,
    parameter integer BG_BITS = 24,     // the header's BACKGROUND_W
    parameter integer INV_BITS = 33,    // INV_WW_W
    parameter integer VOTE_BITS = 10,   // VOTE_W
    parameter integer LUMA_BITS = 8,    // LUMA_WEIGHT_W
    parameter integer TOL_BITS = 11,    // MIXING_TOLERANCE_W
    parameter integer STAGES = 1,       // 1: combinational; 2: one pipeline register
    // Entries 0 .. DSP_ENTRIES - 1 take their mixing products q.w in multiplier blocks, the rest
    // as shifted additions: as shifted additions a product costs some 600 logic cells.
    parameter integer DSP_ENTRIES = 0
) (
    input  wire                  clk,      // STAGES = 2 only
    input  wire                  rst,      // STAGES = 2: clears the register (synchronous)
    input  wire                  advance,  // STAGES = 2: stage 1's results move to stage 2
    input  wire [7:0]            lum,
    input  wire [7:0]            cb,
    input  wire [7:0]            cr,
    input  wire [BG_BITS-1:0]    bg_y,
    input  wire [BG_BITS-1:0]    bg_cb,
    input  wire [BG_BITS-1:0]    bg_cr,
    input  wire [P*INV_BITS-1:0] inv_ww,
    // Run-time registers: the palette (entry j in bits [8j +: 8]), w_Y, the mixing tolerance, the
    // background entries and the switches.
    input  wire [8*P-1:0]        palette_y,
    input  wire [8*P-1:0]        palette_cb,
    input  wire [8*P-1:0]        palette_cr,
    input  wire [LUMA_BITS-1:0]  luma_weight,
    input  wire [TOL_BITS-1:0]   mixing_tolerance,
    input  wire [P-1:0]          background_mask,
    input  wire                  mixing,
    input  wire                  vote_contrast,
    output reg  [CLASS_W-1:0]    class_index,
    output wire [VOTE_BITS-1:0]  vote
);
`include "evclust_params.vh"
`include "evclust_arith.vh"

    generate
        if (P != PALETTE_SIZE || CLASS_W != (P > 1 ? $clog2(P) : 1) || BG_BITS != BACKGROUND_W || INV_BITS != INV_WW_W
            || VOTE_BITS != VOTE_W || LUMA_BITS != LUMA_WEIGHT_W || TOL_BITS != MIXING_TOLERANCE_W || EV_COLOUR_W != 8
            || BACKGROUND_W - BACKGROUND_FRAC != 8 || (STAGES != 1 && STAGES != 2)) begin : widths_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_palette: a width differs from evclust_params.vh, the background is not UQ8.f, or STAGES is not 1 or 2")
        end
    endgenerate

    localparam integer FW = LUMA_WEIGHT_FRAC;
    localparam integer FB = BACKGROUND_FRAC;
    wire signed [63:0] W_Y = $signed({{(64 - LUMA_WEIGHT_W){1'b0}}, luma_weight});
    wire signed [63:0] TOLERANCE = $signed({{(64 - MIXING_TOLERANCE_W){1'b0}}, mixing_tolerance}) <<< FW;

    wire signed [63:0] e_y = $signed({{(64 - EV_COLOUR_W){1'b0}}, lum});
    wire signed [63:0] e_cb = $signed({{(64 - EV_COLOUR_W){1'b0}}, cb});
    wire signed [63:0] e_cr = $signed({{(64 - EV_COLOUR_W){1'b0}}, cr});
    wire signed [63:0] b_y = $signed({{(64 - BACKGROUND_W){1'b0}}, bg_y});
    wire signed [63:0] b_cb = $signed({{(64 - BACKGROUND_W){1'b0}}, bg_cb});
    wire signed [63:0] b_cr = $signed({{(64 - BACKGROUND_W){1'b0}}, bg_cr});
    // The background's integer colour, and the event seen from it.
    wire signed [9:0] bi_y = {{(10 - BACKGROUND_W + FB){1'b0}}, bg_y[BACKGROUND_W-1:FB]};
    wire signed [9:0] bi_cb = {{(10 - BACKGROUND_W + FB){1'b0}}, bg_cb[BACKGROUND_W-1:FB]};
    wire signed [9:0] bi_cr = {{(10 - BACKGROUND_W + FB){1'b0}}, bg_cr[BACKGROUND_W-1:FB]};
    wire signed [9:0] u_y10 = e_y[9:0] - bi_y;  // both in 0..255
    wire signed [9:0] u_cb10 = e_cb[9:0] - bi_cb;
    wire signed [9:0] u_cr10 = e_cr[9:0] - bi_cr;

    // Operands are sized to their ranges so that synthesis builds small multipliers: colour
    // differences fit 9 bits, u.w fits 19, q fits 17 bits (0..2^16), the residual 27.
    localparam integer QF = MIXING_Q_FRAC;
    localparam integer PROD_W = 18 + INV_WW_W;  // u.w (positive, 18 bits) x 2^32 / |w|^2
    localparam integer RES_W = 10 + QF + 2;     // (u << QF) - q w
    localparam [MIXING_Q_W-1:0] ONE_Q = 1 << QF;

    // The distances compared at a width that holds them all (64-bit comparisons would cost a
    // 64-bit carry chain each, per entry): w_Y|dY| + (|dCb| + |dCr|) << F_w, the line distance
    // before its shift, and the tolerance; "far" is all ones, above every distance.
    localparam integer D_END_W = (LUMA_WEIGHT_W + 8 > 9 + FW ? LUMA_WEIGHT_W + 8 : 9 + FW) + 1;
    localparam integer D_LINE_W = (LUMA_WEIGHT_W + RES_W > RES_W + 1 + FW ? LUMA_WEIGHT_W + RES_W : RES_W + 1 + FW) + 1;
    localparam integer D_W = D_END_W > D_LINE_W ? D_END_W : D_LINE_W;
    localparam integer CMP_W = (D_W > MIXING_TOLERANCE_W + FW ? D_W : MIXING_TOLERANCE_W + FW) + 1;
    /* verilator lint_off UNUSEDSIGNAL */  // the bits above CMP_W are zero
    wire [63:0] tolerance_bits = TOLERANCE;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [CMP_W-1:0] TOLERANCE_C = tolerance_bits[CMP_W-1:0];

    function automatic [7:0] byte_gap;  // |a - b| of two bytes: a subtraction, negated if it borrowed
        input [7:0] a;
        input [7:0] b;
        reg [8:0] d;
        begin
            d = {1'b0, a} - {1'b0, b};
            byte_gap = d[8] ? ~d[7:0] + 1'b1 : d[7:0];
        end
    endfunction
    function automatic [RES_W-1:0] residual_size;  // |r| of a RES_W-bit r
        input signed [RES_W-1:0] r;
        begin
            residual_size = r[RES_W-1] ? ~r + 1'b1 : r;
        end
    endfunction

    // ------------------------------------------------ stage 1: end distances, q, order, vote
    integer j, i;
    reg [P*CMP_W-1:0]      s1_d_end;  // entry j's end distance in bits [CMP_W j +: CMP_W]
    reg [P*MIXING_Q_W-1:0] s1_q;      // entry j's q
    reg [P*P-1:0]          s1_before; // bit P j + i: entry j comes before entry i (nearer, or as near and lower)
    reg [CLASS_W-1:0]      s1_nearest;
    /* verilator lint_off UNUSEDSIGNAL */  // compared at CMP_W bits, above which it is zero
    reg signed [63:0] d_end;
    /* verilator lint_on UNUSEDSIGNAL */
    reg [7:0]         ad_y, ad_cb, ad_cr;
    reg signed [9:0]  w_y, w_cb, w_cr;
    reg signed [19:0] dot;
    /* verilator lint_off UNUSEDSIGNAL */  // products by addition: only the product's bits are used
    reg signed [63:0] wy_ad;
    /* verilator lint_on UNUSEDSIGNAL */
    reg [PROD_W-1:0]  q_wide;
    reg [CMP_W-1:0]   d_j, d_i;
    reg               first;
    always @* begin
        for (j = 0; j < P; j = j + 1) begin
            ad_y = byte_gap(lum, palette_y[j*8 +: 8]);
            ad_cb = byte_gap(cb, palette_cb[j*8 +: 8]);
            ad_cr = byte_gap(cr, palette_cr[j*8 +: 8]);
            wy_ad = mul_by_addition($signed({56'd0, ad_y}), W_Y, LUMA_WEIGHT_W + 1);
            d_end = $signed({{(64 - LUMA_WEIGHT_W - 8){1'b0}}, wy_ad[LUMA_WEIGHT_W+7:0]}) + (($signed({56'd0, ad_cb}) + $signed({56'd0, ad_cr})) <<< FW);
            s1_d_end[j*CMP_W +: CMP_W] = d_end[CMP_W-1:0];
            w_y = $signed({2'b00, palette_y[j*8 +: 8]}) - bi_y;  // entry - background, both in 0..255
            w_cb = $signed({2'b00, palette_cb[j*8 +: 8]}) - bi_cb;
            w_cr = $signed({2'b00, palette_cr[j*8 +: 8]}) - bi_cr;
            dot = u_y10 * w_y + u_cb10 * w_cb + u_cr10 * w_cr;  // three DSP blocks: by addition they cost more cells than the part spares
            q_wide = {{(PROD_W - 18){1'b0}}, dot[17:0]} * {{(PROD_W - INV_WW_W){1'b0}}, inv_ww[j*INV_WW_W +: INV_WW_W]};
            // mixing_q, clamped to 1
            s1_q[j*MIXING_Q_W +: MIXING_Q_W] = dot <= 20'sd0 ? {MIXING_Q_W{1'b0}}
                : (q_wide[PROD_W-1:QF] > {{(PROD_W - QF - MIXING_Q_W){1'b0}}, ONE_Q} ? ONE_Q : q_wide[QF +: MIXING_Q_W]);
        end
        // The order: what the model's scan in index order with a strict "<" keeps.
        s1_nearest = {CLASS_W{1'b0}};
        for (j = 0; j < P; j = j + 1) begin
            first = 1'b1;
            for (i = 0; i < P; i = i + 1) begin
                d_j = s1_d_end[j*CMP_W +: CMP_W];
                d_i = s1_d_end[i*CMP_W +: CMP_W];
                s1_before[j*P + i] = i == j ? 1'b0 : (d_j < d_i || (d_j == d_i && j < i));
                if (i != j && !s1_before[j*P + i])
                    first = 1'b0;
            end
            if (first)
                s1_nearest = j[CLASS_W-1:0];
        end
    end

    // |e - BG|_1 from the exact background, rounded half up.
    wire signed [63:0] contrast = (abs64((e_y <<< FB) - b_y) + abs64((e_cb <<< FB) - b_cb) + abs64((e_cr <<< FB) - b_cr)
                                   + (64'sd1 <<< (FB - 1))) >>> FB;
    wire [VOTE_W-1:0] s1_vote = vote_contrast ? contrast[VOTE_W-1:0] : {{(VOTE_W - 1){1'b0}}, 1'b1};

    // ------------------------------------------------ the pipeline register (STAGES = 2)
    localparam integer S2_W = 6 * 10 + P * CMP_W + P * MIXING_Q_W + P * P + CLASS_W + VOTE_W;
    wire [S2_W-1:0] s2_in = {u_y10, u_cb10, u_cr10, bi_y, bi_cb, bi_cr, s1_d_end, s1_q, s1_before, s1_nearest, s1_vote};
    wire [S2_W-1:0] s2;
    evclust_stage_reg #(.W(S2_W), .STAGES(STAGES)) stage_2 (.clk(clk), .rst(rst), .advance(advance), .d(s2_in), .q(s2));
    wire signed [9:0]      s2_u_y, s2_u_cb, s2_u_cr;
    wire [9:0]             s2_bi_y, s2_bi_cb, s2_bi_cr;  // the background's integer colour (0..255)
    wire [P*CMP_W-1:0]     s2_d_end;
    wire [P*MIXING_Q_W-1:0] s2_q;
    wire [P*P-1:0]         s2_before;
    wire [CLASS_W-1:0]     s2_nearest;
    assign {s2_u_y, s2_u_cb, s2_u_cr, s2_bi_y, s2_bi_cb, s2_bi_cr, s2_d_end, s2_q, s2_before, s2_nearest, vote} = s2;

    // ------------------------------------------------ stage 2: the segments, the choice
    reg [MIXING_Q_W-1:0]   q;
    reg signed [9:0]       v_y, v_cb, v_cr;
    reg signed [RES_W-1:0] r_y, r_cb, r_cr;
    reg signed [63:0]      a_y, a_cb, a_cr;
    /* verilator lint_off UNUSEDSIGNAL */  // products by addition: only the product's bits are used; d_line compared at CMP_W bits
    reg signed [63:0]      qw_y, qw_cb, qw_cr, wy_t, d_line;
    /* verilator lint_on UNUSEDSIGNAL */
    reg [CMP_W-1:0]        d_line_c;
    reg [P-1:0]            in_tolerance;  // entry j's segment passes within the tolerance
    reg [CLASS_W-1:0]      mixed;
    reg                    chosen;
    always @* begin
        for (j = 0; j < P; j = j + 1) begin
            v_y = $signed({2'b00, palette_y[j*8 +: 8]}) - $signed(s2_bi_y);
            v_cb = $signed({2'b00, palette_cb[j*8 +: 8]}) - $signed(s2_bi_cb);
            v_cr = $signed({2'b00, palette_cr[j*8 +: 8]}) - $signed(s2_bi_cr);
            q = s2_q[j*MIXING_Q_W +: MIXING_Q_W];
            if (j < DSP_ENTRIES) begin  // a multiplier block each (one 18x18 holds q by w's 10 bits)
                qw_y = $signed({{(64 - MIXING_Q_W){1'b0}}, q}) * $signed({{54{v_y[9]}}, v_y});
                qw_cb = $signed({{(64 - MIXING_Q_W){1'b0}}, q}) * $signed({{54{v_cb[9]}}, v_cb});
                qw_cr = $signed({{(64 - MIXING_Q_W){1'b0}}, q}) * $signed({{54{v_cr[9]}}, v_cr});
            end else begin
                qw_y = mul_by_addition($signed({{(64 - MIXING_Q_W){1'b0}}, q}), {{54{v_y[9]}}, v_y}, 10);
                qw_cb = mul_by_addition($signed({{(64 - MIXING_Q_W){1'b0}}, q}), {{54{v_cb[9]}}, v_cb}, 10);
                qw_cr = mul_by_addition($signed({{(64 - MIXING_Q_W){1'b0}}, q}), {{54{v_cr[9]}}, v_cr}, 10);
            end
            r_y = ($signed({{(RES_W - 10){s2_u_y[9]}}, s2_u_y}) <<< QF) - qw_y[RES_W-1:0];
            r_cb = ($signed({{(RES_W - 10){s2_u_cb[9]}}, s2_u_cb}) <<< QF) - qw_cb[RES_W-1:0];
            r_cr = ($signed({{(RES_W - 10){s2_u_cr[9]}}, s2_u_cr}) <<< QF) - qw_cr[RES_W-1:0];
            // |r| of a RES_W-bit r fits RES_W bits: the product with w_Y stays a small multiplier.
            a_y = $signed({{(64 - RES_W){1'b0}}, residual_size(r_y)});
            a_cb = $signed({{(64 - RES_W){1'b0}}, residual_size(r_cb)});
            a_cr = $signed({{(64 - RES_W){1'b0}}, residual_size(r_cr)});
            wy_t = mul_by_addition(a_y, W_Y, LUMA_WEIGHT_W + 1);
            d_line = ($signed({{(64 - LUMA_WEIGHT_W - RES_W){1'b0}}, wy_t[LUMA_WEIGHT_W+RES_W-1:0]}) + ((a_cb + a_cr) <<< FW)) >>> QF;
            d_line_c = background_mask[j] ? s2_d_end[j*CMP_W +: CMP_W] : d_line[CMP_W-1:0];
            in_tolerance[j] = d_line_c <= TOLERANCE_C;
        end
        // The entry within the tolerance that comes before every other within it.
        mixed = {CLASS_W{1'b0}};
        for (j = 0; j < P; j = j + 1) begin
            chosen = in_tolerance[j];
            for (i = 0; i < P; i = i + 1)
                if (i != j && in_tolerance[i] && !s2_before[j*P + i])
                    chosen = 1'b0;
            if (chosen)
                mixed = j[CLASS_W-1:0];
        end
        class_index = (mixing && in_tolerance != {P{1'b0}}) ? mixed : s2_nearest;
    end
endmodule
`default_nettype wire
