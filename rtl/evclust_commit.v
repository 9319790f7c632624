// evclust_commit: step 3's write half (model: fixed_model._commit), one slot's update landing:
// its increments (evclust_update) added to the slot as it is now, each sum saturated to its
// format; the activity (decayed to the event's time by evclust_decay) plus one; the palette
// vote counted, halving the row when a counter reaches the top; the event counted. With no
// pipeline delay the state is the one the increments came from and no saturation can act.
//
// Widths and fraction bits are the header's (evclust_params.vh), so the ports are declared after it.
`default_nettype none
module evclust_commit (
    act_decayed, px, py, rx, ry, vmx, vmy, norm, col_y, col_cb, col_cr, hist, ev_count,
    d_px, d_py, d_rx, d_ry, d_vmx, d_vmy, d_norm, d_col_y, d_col_cb, d_col_cr, class_index, vote,
    r_min, r_max,
    act_out, px_out, py_out, rx_out, ry_out, vmx_out, vmy_out, norm_out, col_y_out, col_cb_out, col_cr_out, hist_out, ev_count_out,
    act_saturations, vm_saturations, ev_count_saturations
);
`include "evclust_params.vh"
`include "evclust_arith.vh"
`include "evclust_increments.vh"
    localparam integer P = PALETTE_SIZE;
    localparam integer CLASS_W = P > 1 ? $clog2(P) : 1;
    // The slot now (its activity already decayed to the event's time).
    input  wire [ACTIVITY_W-1:0]           act_decayed;
    input  wire [CENTRE_W-1:0]             px, py;
    input  wire [HALF_SIZE_W-1:0]          rx, ry;
    input  wire [V_MCM_W-1:0]              vmx, vmy;  // signed
    input  wire [MCM_NORM_W-1:0]           norm;
    input  wire [COLOUR_W-1:0]             col_y, col_cb, col_cr;
    input  wire [P*HIST_W-1:0]             hist;      // entry j in bits [j*HIST_W +: HIST_W]
    input  wire [EVENTS_IN_INTERVAL_W-1:0] ev_count;
    // The event's update.
    input  wire signed [DP_W-1:0]          d_px, d_py;
    input  wire signed [DR_W-1:0]          d_rx, d_ry;
    input  wire signed [DV_W-1:0]          d_vmx, d_vmy;
    input  wire signed [DN_W-1:0]          d_norm;
    input  wire signed [DC_W-1:0]          d_col_y, d_col_cb, d_col_cr;
    input  wire [CLASS_W-1:0]              class_index;
    input  wire [VOTE_W-1:0]               vote;
    input  wire [CFG_R_MIN_W-1:0]          r_min;
    input  wire [CFG_R_MAX_W-1:0]          r_max;
    // The slot after.
    output wire [ACTIVITY_W-1:0]           act_out;
    output wire [CENTRE_W-1:0]             px_out, py_out;
    output wire [HALF_SIZE_W-1:0]          rx_out, ry_out;
    output wire [V_MCM_W-1:0]              vmx_out, vmy_out;
    output wire [MCM_NORM_W-1:0]           norm_out;
    output wire [COLOUR_W-1:0]             col_y_out, col_cb_out, col_cr_out;
    output reg  [P*HIST_W-1:0]             hist_out;
    output wire [EVENTS_IN_INTERVAL_W-1:0] ev_count_out;
    // Saturations, for the status counters.
    output wire [1:0]                      act_saturations, vm_saturations, ev_count_saturations;

    localparam signed [63:0] ONE_A = 64'sd1 <<< ACTIVITY_FRAC, MAX_ACT = (64'sd1 <<< ACTIVITY_W) - 1;
    localparam signed [63:0] MAX_P = (64'sd1 <<< CENTRE_W) - 1, MAX_C = (64'sd1 <<< COLOUR_W) - 1;
    localparam signed [63:0] MAX_V = (64'sd1 <<< (V_MCM_W - 1)) - 1, MIN_V = -(64'sd1 <<< (V_MCM_W - 1));
    localparam signed [63:0] ONE_W = 64'sd1 <<< MCM_NORM_FRAC;  // w = 1 - alpha^n never passes 1
    localparam signed [63:0] MAX_EVCOUNT = (64'sd1 <<< EVENTS_IN_INTERVAL_W) - 1;
    localparam signed [63:0] H_MAX = (64'sd1 <<< HIST_W) - 1;

    wire signed [63:0] k_r_min = u64({{(63 - CFG_R_MIN_W){1'b0}}, r_min}), k_r_max = u64({{(63 - CFG_R_MAX_W){1'b0}}, r_max});
    wire signed [63:0] act_full = u64({{(63 - ACTIVITY_W){1'b0}}, act_decayed}) + ONE_A;
    wire signed [63:0] p_x = saturate(u64({{(63 - CENTRE_W){1'b0}}, px}) + $signed({{(64 - DP_W){d_px[DP_W-1]}}, d_px}), 0, MAX_P);
    wire signed [63:0] p_y = saturate(u64({{(63 - CENTRE_W){1'b0}}, py}) + $signed({{(64 - DP_W){d_py[DP_W-1]}}, d_py}), 0, MAX_P);
    wire signed [63:0] r_x = saturate(u64({{(63 - HALF_SIZE_W){1'b0}}, rx}) + $signed({{(64 - DR_W){d_rx[DR_W-1]}}, d_rx}), k_r_min, k_r_max);
    wire signed [63:0] r_y = saturate(u64({{(63 - HALF_SIZE_W){1'b0}}, ry}) + $signed({{(64 - DR_W){d_ry[DR_W-1]}}, d_ry}), k_r_min, k_r_max);
    wire signed [63:0] v_x_full = $signed({{(64 - V_MCM_W){vmx[V_MCM_W-1]}}, vmx}) + $signed({{(64 - DV_W){d_vmx[DV_W-1]}}, d_vmx});
    wire signed [63:0] v_y_full = $signed({{(64 - V_MCM_W){vmy[V_MCM_W-1]}}, vmy}) + $signed({{(64 - DV_W){d_vmy[DV_W-1]}}, d_vmy});
    wire signed [63:0] w = saturate(u64({{(63 - MCM_NORM_W){1'b0}}, norm}) + $signed({{(64 - DN_W){d_norm[DN_W-1]}}, d_norm}), 0, ONE_W);
    wire signed [63:0] c_y = saturate(u64({{(63 - COLOUR_W){1'b0}}, col_y}) + $signed({{(64 - DC_W){d_col_y[DC_W-1]}}, d_col_y}), 0, MAX_C);
    wire signed [63:0] c_cb = saturate(u64({{(63 - COLOUR_W){1'b0}}, col_cb}) + $signed({{(64 - DC_W){d_col_cb[DC_W-1]}}, d_col_cb}), 0, MAX_C);
    wire signed [63:0] c_cr = saturate(u64({{(63 - COLOUR_W){1'b0}}, col_cr}) + $signed({{(64 - DC_W){d_col_cr[DC_W-1]}}, d_col_cr}), 0, MAX_C);
    wire signed [63:0] ev_count_full = u64({{(63 - EVENTS_IN_INTERVAL_W){1'b0}}, ev_count}) + 64'sd1;
    wire signed [63:0] act = saturate(act_full, 0, MAX_ACT);
    wire signed [63:0] v_x = saturate(v_x_full, MIN_V, MAX_V), v_y = saturate(v_y_full, MIN_V, MAX_V);
    wire signed [63:0] evc = saturate(ev_count_full, 0, MAX_EVCOUNT);

    // The palette vote: a saturating counter; reaching the top halves the row.
    reg signed [63:0] counted [0:P-1];
    reg               halve;
    reg signed [63:0] kept;
    integer j;
    always @* begin
        for (j = 0; j < P; j = j + 1)
            counted[j] = u64({{(63 - HIST_W){1'b0}}, hist[j*HIST_W +: HIST_W]});
        counted[class_index] = min64(counted[class_index] + u64({{(63 - VOTE_W){1'b0}}, vote}), H_MAX);
        halve = counted[class_index] >= H_MAX;
        for (j = 0; j < P; j = j + 1) begin
            kept = halve ? counted[j] >>> 1 : counted[j];
            hist_out[j*HIST_W +: HIST_W] = kept[HIST_W-1:0];
        end
    end

    assign act_out = act[ACTIVITY_W-1:0];
    assign px_out = p_x[CENTRE_W-1:0];
    assign py_out = p_y[CENTRE_W-1:0];
    assign rx_out = r_x[HALF_SIZE_W-1:0];
    assign ry_out = r_y[HALF_SIZE_W-1:0];
    assign vmx_out = v_x[V_MCM_W-1:0];
    assign vmy_out = v_y[V_MCM_W-1:0];
    assign norm_out = w[MCM_NORM_W-1:0];
    assign col_y_out = c_y[COLOUR_W-1:0];
    assign col_cb_out = c_cb[COLOUR_W-1:0];
    assign col_cr_out = c_cr[COLOUR_W-1:0];
    assign ev_count_out = evc[EVENTS_IN_INTERVAL_W-1:0];
    assign act_saturations = outside(act_full, 0, MAX_ACT);
    assign vm_saturations = outside(v_x_full, MIN_V, MAX_V) + outside(v_y_full, MIN_V, MAX_V);
    assign ev_count_saturations = outside(ev_count_full, 0, MAX_EVCOUNT);
endmodule
`default_nettype wire
