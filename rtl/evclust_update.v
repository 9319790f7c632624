// evclust_update: step 3's read half (model: fixed_model._increments), one slot's update from
// the state the event reads. For each alpha filter, its new value (what a core without pipeline
// semantics writes) and its increment, the new value minus the state read (what a pipelined
// core commits later, evclust_commit). The palette's class and vote are evclust_palette's; the
// activity, histogram and event count are counted by the commit.
//
// STAGES = 2: a register (enabled by `advance`) cuts the chain of multiplies after the first
// (beta_P (e - P), g_R |e - P| and the colours'), so the size's alpha step, gamma * step and V's
// alpha step come one advance later, from the registered operands: the increments then belong
// to the event of the last advance (a pipelined core with update_delay = 2), and the new values
// are not given (only a core without delay writes them). The step saturations count the current
// event (stage 1), the MCM ones the registered one (stage 2).
//
// Widths and fraction bits are the header's (evclust_params.vh), so the ports are declared after
// it; the constants are the run-time registers' (or the header's when they are built in).
`default_nettype none
module evclust_update #(
    parameter integer STAGES = 1  // 1: combinational; 2: one pipeline register
) (
    clk, advance,
    ev_x, ev_y, lum, cb, cr,
    px, py, rx, ry, gamma, vmx, vmy, norm, col_y, col_cb, col_cr,
    beta_pos, size_gain, beta_size, r_min, r_max, beta_vel_mcm, beta_lum, beta_chro,
    px_new, py_new, rx_new, ry_new, vmx_new, vmy_new, norm_new, col_y_new, col_cb_new, col_cr_new,
    d_px, d_py, d_rx, d_ry, d_vmx, d_vmy, d_norm, d_col_y, d_col_cb, d_col_cr,
    step_saturations, mcm_saturations
);
`include "evclust_params.vh"
`include "evclust_arith.vh"
`include "evclust_increments.vh"
    input  wire                          clk, advance;  // STAGES = 2 only
    // The event.
    input  wire [EV_XY_W-1:0]            ev_x, ev_y;
    input  wire [EV_COLOUR_W-1:0]        lum, cb, cr;
    // The slot as the event reads it.
    input  wire [CENTRE_W-1:0]           px, py;
    input  wire [HALF_SIZE_W-1:0]        rx, ry;
    input  wire [GAMMA_W-1:0]            gamma;
    input  wire [V_MCM_W-1:0]            vmx, vmy;  // signed
    input  wire [MCM_NORM_W-1:0]         norm;
    input  wire [COLOUR_W-1:0]           col_y, col_cb, col_cr;
    // Constants.
    input  wire [CFG_BETA_POS_W-1:0]     beta_pos;
    input  wire [CFG_SIZE_GAIN_W-1:0]    size_gain;
    input  wire [CFG_BETA_SIZE_W-1:0]    beta_size;
    input  wire [CFG_R_MIN_W-1:0]        r_min;
    input  wire [CFG_R_MAX_W-1:0]        r_max;
    input  wire [CFG_BETA_VEL_MCM_W-1:0] beta_vel_mcm;
    input  wire [CFG_BETA_LUM_W-1:0]     beta_lum;
    input  wire [CFG_BETA_CHRO_W-1:0]    beta_chro;
    // New values (the size clamped to [R_min, R_max]) and increments.
    output wire [CENTRE_W-1:0]           px_new, py_new;
    output wire [HALF_SIZE_W-1:0]        rx_new, ry_new;
    output wire [V_MCM_W-1:0]            vmx_new, vmy_new;
    output wire [MCM_NORM_W-1:0]         norm_new;
    output wire [COLOUR_W-1:0]           col_y_new, col_cb_new, col_cr_new;
    output wire signed [DP_W-1:0]        d_px, d_py;
    output wire signed [DR_W-1:0]        d_rx, d_ry;  // the size's before its clamp (the commit clamps)
    output wire signed [DV_W-1:0]        d_vmx, d_vmy;
    output wire signed [DN_W-1:0]        d_norm;
    output wire signed [DC_W-1:0]        d_col_y, d_col_cb, d_col_cr;
    // How many of the two axes' values saturated (the status counters).
    output wire [1:0]                    step_saturations;  // P_new - P to centre_step's format
    output wire [1:0]                    mcm_saturations;   // gamma * step to V's format

    localparam integer FP = CENTRE_FRAC, FR = HALF_SIZE_FRAC, FV = V_MCM_FRAC, FW = MCM_NORM_FRAC;
    localparam integer FC = COLOUR_FRAC, FG = GAMMA_FRAC;
    localparam signed [63:0] MAX_V = (64'sd1 <<< (V_MCM_W - 1)) - 1, MIN_V = -(64'sd1 <<< (V_MCM_W - 1));
    localparam signed [63:0] MAX_STEP = (64'sd1 <<< (CENTRE_STEP_W - 1)) - 1, MIN_STEP = -(64'sd1 <<< (CENTRE_STEP_W - 1));

    wire signed [63:0] k_b_pos = u64({{(63 - CFG_BETA_POS_W){1'b0}}, beta_pos}), k_gain = u64({{(63 - CFG_SIZE_GAIN_W){1'b0}}, size_gain}), k_b_size = u64({{(63 - CFG_BETA_SIZE_W){1'b0}}, beta_size});
    wire signed [63:0] k_r_min = u64({{(63 - CFG_R_MIN_W){1'b0}}, r_min}), k_r_max = u64({{(63 - CFG_R_MAX_W){1'b0}}, r_max}), k_b_vm = u64({{(63 - CFG_BETA_VEL_MCM_W){1'b0}}, beta_vel_mcm});
    wire signed [63:0] k_b_lum = u64({{(63 - CFG_BETA_LUM_W){1'b0}}, beta_lum}), k_b_chro = u64({{(63 - CFG_BETA_CHRO_W){1'b0}}, beta_chro});
    wire signed [63:0] ex = u64({{(63 - EV_XY_W){1'b0}}, ev_x}), ey = u64({{(63 - EV_XY_W){1'b0}}, ev_y});
    wire signed [63:0] p_x = u64({{(63 - CENTRE_W){1'b0}}, px}), p_y = u64({{(63 - CENTRE_W){1'b0}}, py});
    wire signed [63:0] w = u64({{(63 - MCM_NORM_W){1'b0}}, norm});
    wire signed [63:0] c_y = u64({{(63 - COLOUR_W){1'b0}}, col_y}), c_cb = u64({{(63 - COLOUR_W){1'b0}}, col_cb}), c_cr = u64({{(63 - COLOUR_W){1'b0}}, col_cr});

    // 3b. Centre: P += beta_P (e - P), the event in P's format with all its fraction bits as guard.
    wire signed [63:0] p_x_new = alpha_step(p_x, ex, k_b_pos, BETA_POS_FRAC, FP, 1'b0);
    wire signed [63:0] p_y_new = alpha_step(p_y, ey, k_b_pos, BETA_POS_FRAC, FP, 1'b0);
    // 3c. Size: R += beta_R (g_R |e - P| - R), |e - P| in the offset format; the product fits
    // size_target (|e - P| < 2^coord, g_R < 2^bits(g_R)), so no saturation.
    wire signed [63:0] o_x = abs64((ex <<< FP) - p_x);
    wire signed [63:0] o_y = abs64((ey <<< FP) - p_y);
    wire signed [63:0] g_x = (u64({{(64 - OFFSET_W){1'b0}}, o_x[OFFSET_W-2:0]}) * k_gain) >>> (SIZE_GAIN_FRAC + FP - FR);
    wire signed [63:0] g_y = (u64({{(64 - OFFSET_W){1'b0}}, o_y[OFFSET_W-2:0]}) * k_gain) >>> (SIZE_GAIN_FRAC + FP - FR);
    // (The size's alpha step is stage 2's, below.)
    // 3d. MCM: V += beta_vm (gamma (P_new - P) - V), the step saturated to centre_step's format
    // (so gamma * step is 22 x 22 bits) and gamma * step to V's. Rounded to nearest: V's input
    // is at V's own LSB. The same filter on the integer 1 gives the bias-correction weight.
    wire signed [63:0] step_x_full = p_x_new - p_x, step_y_full = p_y_new - p_y;
    wire signed [63:0] step_x = saturate(step_x_full, MIN_STEP, MAX_STEP), step_y = saturate(step_y_full, MIN_STEP, MAX_STEP);
    wire signed [63:0] w_new = alpha_step(w, 64'sd1, k_b_vm, BETA_VEL_MCM_FRAC, FW, 1'b1);
    // 3e. Colour: three alpha filters, the event's byte with all of C's fraction bits as guard.
    wire signed [63:0] c_y_new = alpha_step(c_y, u64({{(63 - EV_COLOUR_W){1'b0}}, lum}), k_b_lum, BETA_LUM_FRAC, FC, 1'b0);
    wire signed [63:0] c_cb_new = alpha_step(c_cb, u64({{(63 - EV_COLOUR_W){1'b0}}, cb}), k_b_chro, BETA_CHRO_FRAC, FC, 1'b0);
    wire signed [63:0] c_cr_new = alpha_step(c_cr, u64({{(63 - EV_COLOUR_W){1'b0}}, cr}), k_b_chro, BETA_CHRO_FRAC, FC, 1'b0);
    wire signed [63:0] i_px = p_x_new - p_x, i_py = p_y_new - p_y, i_norm = w_new - w;
    wire signed [63:0] i_cy = c_y_new - c_y, i_ccb = c_cb_new - c_cb, i_ccr = c_cr_new - c_cr;

    // ------------------------------------------------ the pipeline register (STAGES = 2)
    // Stage 2's operands: the step, g_R |e - P|, and the states its alpha steps start from.
    wire [CENTRE_STEP_W-1:0] s2_step_x, s2_step_y;
    wire [SIZE_TARGET_W-1:0] s2_g_x, s2_g_y;  // g_R |e - P| fits size_target (above)
    wire [HALF_SIZE_W-1:0]   s2_r_x, s2_r_y;
    wire [GAMMA_W-1:0]       s2_gamma;
    wire [V_MCM_W-1:0]       s2_v_x, s2_v_y;
    wire [DP_W-1:0]          s2_d_px, s2_d_py;
    wire [DN_W-1:0]          s2_d_norm;
    wire [DC_W-1:0]          s2_d_cy, s2_d_ccb, s2_d_ccr;
    localparam integer S2_W = 2 * CENTRE_STEP_W + 2 * SIZE_TARGET_W + 2 * HALF_SIZE_W + GAMMA_W + 2 * V_MCM_W + 2 * DP_W + DN_W + 3 * DC_W;
    wire [S2_W-1:0] s2_in = {step_x[CENTRE_STEP_W-1:0], step_y[CENTRE_STEP_W-1:0], g_x[SIZE_TARGET_W-1:0], g_y[SIZE_TARGET_W-1:0],
                             rx, ry, gamma, vmx, vmy, i_px[DP_W-1:0], i_py[DP_W-1:0], i_norm[DN_W-1:0],
                             i_cy[DC_W-1:0], i_ccb[DC_W-1:0], i_ccr[DC_W-1:0]};
    wire [S2_W-1:0] s2;
    // No reset: stage 2's increments are committed only for an event that advanced into it.
    evclust_stage_reg #(.W(S2_W), .STAGES(STAGES)) stage_2 (.clk(clk), .rst(1'b0), .advance(advance), .d(s2_in), .q(s2));
    assign {s2_step_x, s2_step_y, s2_g_x, s2_g_y, s2_r_x, s2_r_y, s2_gamma, s2_v_x, s2_v_y, s2_d_px, s2_d_py, s2_d_norm,
            s2_d_cy, s2_d_ccb, s2_d_ccr} = s2;

    // ------------------------------------------------ stage 2: the size's and V's alpha steps
    wire signed [63:0] q_r_x = u64({{(63 - HALF_SIZE_W){1'b0}}, s2_r_x}), q_r_y = u64({{(63 - HALF_SIZE_W){1'b0}}, s2_r_y});
    wire signed [63:0] q_v_x = $signed({{(64 - V_MCM_W){s2_v_x[V_MCM_W-1]}}, s2_v_x}), q_v_y = $signed({{(64 - V_MCM_W){s2_v_y[V_MCM_W-1]}}, s2_v_y});
    wire signed [63:0] r_x_step = alpha_step(q_r_x, u64({{(63 - SIZE_TARGET_W){1'b0}}, s2_g_x}), k_b_size, BETA_SIZE_FRAC, 0, 1'b0);
    wire signed [63:0] r_y_step = alpha_step(q_r_y, u64({{(63 - SIZE_TARGET_W){1'b0}}, s2_g_y}), k_b_size, BETA_SIZE_FRAC, 0, 1'b0);
    wire signed [63:0] k_gamma = u64({{(63 - GAMMA_W){1'b0}}, s2_gamma});
    wire signed [63:0] u_x_full = align(k_gamma * $signed({{(64 - CENTRE_STEP_W){s2_step_x[CENTRE_STEP_W-1]}}, s2_step_x}), FG + FP, FV);
    wire signed [63:0] u_y_full = align(k_gamma * $signed({{(64 - CENTRE_STEP_W){s2_step_y[CENTRE_STEP_W-1]}}, s2_step_y}), FG + FP, FV);
    wire signed [63:0] u_x = saturate(u_x_full, MIN_V, MAX_V), u_y = saturate(u_y_full, MIN_V, MAX_V);
    wire signed [63:0] v_x_new = alpha_step(q_v_x, u_x, k_b_vm, BETA_VEL_MCM_FRAC, 0, 1'b1);
    wire signed [63:0] v_y_new = alpha_step(q_v_y, u_y, k_b_vm, BETA_VEL_MCM_FRAC, 0, 1'b1);

    assign px_new = p_x_new[CENTRE_W-1:0];
    assign py_new = p_y_new[CENTRE_W-1:0];
    wire signed [63:0] r_x_new = saturate(r_x_step, k_r_min, k_r_max), r_y_new = saturate(r_y_step, k_r_min, k_r_max);
    assign rx_new = r_x_new[HALF_SIZE_W-1:0];
    assign ry_new = r_y_new[HALF_SIZE_W-1:0];
    assign vmx_new = v_x_new[V_MCM_W-1:0];
    assign vmy_new = v_y_new[V_MCM_W-1:0];
    assign norm_new = w_new[MCM_NORM_W-1:0];
    assign col_y_new = c_y_new[COLOUR_W-1:0];
    assign col_cb_new = c_cb_new[COLOUR_W-1:0];
    assign col_cr_new = c_cr_new[COLOUR_W-1:0];

    wire signed [63:0] i_rx = r_x_step - q_r_x, i_ry = r_y_step - q_r_y, i_vmx = v_x_new - q_v_x, i_vmy = v_y_new - q_v_y;
    assign d_px = s2_d_px;
    assign d_py = s2_d_py;
    assign d_rx = i_rx[DR_W-1:0];
    assign d_ry = i_ry[DR_W-1:0];
    assign d_vmx = i_vmx[DV_W-1:0];
    assign d_vmy = i_vmy[DV_W-1:0];
    assign d_norm = s2_d_norm;
    assign d_col_y = s2_d_cy;
    assign d_col_cb = s2_d_ccb;
    assign d_col_cr = s2_d_ccr;

    assign step_saturations = outside(step_x_full, MIN_STEP, MAX_STEP) + outside(step_y_full, MIN_STEP, MAX_STEP);
    assign mcm_saturations = outside(u_x_full, MIN_V, MAX_V) + outside(u_y_full, MIN_V, MAX_V);
endmodule
`default_nettype wire
