// evclust_core: the event-by-event colour clusterer, bit for bit the fixed-point model
// (model/evclust/fixed/fixed_model.py; docs/RTL.md walks through the datapath).
//
// Streams: events in (valid/ready, the word of vectors/*/events.hex), track records out
// (valid/ready, the word of expected.hex), the end of each filter step (valid/ready with the
// step's time, after its last record has been taken: what the object unit, evclust_objects,
// waits for) and a trace of each event's action (a monitor port without back-pressure, the word
// of trace.hex). Reset is synchronous and active high.
//
// Schedule: one event per clock in steady state. Stage A holds an accepted event while all N
// slots are searched in parallel; stage B (EXEC) applies it, while stage A searches for the
// next (docs/RTL.md: the one-event-per-clock pipeline). An event that finds no slot and no
// free one scans the N slots for the weakest (N + 1 cycles more). Every FILTER_EVERY events the
// filter step counts the tau boundaries (PHASE: 1 cycle, or two iterative divisions when two or
// more passed), sweeps the table one slot per cycle while the mixing palette's 1/|w|^2 entries
// are refreshed alongside, and drains the sweep's tail (exit, report and record TAIL cycles
// behind the slot): 1 + max(N, PALETTE_SIZE) + TAIL cycles plus output stalls, plus
// MERGE_MOMENT_W + 3 cycles per merge (the weighted centre's iterative division). After a
// reset, INIT fills the mixing table and clears the creation-support map.
//
// N, every width and every constant come from evclust_params.vh, generated from the model's
// formats table (`evclust formats --verilog`).
`default_nettype none
`include "evclust_require.vh"
module evclust_core #(
`define EVCLUST_PORT_PARAMETERS
`include "evclust_params.vh"
`undef EVCLUST_PORT_PARAMETERS
,
    // 1: the constants come from `cfg` (the register file); 0: from the header (CFG_RESET),
    // `cfg` unread, so synthesis folds them into the datapath: the smaller core, one parameter set.
    parameter integer RUNTIME_CONFIG = 1,
    // The palette entries whose mixing products take multiplier blocks, three an entry (the rest
    // are shifted additions, some 600 logic cells a product; the results are the same): six
    // for the LFE5U-85F, whose 156 leave that many beside the rest of the core (137 in the
    // defaults' build); a part with fewer blocks than logic to spare sets fewer.
    parameter integer MIXING_DSP = 6
) (
    input  wire               clk,
    input  wire               rst,
    input  wire               clear,          // restart the datapath: a reset that spares the configuration
    input  wire [CFG_W-1:0]   cfg,            // the configuration block (evclust_regs; CFG_* word indices)
    input  wire               ev_valid,
    output wire               ev_ready,
    input  wire [EV_W-1:0]    ev_data,
    output reg                rec_valid,
    input  wire               rec_ready,
    output reg  [REC_W-1:0]   rec_data,
    output reg                trace_valid,
    output reg  [TRACE_W-1:0] trace_data,
    output wire               step_valid,     // a filter step has ended (all its records taken); tie step_ready high if unused
    input  wire               step_ready,
    output reg  [31:0]        step_t,         // its time: the low 32 bits of the event that triggered it
    output wire               filter_active,  // a filter step: its phase cycle(s), sweep, merges and tail
    output wire               idle,           // no event in flight, no filter step, no record waiting
    output reg  [COUNT_W-1:0] count_inc       // what the last cycle adds to each status counter (COUNT_*)
);
`include "evclust_params.vh"
`include "evclust_arith.vh"
`include "evclust_increments.vh"

    // The port parameters must be the header's: they are given for the instantiating design's sake.
    generate
        if (N != N_CLUSTERS || EV_W != IN_WORD_W || REC_W != REC_WORD_W || TRACE_W != TRACE_WORD_W || CFG_W != 32 * CFG_WORDS
            || COUNT_W != N_COUNTERS * COUNTER_INC_W) begin : parameters_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_core: N, EV_W, REC_W, TRACE_W, CFG_W or COUNT_W differs from evclust_params.vh")
        end
    endgenerate

    localparam integer P = PALETTE_SIZE;
    localparam integer SLOT_W = N > 1 ? $clog2(N) : 1;
    localparam integer CLASS_W = P > 1 ? $clog2(P) : 1;
    localparam integer MIXING_DSP_ENTRIES = P < MIXING_DSP ? P : MIXING_DSP;  // MIXING_DSP says why
    localparam integer SWEEP_LEN = N > P ? N : P;
    // The sweep tail: the operand register, the divider's stages (SWEEP_DIV_STEP bits each) and
    // stage T1's register (the squares and the record, so T2's exit and report start from registers).
    localparam integer INV_STAGES = (INV_WW_W + SWEEP_DIV_STEP - 1) / SWEEP_DIV_STEP;  // 2^32 / |w|^2
    localparam integer MCM_TAIL = 2 + (V_MCM_W - 1 + SWEEP_DIV_STEP - 1) / SWEEP_DIV_STEP;
    localparam integer TAIL = MCM_TAIL > INV_STAGES ? MCM_TAIL : INV_STAGES;
    localparam integer SWEEP_W = $clog2(SWEEP_LEN + TAIL + 1);
    localparam integer EVERY_W = $clog2(FILTER_EVERY + 1);


    // The configuration block the datapath reads (CFG_* word indices).
    /* verilator lint_off UNUSEDSIGNAL */  // a field's word holds only its width's bits
    wire [CFG_W-1:0] cfg_used = RUNTIME_CONFIG != 0 ? cfg : CFG_RESET;
    /* verilator lint_on UNUSEDSIGNAL */
    // Its fields, cfg_<register name>, each of its own width (generated from the register map).
`define EVCLUST_CONFIG_FIELDS
`include "evclust_params.vh"
`undef EVCLUST_CONFIG_FIELDS

    // ---------------------------------------------------------------- formats and constants
    localparam integer FP = CENTRE_FRAC, FR = HALF_SIZE_FRAC, FA = ACTIVITY_FRAC, FV = V_MCM_FRAC;
    localparam integer FW = MCM_NORM_FRAC, FI = V_INT_FRAC, FC = COLOUR_FRAC, FB = BACKGROUND_FRAC;
    localparam integer FG = GAMMA_FRAC, FPT_F = FRAME_PER_TAU_FRAC, SQ_F = SPEED_SQ_FRAC;
    localparam integer V_FULL_BITS = V_INT_W - 1 - FI;  // v_int's integer bits: full-scale speed
    localparam signed [63:0] ONE_A = 64'sd1 <<< FA;
    localparam signed [63:0] MAX_ACT = (64'sd1 <<< ACTIVITY_W) - 1;
    // Against a reference time (ACTIVITY_REFERENCE), a slot keeps Ã, the activity scaled up to
    // the reference by up to 2^REFERENCE_HALVINGS: that many integer bits more in its row.
    localparam REFERENCED = ACTIVITY_REFERENCE != 0;
    localparam integer ACT_ROW_W = REFERENCED ? ACTIVITY_W + REFERENCE_HALVINGS : ACTIVITY_W;
    localparam signed [63:0] MAX_ACT_ROW = (64'sd1 <<< ACT_ROW_W) - 1;
    localparam signed [63:0] MAX_GAMMA = (64'sd1 <<< GAMMA_W) - 1;
    localparam signed [63:0] MAX_EVCOUNT = (64'sd1 <<< EVENTS_IN_INTERVAL_W) - 1;
    localparam signed [63:0] MAX_V = (64'sd1 <<< (V_MCM_W - 1)) - 1, MIN_V = -(64'sd1 <<< (V_MCM_W - 1));
    localparam signed [63:0] MAX_VI = (64'sd1 <<< (V_INT_W - 1)) - 1, MIN_VI = -(64'sd1 <<< (V_INT_W - 1));
    // (The update's constants go to evclust_update and evclust_commit as their fields.)
    wire signed [63:0] K_B_VI = $signed({{(64 - CFG_BETA_VEL_INT_W){1'b0}}, cfg_beta_vel_int});
    wire signed [63:0] K_B_BG = $signed({{(64 - CFG_BETA_BG_W){1'b0}}, cfg_beta_bg});
    wire signed [63:0] K_GAMMA_GLOBAL = $signed({{(64 - CFG_GAMMA_GLOBAL_W){1'b0}}, cfg_gamma_global}), K_GPA = $signed({{(64 - CFG_GAMMA_PER_ACTIVITY_W){1'b0}}, cfg_gamma_per_activity});
    wire signed [63:0] K_INV_P = $signed({{(64 - CFG_INV_P_W){1'b0}}, cfg_inv_p});
    wire signed [63:0] K_R_MAX = $signed({{(64 - CFG_R_MAX_W){1'b0}}, cfg_r_max}), K_SEEK = $signed({{(64 - CFG_SEEK_MARGIN_W){1'b0}}, cfg_seek_margin});
    wire signed [63:0] K_EXIT_M = $signed({{(64 - CFG_EXIT_MARGIN_W){1'b0}}, cfg_exit_margin}), K_A_MIN = $signed({{(64 - CFG_A_MIN_W){1'b0}}, cfg_a_min});
    wire signed [63:0] K_A_VALID = $signed({{(64 - CFG_A_VALID_W){1'b0}}, cfg_a_valid}), K_V_MIN_SQ = $signed({{(64 - CFG_V_MIN_SQ_W){1'b0}}, cfg_v_min_sq});
    wire signed [63:0] K_V_EXIT_SQ = $signed({{(64 - CFG_V_EXIT_SQ_W){1'b0}}, cfg_v_exit_sq}), K_COS_SQ = $signed({{(64 - CFG_COS_SQ_EXIT_W){1'b0}}, cfg_cos_sq_exit});
    wire signed [63:0] HI_X = (($signed({32'd0, SENSOR_WIDTH[31:0]}) - 64'sd1) <<< FP) - K_EXIT_M;
    wire signed [63:0] HI_Y = (($signed({32'd0, SENSOR_HEIGHT[31:0]}) - 64'sd1) <<< FP) - K_EXIT_M;
    wire [63:0] TAU = {{(64 - CFG_TAU_US_W){1'b0}}, cfg_tau_us};
    localparam integer LAST_SLOT_I = N - 1, LAST_SWEEP_I = SWEEP_LEN + TAIL - 1;
    localparam [SWEEP_W-1:0] LAST_SLOT = LAST_SLOT_I[SWEEP_W-1:0];
    localparam [SWEEP_W-1:0] LAST_SWEEP = LAST_SWEEP_I[SWEEP_W-1:0];
    localparam integer LAST_INIT_I = P + INV_STAGES - 1;  // the last mixing entry out of its divider
    localparam [SWEEP_W-1:0] LAST_INIT = LAST_INIT_I[SWEEP_W-1:0];
    localparam [SWEEP_W-1:0] N_SLOTS = N[SWEEP_W-1:0], N_ENTRIES = P[SWEEP_W-1:0];
    localparam integer COS_SQ_F = COS_SQ_EXIT_FRAC;
    // One cluster per object (beyond the paper): scaled seek, merging, noise gate, creation support.
    wire signed [63:0] K_SEEK_SCALE = $signed({{(64 - CFG_SEEK_SCALE_W){1'b0}}, cfg_seek_scale});
    wire signed [63:0] K_MERGE_SCALE = $signed({{(64 - CFG_MERGE_SCALE_W){1'b0}}, cfg_merge_scale});
    wire signed [63:0] K_MERGE_V_REL = $signed({{(64 - CFG_MERGE_V_REL_W){1'b0}}, cfg_merge_v_rel});
    wire signed [63:0] K_NOISE_GATE = $signed({{(64 - CFG_NOISE_GATE_W){1'b0}}, cfg_noise_gate});
    wire [31:0] K_SUPPORT_WINDOW = {{(32 - CFG_SUPPORT_WINDOW_W){1'b0}}, cfg_support_window};
    // Run-time values and switches (registers, docs/REGISTERS.md); their widths are the build's.
    wire [INV_T_HALF_W-1:0]    K_INV_T_HALF = cfg_inv_t_half;
    wire [LUMA_WEIGHT_W-1:0]   K_LUMA_WEIGHT = cfg_luma_weight;
    wire [MIXING_TOLERANCE_W-1:0] K_MIXING_TOLERANCE = cfg_mixing_tolerance;
    wire [HALF_SIZE_W-1:0]     K_R_INIT = cfg_r_init;
    wire [FRAME_PER_TAU_W-1:0] K_FRAME_PER_TAU = cfg_frame_per_tau;
    wire [EVERY_W-1:0]         K_FILTER_EVERY = cfg_filter_every;
    wire [1:0]                 gamma_mode = cfg_gamma_mode;
    wire                       warm_start = cfg_warm_start;
    wire                       mcm_correct = cfg_mcm_correct;
    wire                       vote_contrast = cfg_vote_contrast;
    wire                       mixing = cfg_mixing;
    wire                       bg_fixed = cfg_bg_fixed;
    wire [P-1:0]               background_mask = cfg_background_mask;
    wire [BACKGROUND_W-1:0]    bg_init_y = cfg_bg_init_y;
    wire [BACKGROUND_W-1:0]    bg_init_cb = cfg_bg_init_cb;
    wire [BACKGROUND_W-1:0]    bg_init_cr = cfg_bg_init_cr;
    // The palette, entry j in bits [8j +: 8] (its registers are Y, Cb, Cr for each entry in turn).
    wire [8*P-1:0]             palette_y = cfg_palette_y, palette_cb = cfg_palette_cb, palette_cr = cfg_palette_cr;
    localparam signed [63:0] LAST_X = ($signed({32'd0, SENSOR_WIDTH[31:0]}) - 64'sd1) <<< FP;  // the last column, in P's format
    localparam signed [63:0] LAST_Y = ($signed({32'd0, SENSOR_HEIGHT[31:0]}) - 64'sd1) <<< FP;
    localparam signed [63:0] SENSOR_PIXELS = $signed({32'd0, SENSOR_WIDTH[31:0]}) * $signed({32'd0, SENSOR_HEIGHT[31:0]});
    localparam integer UP = FP - FR;  // R to P's fraction bits
    localparam integer VI_COUNT_MAX_I = VI_CAP > 2 ? VI_CAP : 2;  // vi_count saturates here
    localparam integer GAIN_W = BETA_VEL_INT_W;
    localparam [INTERVAL_UPDATES_W-1:0] VI_COUNT_MAX = VI_COUNT_MAX_I[INTERVAL_UPDATES_W-1:0];
    localparam [INTERVAL_UPDATES_W-1:0] VI_WARM_END = VI_CAP[INTERVAL_UPDATES_W-1:0];
    localparam [INTERVAL_UPDATES_W-1:0] VI_NONE = 0, VI_FIRST = 1, VI_MEASURED = 2;
    localparam integer W20_W = MCM_WEIGHT_W;  // w cut to mcm_weight's fraction bits: the divisor

    // The trace's actions, the record's flags, the FSM's states and the phase unit's steps
    // (generated from model/evclust/fixed/enums.py).
`include "evclust_core_enums.vh"

    // Words of the 64-bit datapath from unsigned and signed fields (u64: evclust_arith.vh).

    // A slot's seek window along one axis in P's format: R + S + seek_scale * max(Rx, Ry)
    // (model: _margin), from the larger half-size's product, taken once as the slot is written.
    function automatic signed [63:0] reach;
        input [HALF_SIZE_W-1:0] r;
        input signed [63:0]     seek;
        input signed [63:0]     scaled_r;  // seek_scale * max(Rx, Ry), unaligned
        begin
            reach = (u64({{(63 - HALF_SIZE_W){1'b0}}, r}) <<< (FP - FR)) + seek + align(scaled_r, SEEK_SCALE_FRAC + FR, FP);
        end
    endfunction

    // The interval filter's warm-up gain 1/n (model: FormatTable.warmup_gains), for 2 <= n < VI_CAP.
    function automatic signed [63:0] warmup_gain;
        input [INTERVAL_UPDATES_W-1:0] n;
        integer g;
        reg [GAIN_W-1:0] gain;
        begin
            // A multiplexer over the entries: an index times the entry width would be a multiply
            // that synthesis maps to a DSP block.
            gain = {GAIN_W{1'b0}};
            for (g = 0; g < (1 << INTERVAL_UPDATES_W); g = g + 1)
                if ({{(32 - INTERVAL_UPDATES_W){1'b0}}, n} == g)
                    gain = WARMUP_GAINS[g * GAIN_W +: GAIN_W];
            warmup_gain = $signed({{(64 - GAIN_W){1'b0}}, gain});
        end
    endfunction

    // |V|^2 (model: _speed_sq) from squares taken once per component: each component is
    // clamped to full scale, so its magnitude fits SQ_MAG_W bits and its square a small multiplier.
    // The product is sized to the clamp, which synthesis cannot see: a magnitude of up to 18 bits
    // squares in one 18x18 multiplier; a wider one as lo^2 + 2 hi lo 2^18 + hi^2 2^36, three
    // multipliers where the plain product takes four (the cross term once, doubled by a shift).
    localparam integer SQ_MAG_W = V_FULL_BITS + (FV > FI ? FV : FI);
    localparam integer SQ_TILE = 18;  // a MULT18X18D operand
    localparam integer SQ_HI_W = SQ_MAG_W > SQ_TILE ? SQ_MAG_W - SQ_TILE : 1;
    function automatic [2*SQ_MAG_W-1:0] square;
        input signed [63:0] v;
        input integer frac;
        reg signed [63:0] full, c;
        reg [SQ_MAG_W-1:0] m;
        /* verilator lint_off UNUSEDSIGNAL */  // the bits above lo and hi are zero
        reg [63:0] wide;
        /* verilator lint_on UNUSEDSIGNAL */
        reg [SQ_TILE-1:0] lo;
        reg [SQ_HI_W-1:0] hi;
        reg [2*SQ_MAG_W-1:0] lo_lo, hi_lo, hi_hi;  // each product at the square's width
        begin
            full = (64'sd1 <<< (V_FULL_BITS + frac)) - 1;
            c = abs64(saturate(v, -full, full));
            m = c[SQ_MAG_W-1:0];
            wide = {{(64 - SQ_MAG_W){1'b0}}, m};
            lo = wide[SQ_TILE-1:0];
            hi = wide[SQ_TILE +: SQ_HI_W];
            lo_lo = lo * lo;
            hi_lo = hi * lo;
            hi_hi = hi * hi;
            square = V_FULL_BITS + frac <= SQ_TILE ? lo_lo : lo_lo + (hi_lo << (SQ_TILE + 1)) + (hi_hi << (2 * SQ_TILE));
        end
    endfunction

    // A sum of squares with 2 * frac fraction bits, in speed_sq's format.
    function automatic signed [63:0] speed_sq;
        input [2*SQ_MAG_W:0] sum;
        input integer frac;
        begin
            speed_sq = align($signed({{(63 - 2 * SQ_MAG_W){1'b0}}, sum}), 2 * frac, SQ_F);
        end
    endfunction

    // Eq. (11): BG + (C - BG) / p in C's format, clamped to the byte range (model: _corrected).
    function automatic signed [63:0] corrected;
        input signed [63:0] colour;
        input signed [63:0] background;
        input signed [63:0] inv_p;
        reg signed [63:0] bg, obj;
        begin
            bg = align(background, FB, FC);
            obj = bg + (((colour - bg) * inv_p) >>> INV_P_FRAC);
            corrected = saturate(obj, 0, 64'sd255 <<< FC);
        end
    endfunction

    function automatic signed [63:0] gamma_from_activity;
        input signed [63:0] a;
        input [1:0]         mode;
        input signed [63:0] global_gamma;
        input signed [63:0] per_activity;
        begin
            gamma_from_activity = mode == GAMMA_MODE_GLOBAL[1:0] ? global_gamma : (a * per_activity) >>> (FA + GAMMA_PER_ACTIVITY_FRAC - FG);
        end
    endfunction

    // floor(a / b) for b > 0, as Python's // (the model's MCM bias correction), saturated to
    // V's format: a negative quotient is -ceil(|a| / b) = -((|a| + b - 1) / b). The magnitude's
    // top part decides saturation (a quotient of 2^Q_W or more), and below it the quotient has
    // Q_W bits, which the sweep tail's pipelined divider computes from the rest.
    localparam integer QUOTIENT_W = V_MCM_W + MCM_WEIGHT_FRAC + 1;  // |V << F_w| + b - 1
    localparam integer Q_W = V_MCM_W - 1;          // a quotient that does not saturate
    function automatic [QUOTIENT_W-1:0] floor_magnitude;
        input [V_MCM_W-1:0] v;  // the dividend is v << MCM_WEIGHT_FRAC
        input [W20_W-1:0] b;
        reg signed [63:0] a;
        reg [QUOTIENT_W-1:0] magnitude;
        begin
            a = $signed({{(64 - V_MCM_W){v[V_MCM_W-1]}}, v}) <<< MCM_WEIGHT_FRAC;
            magnitude = a < 0 ? ~a[QUOTIENT_W-1:0] + {{(QUOTIENT_W - 1){1'b0}}, 1'b1} : a[QUOTIENT_W-1:0];
            floor_magnitude = a < 0 ? magnitude + {{(QUOTIENT_W - W20_W){1'b0}}, b} - {{(QUOTIENT_W - 1){1'b0}}, 1'b1} : magnitude;
        end
    endfunction

    // ---------------------------------------------------------------- the cluster table
    reg                            valid         [0:N-1];
    reg [CENTRE_W-1:0]             px            [0:N-1];
    reg [CENTRE_W-1:0]             py            [0:N-1];
    reg [HALF_SIZE_W-1:0]          rx            [0:N-1];
    reg [HALF_SIZE_W-1:0]          ry            [0:N-1];
    reg [V_INT_W-1:0]              vix           [0:N-1];
    reg [V_INT_W-1:0]              viy           [0:N-1];
    reg [INTERVAL_UPDATES_W-1:0]   vi_count      [0:N-1];  // interval measurements + 1, up to the warm-up's end
    reg                            reported      [0:N-1];
    reg                            ever_reported [0:N-1];
    // Derived once as the slot is written, for the searches that compare every slot at once
    // (no multiply per slot): the seek window per axis (evclust_seek_window, out of the reach in
    // P's format), and for merging merge_scale * max(Rx, Ry) and merge_v_rel * (|Vx| + |Vy|),
    // both unaligned.
    localparam integer SCALED_SEEK_W = SEEK_SCALE_W + HALF_SIZE_W + (FP > SEEK_SCALE_FRAC + FR ? FP - SEEK_SCALE_FRAC - FR : 0);
    localparam integer REACH_BASE_W = HALF_SIZE_W + FP - FR > SEEK_MARGIN_W ? HALF_SIZE_W + FP - FR : SEEK_MARGIN_W;
    localparam integer REACH_W = (REACH_BASE_W > SCALED_SEEK_W ? REACH_BASE_W : SCALED_SEEK_W) + 2;
    localparam integer GROW_W = MERGE_SCALE_W + HALF_SIZE_W;
    localparam integer VREL_W = MERGE_V_REL_W + V_INT_W + 1;
    localparam integer WINDOW_W = 2 * (CENTRE_W - FP + 1) + EV_XY_W + FP;
    reg [WINDOW_W-1:0]             window_x      [0:N-1];
    reg [WINDOW_W-1:0]             window_y      [0:N-1];
    reg [GROW_W-1:0]               grow          [0:N-1];
    reg [VREL_W-1:0]               vrel          [0:N-1];

    // The rest of a slot, one row per slot in RAM (evclust_slot_ram), fields at ROW_*: one write
    // port (an update, a creation, a merge or the sweep's stage 0, each in its own state) and two
    // read ports, A at the event's slot (EXEC) or the swept, scanned or merging slot k, B at the
    // sweep tail's slot t or the slot a merge absorbs. Only the searches need every slot at once.
    localparam integer ROW_ID = 0;
    localparam integer ROW_PPX = ROW_ID + ID_W;
    localparam integer ROW_PPY = ROW_PPX + CENTRE_W;
    localparam integer ROW_ACT = ROW_PPY + CENTRE_W;
    localparam integer ROW_RESIDUAL = ROW_ACT + ACT_ROW_W;
    localparam integer ROW_T_LAST = ROW_RESIDUAL + DECAY_RESIDUAL_W;
    localparam integer ROW_GAMMA = ROW_T_LAST + T_LAST_W;
    localparam integer ROW_VMX = ROW_GAMMA + GAMMA_W;
    localparam integer ROW_VMY = ROW_VMX + V_MCM_W;
    localparam integer ROW_NORM = ROW_VMY + V_MCM_W;
    localparam integer ROW_EV_COUNT = ROW_NORM + MCM_NORM_W;
    localparam integer ROW_COL_Y = ROW_EV_COUNT + EVENTS_IN_INTERVAL_W;
    localparam integer ROW_COL_CB = ROW_COL_Y + COLOUR_W;
    localparam integer ROW_COL_CR = ROW_COL_CB + COLOUR_W;
    localparam integer ROW_HIST = ROW_COL_CR + COLOUR_W;  // entry c at ROW_HIST + c * HIST_W
    localparam integer ROW_W = ROW_HIST + P * HIST_W;
    wire [SLOT_W-1:0] row_a_slot, row_b_slot;
    wire [ROW_W-1:0]  row_a, row_b, row_e;
    reg               row_we;
    reg  [SLOT_W-1:0] row_w_slot;
    reg  [ROW_W-1:0]  row_w;
    evclust_slot_ram #(.DEPTH(N), .WIDTH(ROW_W), .ADDR_W(SLOT_W)) slot_rows (
        .clk(clk), .we(row_we), .waddr(row_w_slot), .wdata(row_w),
        .raddr_a(row_a_slot), .rdata_a(row_a), .raddr_b(row_b_slot), .rdata_b(row_b), .raddr_e(e_slot), .rdata_e(row_e)
    );
    wire [ID_W-1:0]                 id_b = row_b[ROW_ID +: ID_W];  // (port A's id: a merge copies the whole row)
    wire [CENTRE_W-1:0]             ppx_a = row_a[ROW_PPX +: CENTRE_W], ppx_b = row_b[ROW_PPX +: CENTRE_W];
    wire [CENTRE_W-1:0]             ppy_a = row_a[ROW_PPY +: CENTRE_W], ppy_b = row_b[ROW_PPY +: CENTRE_W];
    wire [ACT_ROW_W-1:0]            act_a = row_a[ROW_ACT +: ACT_ROW_W], act_b = row_b[ROW_ACT +: ACT_ROW_W];
    wire [DECAY_RESIDUAL_W-1:0]     residual_a = row_a[ROW_RESIDUAL +: DECAY_RESIDUAL_W], residual_b = row_b[ROW_RESIDUAL +: DECAY_RESIDUAL_W];
    wire [T_LAST_W-1:0]             t_last_a = row_a[ROW_T_LAST +: T_LAST_W], t_last_b = row_b[ROW_T_LAST +: T_LAST_W];
    wire [GAMMA_W-1:0]              gamma_a = row_a[ROW_GAMMA +: GAMMA_W];
    wire [V_MCM_W-1:0]              vmx_a = row_a[ROW_VMX +: V_MCM_W], vmx_b = row_b[ROW_VMX +: V_MCM_W];
    wire [V_MCM_W-1:0]              vmy_a = row_a[ROW_VMY +: V_MCM_W], vmy_b = row_b[ROW_VMY +: V_MCM_W];
    wire [MCM_NORM_W-1:0]           norm_a = row_a[ROW_NORM +: MCM_NORM_W];
    wire [EVENTS_IN_INTERVAL_W-1:0] ev_count_a = row_a[ROW_EV_COUNT +: EVENTS_IN_INTERVAL_W], ev_count_b = row_b[ROW_EV_COUNT +: EVENTS_IN_INTERVAL_W];
    wire [COLOUR_W-1:0]             col_y_b = row_b[ROW_COL_Y +: COLOUR_W];
    wire [COLOUR_W-1:0]             col_cb_b = row_b[ROW_COL_CB +: COLOUR_W];
    wire [COLOUR_W-1:0]             col_cr_b = row_b[ROW_COL_CR +: COLOUR_W];
    wire [P*HIST_W-1:0]             hist_b = row_b[ROW_HIST +: P * HIST_W];

    // ---------------------------------------------------------------- globals
    reg [BACKGROUND_W-1:0]     bg_y, bg_cb, bg_cr;
    reg [P*INV_WW_W-1:0]       inv_ww;
    reg [ID_W-1:0]             next_id;
    reg [31:0]                 step;
    reg [EV_T_W-1:0]           t_filter;
    reg [TAU_PHASE_W-1:0]      tau_phase;
    reg [EVERY_W-1:0]          since_filter;
    reg                        started;
    reg [ACT_ROW_W-1:0]        bg_act;       // the activity of the events no reported cluster takes
    reg [DECAY_RESIDUAL_W-1:0] bg_residual;  // (against a reference time: the reference's residual)
    reg [EV_T_W-1:0]           bg_t;         // (and the reference time)

    // ---------------------------------------------------------------- the creation-support map
    // One cell per 2^SUPPORT_CELL_BITS px square, a border cell all round (model: layout.support_shape):
    // the time of the cell's latest event and whether it has one.
    localparam integer MAP_W = ((SENSOR_WIDTH - 1) >> SUPPORT_CELL_BITS) + 3;
    localparam integer MAP_H = ((SENSOR_HEIGHT - 1) >> SUPPORT_CELL_BITS) + 3;
    localparam integer CELLS = CREATE_SUPPORT != 0 ? MAP_W * MAP_H : 1;
    localparam integer CELL_W = CELLS > 1 ? $clog2(CELLS) : 1;
    localparam integer LAST_CELL_I = CELLS - 1;
    localparam [CELL_W-1:0] LAST_CELL = LAST_CELL_I[CELL_W-1:0];
    reg [SUPPORT_TIME_W-1:0] support_t    [0:CELLS-1];
    reg                      support_seen [0:CELLS-1];
    reg [CELL_W-1:0]         init_cell;  // INIT: the cell being cleared

    // ---------------------------------------------------------------- control
    reg [2:0]              state, state_next;  // the FSM: state_next below, one register
    reg [SWEEP_W-1:0]      index;        // INIT: palette entry; SCAN: slot; SWEEP: slot and palette entry
    reg [EV_T_W-1:0]       e_t;
    reg [EV_XY_W-1:0]      e_x, e_y;
    reg [EV_COLOUR_W-1:0]  e_lum, e_cb, e_cr;
    reg [SLOT_W-1:0]       weakest;
    reg [ACT_ROW_W-1:0]    weakest_a;
    reg [32:0]             boundaries;   // tau boundaries since the last filter step
    reg [FRAME_PER_TAU_W-1:0] per_frame; // T_frame / (boundaries * tau)

    assign filter_active = state == ST_PHASE || state == ST_SWEEP || state == ST_MERGE;
    // The datapath restarts on a reset or a clear; the configuration lives outside (evclust_regs).
    wire dp_rst = rst || clear;

    // ---------------------------------------------------------------- step 1: the seek
    // Stage A holds an accepted event while every slot compares it against its window in
    // parallel. The keys {miss, L1 distance, slot} and {taken, slot} make "smallest" the model's
    // choice (nearest, ties to the lower slot; the lowest free slot); a tree keeps the two
    // smallest of each, registered into stage B with the event. The slot that the event before
    // writes on that same clock edge is tested again in B (`seek_w`), so the search sees the
    // table exactly as the model does.
    // The event word's fields (IN_*: the layout vectors/pack.py packs).
    localparam integer CW = EV_COLOUR_W;
    wire [EV_T_W-1:0]  in_t = ev_data[IN_T_LSB +: IN_T_W];
    wire [EV_XY_W-1:0] in_x = ev_data[IN_X_LSB +: IN_X_W];
    wire [EV_XY_W-1:0] in_y = ev_data[IN_Y_LSB +: IN_Y_W];
    wire [CW-1:0]      in_lum = ev_data[IN_LUM_LSB +: IN_LUM_W];
    wire [CW-1:0]      in_cb = ev_data[IN_CB_LSB +: IN_CB_W];
    wire [CW-1:0]      in_cr = ev_data[IN_CR_LSB +: IN_CR_W];
    wire               unused_polarity = ev_data[IN_ON_LSB];  // the clusterer is blind to polarity

    reg                a_valid;
    reg [EV_T_W-1:0]   a_t;
    reg [EV_XY_W-1:0]  a_x, a_y;
    reg [CW-1:0]       a_lum, a_cb, a_cr;

    localparam integer DIST_W = SEEK_DISTANCE_W;  // |dx| + |dy| of two points inside the sensor
    localparam integer SEEK_KEY_W = 1 + DIST_W + SLOT_W;
    localparam integer FREE_KEY_W = 1 + SLOT_W;

    // Every slot's key, and the two smallest of the seek and free-slot keys (evclust_seek).
    reg  [N-1:0]            valid_bits;
    reg  [N*CENTRE_W-1:0]   px_bits, py_bits;
    reg  [N*WINDOW_W-1:0]   window_x_bits, window_y_bits;
    integer s;
    always @* begin
        for (s = 0; s < N; s = s + 1) begin
            valid_bits[s] = valid[s];
            px_bits[s*CENTRE_W +: CENTRE_W] = px[s];
            py_bits[s*CENTRE_W +: CENTRE_W] = py[s];
            window_x_bits[s*WINDOW_W +: WINDOW_W] = window_x[s];
            window_y_bits[s*WINDOW_W +: WINDOW_W] = window_y[s];
        end
    end
    wire [SEEK_KEY_W-1:0] seek_first, seek_second;
    wire [FREE_KEY_W-1:0] free_first, free_second;
    evclust_seek #(
        .N(N), .XY_BITS(EV_XY_W), .CENTRE_BITS(CENTRE_W), .WINDOW_BITS(WINDOW_W), .SLOT_BITS(SLOT_W), .KEY_BITS(SEEK_KEY_W)
    ) seek (
        .x(a_x), .y(a_y), .valid(valid_bits), .centre_x(px_bits), .centre_y(py_bits), .window_x(window_x_bits), .window_y(window_y_bits),
        .seek_first(seek_first), .seek_second(seek_second), .free_first(free_first), .free_second(free_second)
    );

    // Stage B (EXEC): the search's result with the slot written as the event entered, w,
    // tested on its new state; the search's runner-up stands in when its winner was w.
    reg [SEEK_KEY_W-1:0] e_seek_first, e_seek_second;
    reg [FREE_KEY_W-1:0] e_free_first, e_free_second;
    reg [SLOT_W-1:0]     seek_w;
    wire [SEEK_KEY_W-1:0] w_key;
    evclust_seek_key #(
        .XY_BITS(EV_XY_W), .CENTRE_BITS(CENTRE_W), .WINDOW_BITS(WINDOW_W), .SLOT_BITS(SLOT_W), .KEY_BITS(SEEK_KEY_W)
    ) seek_w_key (
        .x(e_x), .y(e_y), .live(valid[seek_w]), .centre_x(px[seek_w]), .centre_y(py[seek_w]),
        .window_x(window_x[seek_w]), .window_y(window_y[seek_w]), .slot(seek_w), .key(w_key)
    );
    wire [SEEK_KEY_W-1:0] other_key = e_seek_first[SLOT_W-1:0] == seek_w ? e_seek_second : e_seek_first;
    wire [SEEK_KEY_W-1:0] chosen_key = w_key < other_key ? w_key : other_key;
    wire [FREE_KEY_W-1:0] w_free_key = {valid[seek_w], seek_w};
    wire [FREE_KEY_W-1:0] other_free_key = e_free_first[SLOT_W-1:0] == seek_w ? e_free_second : e_free_first;
    wire [FREE_KEY_W-1:0] chosen_free_key = w_free_key < other_free_key ? w_free_key : other_free_key;
    wire              e_hit = !chosen_key[SEEK_KEY_W-1];
    wire [SLOT_W-1:0] e_slot = chosen_key[SLOT_W-1:0];
    wire              e_free = !chosen_free_key[FREE_KEY_W-1];
    wire [SLOT_W-1:0] e_free_slot = chosen_free_key[SLOT_W-1:0];

    // ---------------------------------------------------------------- the decay unit
    // Shared, on the slot row's port A: the updated slot (EXEC), the scanned slot (SCAN, without
    // the residual, as the model's eviction compares), the swept or merging slot (SWEEP, MERGE).
    wire [ACTIVITY_W-1:0] dec_a;
    wire [DECAY_RESIDUAL_W-1:0] dec_residual;
    evclust_decay #(.ACTIVITY_BITS(ACTIVITY_W), .DT_BITS(DT_W), .RESIDUAL_BITS(DECAY_RESIDUAL_W), .INV_T_HALF_BITS(INV_T_HALF_W)) decay_unit (
        .activity(commit_reads ? act_b[ACTIVITY_W-1:0] : act_a[ACTIVITY_W-1:0]),
        .dt(commit_reads ? c_t - t_last_b : e_t - t_last_a),
        .residual(commit_reads ? residual_b : residual_a),
        .use_residual(state != ST_SCAN),
        .inv_t_half(K_INV_T_HALF),
        .decayed(dec_a),
        .residual_out(dec_residual)
    );

    // The background's activity decayed to the event's time (model: _decay_background).
    wire [ACTIVITY_W-1:0] bg_dec_a;
    wire [DECAY_RESIDUAL_W-1:0] bg_dec_residual;
    evclust_decay #(.ACTIVITY_BITS(ACTIVITY_W), .DT_BITS(DT_W), .RESIDUAL_BITS(DECAY_RESIDUAL_W), .INV_T_HALF_BITS(INV_T_HALF_W)) bg_decay_unit (
        .activity(bg_act[ACTIVITY_W-1:0]),
        .dt(e_t - bg_t),
        .residual(bg_residual),
        .use_residual(1'b1),
        .inv_t_half(K_INV_T_HALF),
        .decayed(bg_dec_a),
        .residual_out(bg_dec_residual)
    );

    // ---------------------------------------------------------------- the activity against a reference time
    // (ACTIVITY_REFERENCE; model: _reference_span, _weight, _move_reference.) bg_t is the
    // reference and bg_residual its residual. The event in stage A gets its weight, and is held
    // there while the reference first moves to its time if Ã could outgrow its headroom
    // (`move_due`: a drain of the updates in flight, then a pass over the slots, PHASE and SWEEP
    // with `moving`). A filter step moves the reference to its event's time in PHASE. Either
    // way every activity is decayed by the one step count `ref_m`: the background's as PHASE
    // ends, a slot's at its stage 0 (or the merge that reads it first, `k_decayed`).
    reg                   moving;     // PHASE and SWEEP move the reference: no filter step
    reg                   k_decayed;  // the swept slot's activity is already decayed (a merge wrote it)
    reg [63:0]            ref_m;      // the steps every activity decays by, as PHASE ends
    reg [ACT_ROW_W-1:0]   e_weight, h_weight, c_weight;  // the weight of the event in B, H, C
    wire [EV_T_W-1:0]     ref_time = state == ST_PHASE && !moving ? e_t : a_t;  // the step's event, or the one in A
    wire [63:0]           ref_steps;
    wire [DECAY_RESIDUAL_W-1:0] ref_residual;
    wire                  ref_passed;
    wire [ACT_ROW_W-1:0]  a_weight;
    wire [ACT_ROW_W-1:0]  ref_dec_a, ref_dec_b;
    generate
        if (REFERENCED) begin : reference
            evclust_reference #(.WEIGHT_BITS(ACT_ROW_W)) weights (
                .t(ref_time), .t_ref(bg_t), .residual(bg_residual), .inv_t_half(K_INV_T_HALF),
                .steps(ref_steps), .residual_out(ref_residual), .passed(ref_passed), .weight(a_weight)
            );
            // Port A's slot (the sweep's stage 0) and port B's (the slot a merge absorbs) or, in
            // PHASE, the background.
            evclust_decay_apply #(.ACTIVITY_BITS(ACT_ROW_W)) decay_a (.activity(act_a), .m(ref_m), .decayed(ref_dec_a));
            evclust_decay_apply #(.ACTIVITY_BITS(ACT_ROW_W)) decay_b (
                .activity(state == ST_PHASE ? bg_act : act_b), .m(state == ST_PHASE ? ref_steps : ref_m), .decayed(ref_dec_b)
            );
        end else begin : own_time
            assign ref_steps = 64'd0;
            assign ref_residual = {DECAY_RESIDUAL_W{1'b0}};
            assign ref_passed = 1'b0;
            assign a_weight = {ACT_ROW_W{1'b0}};
            assign ref_dec_a = {ACT_ROW_W{1'b0}};
            assign ref_dec_b = {ACT_ROW_W{1'b0}};
        end
    endgenerate
    // Saturated to the activity's format (model: _move_reference): port A's, the swept slot k's;
    // port B's, in PHASE the background's and in MERGE the slot k absorbs.
    wire signed [63:0] ref_dec_k = saturate(u64({{(63 - ACT_ROW_W){1'b0}}, ref_dec_a}), 0, MAX_ACT);
    wire signed [63:0] ref_dec_port_b = saturate(u64({{(63 - ACT_ROW_W){1'b0}}, ref_dec_b}), 0, MAX_ACT);
    // The swept (or merging) slot's activity at the step's time (model: the slot after _decay_slot
    // or _move_reference), and the write-back's word.
    wire signed [63:0] a_decayed = !REFERENCED ? u64({{(63 - ACTIVITY_W){1'b0}}, dec_a})
                                 : k_decayed ? u64({{(63 - ACT_ROW_W){1'b0}}, act_a}) : ref_dec_k;
    wire [ACT_ROW_W-1:0] act_now = a_decayed[ACT_ROW_W-1:0];
    // The event's count: one (plus the background's decay), or its weight.
    wire signed [63:0] bg_counted_full = REFERENCED ? u64({{(63 - ACT_ROW_W){1'b0}}, bg_act}) + u64({{(63 - ACT_ROW_W){1'b0}}, e_weight})
                                                    : u64({{(63 - ACTIVITY_W){1'b0}}, bg_dec_a}) + ONE_A;
    wire signed [63:0] bg_counted = saturate(bg_counted_full, 0, MAX_ACT_ROW);
    wire signed [63:0] bg_dec_wide = u64({{(63 - ACTIVITY_W){1'b0}}, bg_dec_a});  // (the paper's, decayed to the step)

    // ---------------------------------------------------------------- creation support
    // Some event of the 3x3 cells around the event's cell at most SUPPORT_WINDOW us old (mod 2^32).
    wire [31:0] cell_x = {{(32 - EV_XY_W){1'b0}}, e_x} >> SUPPORT_CELL_BITS;
    wire [31:0] cell_y = {{(32 - EV_XY_W){1'b0}}, e_y} >> SUPPORT_CELL_BITS;
    wire [31:0] cell_index = (cell_y + 32'd1) * MAP_W + cell_x + 32'd1;
    wire [CELL_W-1:0] ev_cell = cell_index[CELL_W-1:0];
    integer ny, nx;
    reg [31:0] neighbour;
    reg supported;
    always @* begin
        supported = CREATE_SUPPORT == 0;
        if (CREATE_SUPPORT != 0) begin
            for (ny = 0; ny < 3; ny = ny + 1) begin
                for (nx = 0; nx < 3; nx = nx + 1) begin
                    neighbour = (cell_y + ny) * MAP_W + cell_x + nx;
                    if (support_seen[neighbour[CELL_W-1:0]] && e_t - support_t[neighbour[CELL_W-1:0]] <= K_SUPPORT_WINDOW)
                        supported = 1'b1;
                end
            end
        end
    end

    // ---------------------------------------------------------------- step 3: the update
    // With UPDATE_DELAY = 2 the palette's and the update's second halves run in stage H, from
    // registers loaded as the event finishes (h_load).
    localparam integer UPDATE_STAGES = UPDATE_DELAY > 1 ? 2 : 1;
    wire h_load;
    wire [CLASS_W-1:0] vote_class;
    wire [VOTE_W-1:0]  vote;
    evclust_palette #(
        .P(P), .CLASS_W(CLASS_W), .BG_BITS(BACKGROUND_W), .INV_BITS(INV_WW_W), .VOTE_BITS(VOTE_W),
        .LUMA_BITS(LUMA_WEIGHT_W), .TOL_BITS(MIXING_TOLERANCE_W), .STAGES(UPDATE_STAGES), .DSP_ENTRIES(MIXING_DSP_ENTRIES)
    ) palette (
        .clk(clk), .rst(dp_rst), .advance(h_load),  // with stage H, its second half is H's
        .lum(e_lum), .cb(e_cb), .cr(e_cr),
        .bg_y(bg_y), .bg_cb(bg_cb), .bg_cr(bg_cr),
        .inv_ww(inv_ww),
        .palette_y(palette_y), .palette_cb(palette_cb), .palette_cr(palette_cr),
        .luma_weight(K_LUMA_WEIGHT), .mixing_tolerance(K_MIXING_TOLERANCE), .background_mask(background_mask),
        .mixing(mixing), .vote_contrast(vote_contrast),
        .class_index(vote_class),
        .vote(vote)
    );

    // The update as the model's _increments computes it (the palette's class and vote above):
    // each alpha filter's new value and its increment from the slot read at port A. With
    // UPDATE_DELAY = 2 its second half runs a stage later (stage H, below), from a register
    // loaded as the event finishes (h_load).
    wire [ROW_W-1:0] row_u = UPDATE_DELAY == 0 ? row_a : row_e;  // the event's slot's row (port E when delayed)
    wire [CENTRE_W-1:0]       up_px, up_py;
    wire [HALF_SIZE_W-1:0]    up_rx, up_ry;
    wire [V_MCM_W-1:0]        up_vmx, up_vmy;
    wire [MCM_NORM_W-1:0]     up_norm;
    wire [COLOUR_W-1:0]       up_cy, up_ccb, up_ccr;
    wire signed [DP_W-1:0]    i_px, i_py;
    wire signed [DR_W-1:0]    i_rx, i_ry;
    wire signed [DV_W-1:0]    i_vmx, i_vmy;
    wire signed [DN_W-1:0]    i_norm;
    wire signed [DC_W-1:0]    i_cy, i_ccb, i_ccr;
    wire [1:0]                up_step_saturations, up_mcm_saturations;
    evclust_update #(.STAGES(UPDATE_STAGES)) update (
        .clk(clk), .advance(h_load),
        .ev_x(e_x), .ev_y(e_y), .lum(e_lum), .cb(e_cb), .cr(e_cr),
        .px(px[e_slot]), .py(py[e_slot]), .rx(rx[e_slot]), .ry(ry[e_slot]), .gamma(row_u[ROW_GAMMA +: GAMMA_W]),
        .vmx(row_u[ROW_VMX +: V_MCM_W]), .vmy(row_u[ROW_VMY +: V_MCM_W]), .norm(row_u[ROW_NORM +: MCM_NORM_W]),
        .col_y(row_u[ROW_COL_Y +: COLOUR_W]), .col_cb(row_u[ROW_COL_CB +: COLOUR_W]), .col_cr(row_u[ROW_COL_CR +: COLOUR_W]),
        .beta_pos(cfg_beta_pos), .size_gain(cfg_size_gain), .beta_size(cfg_beta_size), .r_min(cfg_r_min), .r_max(cfg_r_max),
        .beta_vel_mcm(cfg_beta_vel_mcm), .beta_lum(cfg_beta_lum), .beta_chro(cfg_beta_chro),
        .px_new(up_px), .py_new(up_py), .rx_new(up_rx), .ry_new(up_ry), .vmx_new(up_vmx), .vmy_new(up_vmy), .norm_new(up_norm),
        .col_y_new(up_cy), .col_cb_new(up_ccb), .col_cr_new(up_ccr),
        .d_px(i_px), .d_py(i_py), .d_rx(i_rx), .d_ry(i_ry), .d_vmx(i_vmx), .d_vmy(i_vmy), .d_norm(i_norm),
        .d_col_y(i_cy), .d_col_cb(i_ccb), .d_col_cr(i_ccr),
        .step_saturations(up_step_saturations), .mcm_saturations(up_mcm_saturations)
    );

    // ---------------------------------------------------------------- the commit (pipeline semantics)
    // UPDATE_DELAY = 1 (model: _increments, _commit; docs/DESIGN.md, "Pipeline semantics"): EXEC
    // keeps its event's update as increments from the state it read, and they are added to the
    // slot as it then is when the next event finishes (or, before a filter step, in PHASE). So
    // the next event reads the table without them, and the sums leave EXEC's recurrence. The
    // commit reads its slot's row at port B. UPDATE_DELAY = 0: EXEC writes the update itself,
    // the alpha filters' new values and the commit's counts on the row it read at port A.
    // UPDATE_DELAY = 2: the same, the update passing through stage H first (below).
    localparam signed [63:0] MAX_B = (64'sd1 <<< BACKGROUND_W) - 1;
    reg                    c_live, c_bg_live;  // a slot update, a background update in flight
    reg [SLOT_W-1:0]       c_slot;
    reg [EV_T_W-1:0]       c_t;
    reg signed [DP_W-1:0]  c_dpx, c_dpy;
    reg signed [DR_W-1:0]  c_drx, c_dry;
    reg signed [DV_W-1:0]  c_dvmx, c_dvmy;
    reg signed [DN_W-1:0]  c_dnorm;
    reg signed [DC_W-1:0]  c_dcy, c_dccb, c_dccr;
    reg [CLASS_W-1:0]      c_class;
    reg [VOTE_W-1:0]       c_vote;
    reg signed [DB_W-1:0]  c_dbg_y, c_dbg_cb, c_dbg_cr;
    // Stage H (UPDATE_DELAY = 2): the event before's update, its second half being computed
    // (evclust_update's register holds its operands); it moves to C as the next event finishes,
    // or in PHASE. The increments C takes are evclust_update's outputs.
    reg                    h_live, h_bg_live, h_fresh;  // h_fresh: loaded last cycle (its MCM saturations count now)
    reg [SLOT_W-1:0]       h_slot;
    reg [EV_T_W-1:0]       h_t;
    reg signed [DB_W-1:0]  h_dbg_y, h_dbg_cb, h_dbg_cr;
    reg                    creating;  // a creation's second cycle: the first committed the event before
    reg [SLOT_W-1:0]       creating_slot;
    wire commit_moment;  // the event before commits now (the decision logic below)
    wire commit_reads = UPDATE_DELAY != 0 && (state == ST_EXEC || state == ST_EVICT || state == ST_PHASE);
    // The slot an update lands in, as it is now: the event's own at port A, or the event
    // before's at port B (the decay unit reads the same port).
    localparam DELAYED = UPDATE_DELAY != 0;
    wire [SLOT_W-1:0] sw_slot = DELAYED ? c_slot : e_slot;
    wire [ROW_W-1:0]  sw_row = DELAYED ? row_b : row_a;
    wire [ACTIVITY_W-1:0] cm_act;
    wire [CENTRE_W-1:0]   cm_px, cm_py;
    wire [HALF_SIZE_W-1:0] cm_rx, cm_ry;
    wire [V_MCM_W-1:0]    cm_vmx, cm_vmy;
    wire [MCM_NORM_W-1:0] cm_norm;
    wire [COLOUR_W-1:0]   cm_cy, cm_ccb, cm_ccr;
    wire [P*HIST_W-1:0]   cm_hist;
    wire [EVENTS_IN_INTERVAL_W-1:0] cm_evc;
    wire [1:0]            cm_act_saturations, cm_vm_saturations, cm_evc_saturations;
    evclust_commit commit (
        .act_decayed(dec_a), .px(px[sw_slot]), .py(py[sw_slot]), .rx(rx[sw_slot]), .ry(ry[sw_slot]),
        .vmx(sw_row[ROW_VMX +: V_MCM_W]), .vmy(sw_row[ROW_VMY +: V_MCM_W]), .norm(sw_row[ROW_NORM +: MCM_NORM_W]),
        .col_y(sw_row[ROW_COL_Y +: COLOUR_W]), .col_cb(sw_row[ROW_COL_CB +: COLOUR_W]), .col_cr(sw_row[ROW_COL_CR +: COLOUR_W]),
        .hist(sw_row[ROW_HIST +: P * HIST_W]), .ev_count(sw_row[ROW_EV_COUNT +: EVENTS_IN_INTERVAL_W]),
        .d_px(c_dpx), .d_py(c_dpy), .d_rx(c_drx), .d_ry(c_dry), .d_vmx(c_dvmx), .d_vmy(c_dvmy), .d_norm(c_dnorm),
        .d_col_y(c_dcy), .d_col_cb(c_dccb), .d_col_cr(c_dccr),
        .class_index(DELAYED ? c_class : vote_class), .vote(DELAYED ? c_vote : vote),
        .r_min(cfg_r_min), .r_max(cfg_r_max),
        .act_out(cm_act), .px_out(cm_px), .py_out(cm_py), .rx_out(cm_rx), .ry_out(cm_ry), .vmx_out(cm_vmx), .vmy_out(cm_vmy),
        .norm_out(cm_norm), .col_y_out(cm_cy), .col_cb_out(cm_ccb), .col_cr_out(cm_ccr), .hist_out(cm_hist), .ev_count_out(cm_evc),
        .act_saturations(cm_act_saturations), .vm_saturations(cm_vm_saturations), .ev_count_saturations(cm_evc_saturations)
    );
    // What the slot write stores: without delay, the alpha filters' new values (their sums with
    // the state read cannot saturate) and the commit's counts; with it, the commit's all.
    wire [CENTRE_W-1:0]    sw_px = DELAYED ? cm_px : up_px, sw_py = DELAYED ? cm_py : up_py;
    wire [HALF_SIZE_W-1:0] sw_rx = DELAYED ? cm_rx : up_rx, sw_ry = DELAYED ? cm_ry : up_ry;
    wire [V_MCM_W-1:0]     sw_vmx = DELAYED ? cm_vmx : up_vmx, sw_vmy = DELAYED ? cm_vmy : up_vmy;
    wire [MCM_NORM_W-1:0]  sw_norm = DELAYED ? cm_norm : up_norm;
    wire [COLOUR_W-1:0]    sw_cy = DELAYED ? cm_cy : up_cy, sw_ccb = DELAYED ? cm_ccb : up_ccb, sw_ccr = DELAYED ? cm_ccr : up_ccr;
    wire [EV_T_W-1:0]      sw_t = DELAYED ? c_t : e_t;
    // Against a reference time the activity's update is Ã plus the event's weight (model: _commit).
    wire signed [63:0]     ref_act_full = u64({{(63 - ACT_ROW_W){1'b0}}, sw_row[ROW_ACT +: ACT_ROW_W]})
                                        + u64({{(63 - ACT_ROW_W){1'b0}}, DELAYED ? c_weight : e_weight});
    wire signed [63:0]     ref_act = saturate(ref_act_full, 0, MAX_ACT_ROW);
    wire signed [63:0]     cm_act_wide = u64({{(63 - ACTIVITY_W){1'b0}}, cm_act});
    wire [ACT_ROW_W-1:0]   sw_act = REFERENCED ? ref_act[ACT_ROW_W-1:0] : cm_act_wide[ACT_ROW_W-1:0];
    wire [1:0]             sw_act_saturations = REFERENCED ? outside(ref_act_full, 0, MAX_ACT_ROW) : cm_act_saturations;
    // The background colour's commit.
    reg signed [63:0] cm_bg_y, cm_bg_cb, cm_bg_cr;
    always @* begin
        cm_bg_y = saturate(u64({{(63 - BACKGROUND_W){1'b0}}, bg_y}) + $signed({{(64 - DB_W){c_dbg_y[DB_W-1]}}, c_dbg_y}), 0, MAX_B);
        cm_bg_cb = saturate(u64({{(63 - BACKGROUND_W){1'b0}}, bg_cb}) + $signed({{(64 - DB_W){c_dbg_cb[DB_W-1]}}, c_dbg_cb}), 0, MAX_B);
        cm_bg_cr = saturate(u64({{(63 - BACKGROUND_W){1'b0}}, bg_cr}) + $signed({{(64 - DB_W){c_dbg_cr[DB_W-1]}}, c_dbg_cr}), 0, MAX_B);
    end

    // ---------------------------------------------------------------- the filter sweep
    // Stage 0, one slot k per cycle: decay, expiry, gamma, the interval velocity at tau
    // boundaries. The tail, TAIL cycles behind: the MCM bias correction (a pipelined divider),
    // then T1 (the corrected velocity, its squares, the record) and T2 (exit prediction, the
    // report, the record out). Nothing the tail reads of slot t changes after t's stage 0 (later
    // slots' merges touch only later slots, and the sweep runs no event), so T1 reads the table
    // and registers what T2 needs.
    wire [SLOT_W-1:0] k = index[SLOT_W-1:0];
    reg signed [63:0] f_gamma, f_mx, f_my, f_vix, f_viy, f_per_frame, f_evc;
    reg signed [63:0] f_gamma_activity, f_gamma_count, f_mx_full, f_my_full;  // before saturation
    reg               f_gamma_by_activity, f_gamma_by_count;  // which γ the slot takes, if any
    reg [INTERVAL_UPDATES_W-1:0] f_vi_count;
    reg               f_expire;
    always @* begin
        f_per_frame = u64({{(63 - FRAME_PER_TAU_W){1'b0}}, per_frame});
        f_expire = a_decayed < K_A_MIN;
        f_vi_count = vi_count[k];
        f_gamma = u64({{(63 - GAMMA_W){1'b0}}, gamma_a});
        f_evc = u64({{(63 - EVENTS_IN_INTERVAL_W){1'b0}}, ev_count_a});
        f_gamma_activity = gamma_from_activity(a_decayed, gamma_mode, K_GAMMA_GLOBAL, K_GPA);
        f_gamma_count = (f_evc * f_per_frame) >>> (FPT_F - FG);
        f_gamma_by_activity = gamma_mode != GAMMA_MODE_COUNT[1:0] || vi_count[k] == VI_NONE;
        f_gamma_by_count = boundaries != 33'd0 && !f_gamma_by_activity;
        if (f_gamma_by_activity)
            f_gamma = saturate(f_gamma_activity, 0, MAX_GAMMA);
        f_vix = $signed({{(64 - V_INT_W){vix[k][V_INT_W-1]}}, vix[k]});
        f_viy = $signed({{(64 - V_INT_W){viy[k][V_INT_W-1]}}, viy[k]});
        f_mx_full = align((u64({{(63 - CENTRE_W){1'b0}}, px[k]}) - u64({{(63 - CENTRE_W){1'b0}}, ppx_a})) * f_per_frame, FP + FPT_F, FI);
        f_my_full = align((u64({{(63 - CENTRE_W){1'b0}}, py[k]}) - u64({{(63 - CENTRE_W){1'b0}}, ppy_a})) * f_per_frame, FP + FPT_F, FI);
        f_mx = saturate(f_mx_full, MIN_VI, MAX_VI);
        f_my = saturate(f_my_full, MIN_VI, MAX_VI);
        if (boundaries != 33'd0) begin
            if (f_gamma_by_count)
                f_gamma = saturate(f_gamma_count, 0, MAX_GAMMA);
            f_evc = 0;
            if (!warm_start || vi_count[k] >= VI_WARM_END) begin
                f_vix = alpha_step(f_vix, f_mx, K_B_VI, BETA_VEL_INT_FRAC, 0, 1'b0);
                f_viy = alpha_step(f_viy, f_my, K_B_VI, BETA_VEL_INT_FRAC, 0, 1'b0);
            end else if (vi_count[k] == VI_FIRST) begin  // the first full interval: as it is
                f_vix = f_mx;
                f_viy = f_my;
            end else if (vi_count[k] >= VI_MEASURED) begin  // the warm-up's running mean: gain 1/n
                f_vix = alpha_step(f_vix, f_mx, warmup_gain(vi_count[k]), BETA_VEL_INT_FRAC, 0, 1'b0);
                f_viy = alpha_step(f_viy, f_my, warmup_gain(vi_count[k]), BETA_VEL_INT_FRAC, 0, 1'b0);
            end
            f_vi_count = vi_count[k] >= VI_COUNT_MAX ? VI_COUNT_MAX : vi_count[k] + 1'b1;
        end
    end

    // The tail's first register: the live slot swept and its MCM accumulator and weight.
    reg               p_live;
    reg [SLOT_W-1:0]  p_slot;
    reg [V_MCM_W-1:0] p_vmx, p_vmy;
    reg [W20_W-1:0]   p_w20;
    wire [MCM_NORM_W-1:0] norm_cut = norm_a >> (FW - MCM_WEIGHT_FRAC);  // w floored to mcm_weight's format
    wire [QUOTIENT_W-1:0] p_mag_x = floor_magnitude(p_vmx, p_w20);
    wire [QUOTIENT_W-1:0] p_mag_y = floor_magnitude(p_vmy, p_w20);
    wire              p_correct = mcm_correct && p_w20 != {W20_W{1'b0}};
    wire              p_sat_x = p_mag_x[QUOTIENT_W-1:Q_W] >= {{(QUOTIENT_W - Q_W - W20_W){1'b0}}, p_w20};
    wire              p_sat_y = p_mag_y[QUOTIENT_W-1:Q_W] >= {{(QUOTIENT_W - Q_W - W20_W){1'b0}}, p_w20};
    wire [W20_W-1:0]  p_divisor = p_correct ? p_w20 : {{(W20_W - 1){1'b0}}, 1'b1};  // no division by zero
    // The model's saturation of V / w, for the counter: a negative quotient of exactly -2^Q_W
    // fits V's format (saturating gives the same word), so it saturates only from
    // -(2^Q_W + 1), that is a magnitude |a| + b - 1 of at least (2^Q_W + 1) b.
    wire [QUOTIENT_W-1:0] p_b = {{(QUOTIENT_W - W20_W){1'b0}}, p_w20};
    /* verilator lint_off UNUSEDSIGNAL */  // only the bits above the quotient's are compared
    wire [QUOTIENT_W-1:0] p_less_x = p_mag_x - p_b, p_less_y = p_mag_y - p_b;
    /* verilator lint_on UNUSEDSIGNAL */
    wire              p_over_x = p_vmx[V_MCM_W-1] ? p_mag_x >= p_b && p_less_x[QUOTIENT_W-1:Q_W] >= p_b[QUOTIENT_W-Q_W-1:0] : p_sat_x;
    wire              p_over_y = p_vmy[V_MCM_W-1] ? p_mag_y >= p_b && p_less_y[QUOTIENT_W-1:Q_W] >= p_b[QUOTIENT_W-Q_W-1:0] : p_sat_y;
    localparam integer TAG_W = 1 + SLOT_W + 7;
    wire [TAG_W-1:0]  t_tag;
    wire [Q_W-1:0]    t_qx, t_qy;
    wire              tail_en;
`ifdef FORMAL
    wire [(Q_W + SWEEP_DIV_STEP - 1) / SWEEP_DIV_STEP * TAG_W - 1:0] f_vmx_tags;  // the tail's stages (evclust_core_props.vh)
`endif
    evclust_pipediv #(.Q_W(Q_W), .DEN_W(W20_W), .STEP(SWEEP_DIV_STEP), .TAG_W(TAG_W)) div_vmx (
        .clk(clk), .rst(dp_rst), .en(tail_en),
        .remainder_in(p_sat_x || !p_correct ? {W20_W{1'b0}} : p_mag_x[Q_W +: W20_W]), .bits_in(p_mag_x[Q_W-1:0]),
        .divisor(p_divisor),
        .tag_in({p_live, p_slot, p_correct, p_vmx[V_MCM_W-1], p_sat_x, p_vmy[V_MCM_W-1], p_sat_y, p_over_x, p_over_y}),
        .quotient(t_qx), .tag_out(t_tag)
`ifdef FORMAL
        , .f_tags(f_vmx_tags)
`endif
    );
    wire [TAG_W-1:0] unused_tag_y;
    evclust_pipediv #(.Q_W(Q_W), .DEN_W(W20_W), .STEP(SWEEP_DIV_STEP), .TAG_W(TAG_W)) div_vmy (
        .clk(clk), .rst(dp_rst), .en(tail_en),
        .remainder_in(p_sat_y || !p_correct ? {W20_W{1'b0}} : p_mag_y[Q_W +: W20_W]), .bits_in(p_mag_y[Q_W-1:0]),
        .divisor(p_divisor),
        .tag_in({TAG_W{1'b0}}),
        .quotient(t_qy), .tag_out(unused_tag_y)
    );
    wire             t_live = t_tag[TAG_W-1];
    wire [SLOT_W-1:0] t = t_tag[TAG_W-2 -: SLOT_W];
    wire             t_correct = t_tag[6], t_neg_x = t_tag[5], t_sat_x = t_tag[4], t_neg_y = t_tag[3], t_sat_y = t_tag[2];
    wire             t_over_x = t_tag[1], t_over_y = t_tag[0];

    // The tail's stage T1, at the divider's output (slot t): the reported MCM velocity V / w, its
    // squares, the report's terms, the class and the record, registered for T2, which compares
    // and decides (a path through the squares and on through the exit's multiply was the core's
    // longest).
    function automatic signed [63:0] corrected_v;
        input [V_MCM_W-1:0] raw;
        input correct, negative, saturated;
        input [Q_W-1:0] quotient;
        reg signed [63:0] q;
        begin
            q = u64({{(63 - Q_W){1'b0}}, quotient});
            if (!correct)
                corrected_v = $signed({{(64 - V_MCM_W){raw[V_MCM_W-1]}}, raw});
            else if (saturated)
                corrected_v = negative ? MIN_V : MAX_V;
            else
                corrected_v = negative ? -q : q;
        end
    endfunction
    integer cls;
    reg signed [63:0] f_vmx, f_vmy, f_vmx_raw, f_vmy_raw, f_px, f_py, f_act, f_vix_t, f_viy_t;
    reg signed [63:0] f_speed_sq, f_speed_full, f_speed_sq_x, f_speed_sq_y;
    reg [2*SQ_MAG_W-1:0] f_sq_x, f_sq_y;
    reg               f_left, f_right, f_top, f_bottom, f_out_x, f_out_y, f_fast, f_moving_mcm, f_moving_int, f_active_moving;
    reg signed [63:0] f_box, f_noise_signal, f_noise_scale;
    reg signed [63:0] f_best;
    reg [7:0]         f_class;
    reg [3:0]         f_flags;
    always @* begin
        f_act = u64({{(63 - ACT_ROW_W){1'b0}}, act_b});
        f_px = u64({{(63 - CENTRE_W){1'b0}}, px[t]});
        f_py = u64({{(63 - CENTRE_W){1'b0}}, py[t]});
        f_vix_t = $signed({{(64 - V_INT_W){vix[t][V_INT_W-1]}}, vix[t]});
        f_viy_t = $signed({{(64 - V_INT_W){viy[t][V_INT_W-1]}}, viy[t]});
        f_vmx_raw = $signed({{(64 - V_MCM_W){vmx_b[V_MCM_W-1]}}, vmx_b});
        f_vmy_raw = $signed({{(64 - V_MCM_W){vmy_b[V_MCM_W-1]}}, vmy_b});
        f_vmx = corrected_v(vmx_b, t_correct, t_neg_x, t_sat_x, t_qx);
        f_vmy = corrected_v(vmy_b, t_correct, t_neg_y, t_sat_y, t_qy);
        // Exit prediction on the squared speed.
        f_sq_x = square(f_vmx, FV);
        f_sq_y = square(f_vmy, FV);
        f_speed_full = speed_sq({1'b0, f_sq_x} + {1'b0, f_sq_y}, FV);
        f_speed_sq = f_speed_full;  // < 2^SPEED_SQ_W by construction: square() clamps each component below full scale
        f_speed_sq_x = speed_sq({1'b0, f_sq_x}, FV);
        f_speed_sq_y = speed_sq({1'b0, f_sq_y}, FV);
        f_fast = f_speed_sq >= K_V_EXIT_SQ && f_speed_sq > 0;
        f_left = f_px < K_EXIT_M;
        f_right = f_px > HI_X;
        f_top = f_py < K_EXIT_M;
        f_bottom = f_py > HI_Y;
        // Heading out across a border the centre is beyond, per axis (T2 weighs the axis's share of the speed).
        f_out_x = (f_left && f_vmx < 0) || (f_right && f_vmx > 0);
        f_out_y = (f_top && f_vmy < 0) || (f_bottom && f_vmy > 0);
        f_moving_mcm = speed_sq({1'b0, square(f_vmx_raw, FV)} + {1'b0, square(f_vmy_raw, FV)}, FV) >= K_V_MIN_SQ;
        f_moving_int = speed_sq({1'b0, square(f_vix_t, FI)} + {1'b0, square(f_viy_t, FI)}, FI) >= K_V_MIN_SQ;
        f_active_moving = f_act >= K_A_VALID && (f_moving_mcm || f_moving_int);  // the report, but for the noise gate
        // The noise gate's terms: A * W * H against gate * A_bg * (pixels of the box), the gate in
        // Q.NOISE_GATE_FRAC; T2 multiplies the floor's two factors, both exact here.
        f_box = (2 * u64({{(63 - HALF_SIZE_W){1'b0}}, rx[t] >> FR}) + 1) * (2 * u64({{(63 - HALF_SIZE_W){1'b0}}, ry[t] >> FR}) + 1);
        f_noise_signal = (f_act * SENSOR_PIXELS) <<< NOISE_GATE_FRAC;  // both sides fit noise_count
        f_noise_scale = K_NOISE_GATE * u64({{(63 - ACT_ROW_W){1'b0}}, bg_act});
        // The class: the strongest non-background histogram entry, none while all are zero.
        f_class = 8'hff;
        f_best = 0;
        for (cls = 0; cls < P; cls = cls + 1) begin
            if (!background_mask[cls] && u64({{(63 - HIST_W){1'b0}}, hist_b[cls*HIST_W +: HIST_W]}) > f_best) begin
                f_best = u64({{(63 - HIST_W){1'b0}}, hist_b[cls*HIST_W +: HIST_W]});
                f_class = cls[7:0];
            end
        end
        f_flags = (ever_reported[t] ? 4'd0 : FLAG_NEW) | ((f_left || f_right || f_top || f_bottom) ? FLAG_BORDER : 4'd0)
                | (f_moving_mcm ? FLAG_MOVING_MCM : 4'd0) | (f_moving_int ? FLAG_MOVING_INT : 4'd0);
    end

    // The record of slot t, in the layout of expected.hex.
    wire signed [63:0] r_cy = corrected(u64({{(63 - COLOUR_W){1'b0}}, col_y_b}), u64({{(63 - BACKGROUND_W){1'b0}}, bg_y}), K_INV_P);
    wire signed [63:0] r_cb = corrected(u64({{(63 - COLOUR_W){1'b0}}, col_cb_b}), u64({{(63 - BACKGROUND_W){1'b0}}, bg_cb}), K_INV_P);
    wire signed [63:0] r_cr = corrected(u64({{(63 - COLOUR_W){1'b0}}, col_cr_b}), u64({{(63 - BACKGROUND_W){1'b0}}, bg_cr}), K_INV_P);
    wire [REC_W-1:0] record;  // the fields at the layout's REC_* places
    assign record[REC_T_US_LSB +: REC_T_US_W] = e_t;
    assign record[REC_STEP_LSB +: REC_STEP_W] = step;
    assign record[REC_SLOT_LSB +: REC_SLOT_W] = t;
    assign record[REC_ID_LSB +: REC_ID_W] = id_b;
    assign record[REC_X_LSB +: REC_X_W] = px[t];
    assign record[REC_Y_LSB +: REC_Y_W] = py[t];
    assign record[REC_RX_LSB +: REC_RX_W] = rx[t];
    assign record[REC_RY_LSB +: REC_RY_W] = ry[t];
    assign record[REC_ACTIVITY_LSB +: REC_ACTIVITY_W] = act_b[ACTIVITY_W-1:0];  // (swept: within the activity's format)
    assign record[REC_VX_MCM_LSB +: REC_VX_MCM_W] = f_vmx[V_MCM_W-1:0];
    assign record[REC_VY_MCM_LSB +: REC_VY_MCM_W] = f_vmy[V_MCM_W-1:0];
    assign record[REC_VX_INT_LSB +: REC_VX_INT_W] = vix[t];
    assign record[REC_VY_INT_LSB +: REC_VY_INT_W] = viy[t];
    assign record[REC_LUM_LSB +: REC_LUM_W] = r_cy[COLOUR_W-1:0];
    assign record[REC_CB_LSB +: REC_CB_W] = r_cb[COLOUR_W-1:0];
    assign record[REC_CR_LSB +: REC_CR_W] = r_cr[COLOUR_W-1:0];
    assign record[REC_CLASS_LSB +: REC_CLASS_W] = f_class;
    assign record[REC_FLAGS_LSB +: REC_FLAGS_W] = f_flags;

    // The tail's stage T2, slot t2_slot (T1's, one enabled cycle later): T1's register, then the
    // exit prediction and the noise gate, each a multiply of registered terms and a compare.
    localparam integer BOX_W = 2 * (HALF_SIZE_W - FR + 1);            // (2 (R >> FR) + 1)^2 < 2^BOX_W
    localparam integer NOISE_SCALE_W = CFG_NOISE_GATE_W + ACT_ROW_W;  // gate * A_bg, exact
    reg                     t2_live;
    reg [SLOT_W-1:0]        t2_slot;
    reg [REC_W-1:0]         t2_record;
    reg [SPEED_SQ_W-1:0]    t2_speed_sq, t2_speed_sq_x, t2_speed_sq_y;
    reg                     t2_fast, t2_out_x, t2_out_y, t2_active_moving;
    reg [NOISE_COUNT_W-1:0] t2_noise_signal;
    reg [NOISE_SCALE_W-1:0] t2_noise_scale;
    reg [BOX_W-1:0]         t2_box;
    wire signed [63:0] f_limit = (u64({{(63 - SPEED_SQ_W){1'b0}}, t2_speed_sq}) * K_COS_SQ) >>> COS_SQ_F;
    wire               f_exit_x = t2_out_x && u64({{(63 - SPEED_SQ_W){1'b0}}, t2_speed_sq_x}) >= f_limit;
    wire               f_exit_y = t2_out_y && u64({{(63 - SPEED_SQ_W){1'b0}}, t2_speed_sq_y}) >= f_limit;
    wire               f_exit = t2_fast && (f_exit_x || f_exit_y);
    // The floor's low NOISE_COUNT_W bits, as the product of the three factors had them.
    wire signed [63:0] f_noise_floor = u64({{(63 - NOISE_SCALE_W){1'b0}}, t2_noise_scale}) * u64({{(63 - BOX_W){1'b0}}, t2_box});
    wire               f_report = t2_active_moving && (K_NOISE_GATE == 0 || t2_noise_signal >= f_noise_floor[NOISE_COUNT_W-1:0]);

    // ---------------------------------------------------------------- merging (model: _mergeable, _merge)
    // The swept slot k absorbs the lowest later slot j that is the same object (evclust_merge_search).
    // k stays in the sweep until no such j is left.
    function automatic signed [63:0] s64v;  // a v_int word, sign-extended
        input [V_INT_W-1:0] v;
        begin
            s64v = $signed({{(64 - V_INT_W){v[V_INT_W-1]}}, v});
        end
    endfunction
    function automatic signed [63:0] c64;  // a centre word
        input [CENTRE_W-1:0] v;
        begin
            c64 = u64({{(63 - CENTRE_W){1'b0}}, v});
        end
    endfunction
    function automatic signed [63:0] r64;  // a half-size word
        input [HALF_SIZE_W-1:0] v;
        begin
            r64 = u64({{(63 - HALF_SIZE_W){1'b0}}, v});
        end
    endfunction
    reg  [N*HALF_SIZE_W-1:0]        rx_bits, ry_bits;
    reg  [N*V_INT_W-1:0]            vix_bits, viy_bits;
    reg  [N*INTERVAL_UPDATES_W-1:0] vi_count_bits;
    reg  [N*GROW_W-1:0]             grow_bits;
    reg  [N*VREL_W-1:0]             vrel_bits;
    integer mj;
    always @* begin
        for (mj = 0; mj < N; mj = mj + 1) begin
            rx_bits[mj*HALF_SIZE_W +: HALF_SIZE_W] = rx[mj];
            ry_bits[mj*HALF_SIZE_W +: HALF_SIZE_W] = ry[mj];
            vix_bits[mj*V_INT_W +: V_INT_W] = vix[mj];
            viy_bits[mj*V_INT_W +: V_INT_W] = viy[mj];
            vi_count_bits[mj*INTERVAL_UPDATES_W +: INTERVAL_UPDATES_W] = vi_count[mj];
            grow_bits[mj*GROW_W +: GROW_W] = grow[mj];
            vrel_bits[mj*VREL_W +: VREL_W] = vrel[mj];
        end
    end
    wire              merge_found;
    wire [SLOT_W-1:0] merge_j;
    evclust_merge_search #(
        .N(N), .SLOT_BITS(SLOT_W), .CENTRE_BITS(CENTRE_W), .HALF_BITS(HALF_SIZE_W), .V_BITS(V_INT_W), .COUNT_BITS(INTERVAL_UPDATES_W),
        .V_TOL_BITS(CFG_MERGE_V_TOL_W), .GROW_BITS(GROW_W), .VREL_BITS(VREL_W)
    ) merge_search (
        .k(k), .valid(valid_bits), .centre_x(px_bits), .centre_y(py_bits), .half_x(rx_bits), .half_y(ry_bits),
        .v_x(vix_bits), .v_y(viy_bits), .measured(vi_count_bits), .grow(grow_bits), .vrel(vrel_bits), .v_tol(cfg_merge_v_tol),
        .found(merge_found), .j(merge_j)
    );

    // The weighted centre (A_k P_k + A_j P_j) / (A_k + A_j), floored, by two iterative dividers.
    localparam integer MOMENT_W = MERGE_MOMENT_W;
    reg  [SLOT_W-1:0]     m_j;          // the slot being absorbed
    reg                   m_started;    // MERGE: the dividers have their operands
    wire signed [63:0]    m_act_j = REFERENCED ? ref_dec_port_b : u64({{(63 - ACT_ROW_W){1'b0}}, act_b});  // (the paper's: not decayed yet)
    wire signed [63:0]    m_weight = a_decayed + m_act_j;
    wire signed [63:0]    m_moment_x = a_decayed * c64(px[k]) + m_act_j * c64(px[m_j]);
    wire signed [63:0]    m_moment_y = a_decayed * c64(py[k]) + m_act_j * c64(py[m_j]);
    wire                  div_start = state == ST_MERGE && !m_started;
    wire                  div_x_done, div_y_done;
    wire [MOMENT_W-1:0]   div_x_q, div_y_q;
    wire [ACTIVITY_W:0]   unused_left_x, unused_left_y;
`ifdef FORMAL
    wire [$clog2(MOMENT_W + 1)-1:0] f_merge_x_count, f_merge_y_count;  // the dividers' steps to go (evclust_core_props.vh)
`endif
    evclust_udiv #(.NUM_W(MOMENT_W), .DEN_W(ACTIVITY_W + 1)) div_x (
        .clk(clk), .rst(dp_rst), .start(div_start),
        .numerator(m_moment_x[MOMENT_W-1:0]), .denominator(m_weight[ACTIVITY_W:0]),
        .done(div_x_done), .quotient(div_x_q), .remainder_out(unused_left_x)
`ifdef FORMAL
        , .f_count(f_merge_x_count)
`endif
    );
    evclust_udiv #(.NUM_W(MOMENT_W), .DEN_W(ACTIVITY_W + 1)) div_y (
        .clk(clk), .rst(dp_rst), .start(div_start),
        .numerator(m_moment_y[MOMENT_W-1:0]), .denominator(m_weight[ACTIVITY_W:0]),
        .done(div_y_done), .quotient(div_y_q), .remainder_out(unused_left_y)
`ifdef FORMAL
        , .f_count(f_merge_y_count)
`endif
    );
    wire m_write = state == ST_MERGE && m_started && div_x_done && div_y_done;  // the merge's last cycle

    // The merged slot: the survivor (reported before, else the more active) gives the identity,
    // velocities, colour and histogram; the box covers both boxes; activities and counts add.
    wire                  m_from_j = (ever_reported[m_j] && !ever_reported[k])
                                  || (ever_reported[m_j] == ever_reported[k] && m_act_j > a_decayed);
    wire [SLOT_W-1:0]     m_surv = m_from_j ? m_j : k;
    wire signed [63:0]    m_px = m_weight == 0 ? c64(px[k]) : u64({{(63 - CENTRE_W){1'b0}}, div_x_q[CENTRE_W-1:0]});
    wire signed [63:0]    m_py = m_weight == 0 ? c64(py[k]) : u64({{(63 - CENTRE_W){1'b0}}, div_y_q[CENTRE_W-1:0]});
    wire signed [63:0]    m_lo_x = min64(c64(px[k]) - (r64(rx[k]) <<< UP), c64(px[m_j]) - (r64(rx[m_j]) <<< UP));
    wire signed [63:0]    m_hi_x = -min64(-(c64(px[k]) + (r64(rx[k]) <<< UP)), -(c64(px[m_j]) + (r64(rx[m_j]) <<< UP)));
    wire signed [63:0]    m_lo_y = min64(c64(py[k]) - (r64(ry[k]) <<< UP), c64(py[m_j]) - (r64(ry[m_j]) <<< UP));
    wire signed [63:0]    m_hi_y = -min64(-(c64(py[k]) + (r64(ry[k]) <<< UP)), -(c64(py[m_j]) + (r64(ry[m_j]) <<< UP)));
    wire signed [63:0]    m_rx = min64((m_hi_x - m_lo_x) >>> (UP + 1), K_R_MAX);
    wire signed [63:0]    m_ry = min64((m_hi_y - m_lo_y) >>> (UP + 1), K_R_MAX);
    wire signed [63:0]    m_ppx = saturate(c64(m_from_j ? ppx_b : ppx_a) + m_px - c64(px[m_surv]), 0, LAST_X);  // inside the sensor
    wire signed [63:0]    m_ppy = saturate(c64(m_from_j ? ppy_b : ppy_a) + m_py - c64(py[m_surv]), 0, LAST_Y);
    wire signed [63:0]    m_act = saturate(m_weight, 0, MAX_ACT);
    wire signed [63:0]    m_evc_full = u64({{(63 - EVENTS_IN_INTERVAL_W){1'b0}}, ev_count_a}) + u64({{(63 - EVENTS_IN_INTERVAL_W){1'b0}}, ev_count_b});
    wire signed [63:0]    m_evc = saturate(m_evc_full, 0, MAX_EVCOUNT);

    // The end of a filter step, held until the object unit takes it; the next step waits in
    // PHASE until then, so a step's records never follow the next step's mark.
    reg  step_pending;
    assign step_valid = step_pending && !rec_valid;
    wire phase_hold = step_pending || (UPDATE_DELAY > 1 && (h_live || h_bg_live));  // (or stage H still to drain through C)

    // tau boundaries since the last filter step, from the phase counter (33 bits: a 32-bit time
    // difference plus the phase); T_frame/(n tau), nothing once n reaches 2^FRAME_PER_TAU_W.
    wire [32:0] phase = {{(33 - TAU_PHASE_W){1'b0}}, tau_phase} + {1'b0, e_t - t_filter};
    // The filter step's first cycle (PHASE) settles the usual cases, fewer than two boundaries,
    // by comparison; more take two iterative divisions (phase / tau, then T_frame / count).
    reg  [32:0] phase_q;     // the phase at the filter step's event
    reg  [1:0]  phase_step;  // PHASE: deciding, dividing the phase, dividing the frame period
    wire        phase_start = state == ST_PHASE && !moving && phase_step == PHASE_DECIDE && !phase_hold && phase_q >= TAU[31:0] * 33'd2;
    wire        by_tau_done, frame_done;
    wire [32:0] by_tau_q;
    wire [TAU_PHASE_W:0] by_tau_left;
`ifdef FORMAL
    wire [$clog2(33 + 1)-1:0] f_by_tau_count;                  // the dividers' steps to go (evclust_core_props.vh)
    wire [$clog2(FRAME_PER_TAU_W + 1)-1:0] f_frame_count;
`endif
    evclust_udiv #(.NUM_W(33), .DEN_W(TAU_PHASE_W + 1)) div_phase (
        .clk(clk), .rst(dp_rst), .start(phase_start),
        .numerator(phase_q), .denominator(TAU[TAU_PHASE_W:0]),
        .done(by_tau_done), .quotient(by_tau_q), .remainder_out(by_tau_left)
`ifdef FORMAL
        , .f_count(f_by_tau_count)
`endif
    );
    wire        many_boundaries = by_tau_q >= (33'd1 << FRAME_PER_TAU_W);
    wire        no_boundary = phase_q < {1'b0, TAU[31:0]};
    wire        frame_start = state == ST_PHASE && !moving && phase_step == PHASE_BY_TAU && by_tau_done && !many_boundaries;
    wire [FRAME_PER_TAU_W-1:0] frame_q;
    wire [FRAME_PER_TAU_W-1:0] unused_frame_left;
    evclust_udiv #(.NUM_W(FRAME_PER_TAU_W), .DEN_W(FRAME_PER_TAU_W)) div_frame (
        .clk(clk), .rst(dp_rst), .start(frame_start),
        .numerator(K_FRAME_PER_TAU), .denominator(by_tau_q[FRAME_PER_TAU_W-1:0]),
        .done(frame_done), .quotient(frame_q), .remainder_out(unused_frame_left)
`ifdef FORMAL
        , .f_count(f_frame_count)
`endif
    );

    // 1/|palette_j - BG|^2 for the mixing rule (model: refresh_mixing), one entry per cycle.
    wire [CLASS_W-1:0] refresh_j = index[CLASS_W-1:0];
    wire signed [63:0] w_y = u64({55'd0, palette_y[refresh_j * 8 +: 8]}) - (u64({{(63 - BACKGROUND_W){1'b0}}, bg_y}) >>> FB);
    wire signed [63:0] w_cb = u64({55'd0, palette_cb[refresh_j * 8 +: 8]}) - (u64({{(63 - BACKGROUND_W){1'b0}}, bg_cb}) >>> FB);
    wire signed [63:0] w_cr = u64({55'd0, palette_cr[refresh_j * 8 +: 8]}) - (u64({{(63 - BACKGROUND_W){1'b0}}, bg_cr}) >>> FB);
    wire signed [63:0] ww = w_y * w_y + w_cb * w_cb + w_cr * w_cr;  // < 3 * 255^2 < 2^18
    // 2^32 / ww in a pipelined divider, INV_STAGES cycles behind the entry fed (INIT and the
    // sweep feed one entry per cycle; the sweep's tail and INIT wait for it).
    wire               inv_en = state == ST_INIT || tail_en;
    wire               inv_live = index < N_ENTRIES && (state == ST_INIT || (mixing && !bg_fixed));
    wire [CLASS_W+1:0] inv_tag;
    wire [INV_WW_W-1:0] inverse;
    evclust_pipediv #(.Q_W(INV_WW_W), .DEN_W(18), .STEP(SWEEP_DIV_STEP), .TAG_W(CLASS_W + 2)) div_inverse (
        .clk(clk), .rst(dp_rst), .en(inv_en),
        .remainder_in(18'd0), .bits_in({1'b1, {(INV_WW_W - 1){1'b0}}}), .divisor(ww == 64'sd0 ? 18'd1 : ww[17:0]),
        .tag_in({inv_live, ww == 64'sd0, refresh_j}),
        .quotient(inverse), .tag_out(inv_tag)
    );
    wire               inv_out_live = inv_tag[CLASS_W+1];
    wire [CLASS_W-1:0] inv_out_j = inv_tag[CLASS_W-1:0];
    wire [INV_WW_W-1:0] refreshed = inv_tag[CLASS_W] ? {INV_WW_W{1'b0}} : inverse;

    // ---------------------------------------------------------------- the event's decision
    // EXEC: update the slot found, or create in a free one; SCAN finds the weakest; EVICT
    // creates there if it is weak enough, else drops the event.
    wire scan_last = index == LAST_SLOT;
    wire init_done = index >= LAST_INIT && (CREATE_SUPPORT == 0 || init_cell == LAST_CELL);
    // Against a reference time every Ã has the one reference: the weakest now has the least Ã,
    // and A < A_valid is Ã < A_valid * w (model: _slot_for_new).
    wire scan_weaker = (REFERENCED ? act_a : a_decayed[ACT_ROW_W-1:0]) < weakest_a || index == {SWEEP_W{1'b0}};
    wire signed [63:0] weakest_wide = u64({{(63 - ACT_ROW_W){1'b0}}, weakest_a});
    wire evict = REFERENCED ? (weakest_wide <<< FA) < K_A_VALID * u64({{(63 - ACT_ROW_W){1'b0}}, e_weight}) : weakest_wide < K_A_VALID;
    reg              do_update, do_create, finish, split;
    reg [SLOT_W-1:0] create_slot;
    reg [2:0]        action;
    reg [SLOT_W-1:0] action_slot;
    // split (UPDATE_DELAY >= 1): a creation while an update is due to commit (C) takes two
    // cycles, the commit in the first (one write port), the creation, as decided, in the second.
    always @* begin
        do_update = 1'b0;
        do_create = 1'b0;
        finish = 1'b0;
        split = 1'b0;
        create_slot = e_free_slot;
        action = TRACE_UPDATE;
        action_slot = e_slot;
        if (state == ST_EXEC && creating) begin
            do_create = 1'b1;
            finish = 1'b1;
            create_slot = creating_slot;
            action = TRACE_CREATE;
            action_slot = creating_slot;
        end else if (state == ST_EXEC) begin
            if (e_hit) begin
                do_update = 1'b1;
                finish = 1'b1;
            end else if (!supported) begin  // no cluster, and nothing nearby to start one with
                finish = 1'b1;
                action = TRACE_UNSUPPORTED;
                action_slot = {SLOT_W{1'b0}};
            end else if (e_free) begin
                split = UPDATE_DELAY != 0 && c_live;
                do_create = !split;
                finish = !split;
                action = TRACE_CREATE;
                action_slot = e_free_slot;
            end
        end else if (state == ST_EVICT) begin
            // (an eviction of the slot the event before updates voids that update: no split)
            split = UPDATE_DELAY != 0 && c_live && !creating && evict && weakest != c_slot;
            finish = !split;
            do_create = evict && !split;
            create_slot = weakest;
            action = evict ? TRACE_EVICT : TRACE_DROP;
            action_slot = evict ? weakest : {SLOT_W{1'b0}};
        end
    end
    assign commit_moment = UPDATE_DELAY != 0 && (finish || split || state == ST_PHASE);
    wire do_commit = commit_moment && c_live && !(do_create && create_slot == c_slot);
    // (a split's background update waits for its second cycle: the creation's own background step reads the background without it)
    wire do_commit_bg = commit_moment && c_bg_live && !split;
    wire upd_write = do_update && UPDATE_DELAY == 0;  // EXEC writes its update itself
    // What C takes as an event finishes or in PHASE: the update of the event (UPDATE_DELAY = 1),
    // or stage H's (2), void if this event's creation takes its slot.
    localparam H_STAGE = UPDATE_STAGES == 2;  // stage H exists: the update's second half a stage later
    assign h_load = H_STAGE && finish && !split;
    wire c_load = UPDATE_DELAY != 0 && ((finish && !split) || (H_STAGE && state == ST_PHASE));
    wire to_c_live = H_STAGE ? h_live && !(do_create && create_slot == h_slot) : do_update;
    wire to_c_bg_live = H_STAGE ? h_bg_live : bg_learns;
    wire [SLOT_W-1:0] to_c_slot = H_STAGE ? h_slot : e_slot;
    wire [EV_T_W-1:0] to_c_t = H_STAGE ? h_t : e_t;
    wire [CLASS_W-1:0] to_c_class = vote_class;  // stage H's with H (the palette's second half), else the event's
    wire [VOTE_W-1:0] to_c_vote = vote;
    wire slot_write = upd_write || do_commit;         // an update lands in slot sw_slot
    // The background learns from every event that is not a reported object's.
    wire signed [63:0] bg_y_next = alpha_step(u64({{(63 - BACKGROUND_W){1'b0}}, bg_y}), u64({{(63 - CW){1'b0}}, e_lum}), K_B_BG, BETA_BG_FRAC, FB, 1'b0);
    wire signed [63:0] bg_cb_next = alpha_step(u64({{(63 - BACKGROUND_W){1'b0}}, bg_cb}), u64({{(63 - CW){1'b0}}, e_cb}), K_B_BG, BETA_BG_FRAC, FB, 1'b0);
    wire signed [63:0] bg_cr_next = alpha_step(u64({{(63 - BACKGROUND_W){1'b0}}, bg_cr}), u64({{(63 - CW){1'b0}}, e_cr}), K_B_BG, BETA_BG_FRAC, FB, 1'b0);
    wire signed [63:0] bg_y_d = bg_y_next - u64({{(63 - BACKGROUND_W){1'b0}}, bg_y});  // its increments (UPDATE_DELAY >= 1)
    wire signed [63:0] bg_cb_d = bg_cb_next - u64({{(63 - BACKGROUND_W){1'b0}}, bg_cb});
    wire signed [63:0] bg_cr_d = bg_cr_next - u64({{(63 - BACKGROUND_W){1'b0}}, bg_cr});
    wire signed [63:0] gamma_new = gamma_from_activity(ONE_A, gamma_mode, K_GAMMA_GLOBAL, K_GPA);
    wire sweep_due = {{(32 - EVERY_W){1'b0}}, since_filter} + 32'd1 >= {{(32 - EVERY_W){1'b0}}, K_FILTER_EVERY};
    // An update of a reported cluster is the object's colour, not the background's.
    wire bg_learns = finish && !bg_fixed && !(do_update && reported[e_slot]);
    wire sweep_advance = state == ST_SWEEP && (moving || !rec_valid || rec_ready);
    wire sweep_live = sweep_advance && index < N_SLOTS && valid[k];
    wire sweep_merge = sweep_live && !moving && !f_expire && merge_found;  // k absorbs merge_j first
    wire sweep_slot = sweep_live && !sweep_merge;                          // k's stage 0 (moving: its decay only)
    assign tail_en = sweep_advance && !sweep_merge && !moving;
    // The reference must move before the event in stage A goes on (model: _reference_passed).
    wire move_pending = REFERENCED && a_valid && ref_passed;
    wire move_due = state == ST_IDLE && move_pending;
    wire move_hold = UPDATE_DELAY > 1 && (h_live || h_bg_live);  // stage H still to drain through C

    // ---------------------------------------------------------------- derived slot fields
    // At most one slot's size is written per cycle (an update, a creation or a merge, each in
    // its own state), so one multiplier per product serves them all, and the interval
    // velocity changes only at a filter step's stage 0 (a merge copies the survivor's product).
    wire                   size_write = slot_write || do_create || m_write;
    wire [SLOT_W-1:0]      size_slot = m_write ? k : (slot_write ? sw_slot : create_slot);
    wire [HALF_SIZE_W-1:0] size_rx = m_write ? m_rx[HALF_SIZE_W-1:0] : (slot_write ? sw_rx : K_R_INIT);
    wire [HALF_SIZE_W-1:0] size_ry = m_write ? m_ry[HALF_SIZE_W-1:0] : (slot_write ? sw_ry : K_R_INIT);
    wire [HALF_SIZE_W-1:0] size_r = size_rx > size_ry ? size_rx : size_ry;
    wire signed [63:0]     d_scaled_seek = r64(size_r) * K_SEEK_SCALE;
    wire signed [63:0]     d_reach_x = reach(size_rx, K_SEEK, d_scaled_seek);
    wire signed [63:0]     d_reach_y = reach(size_ry, K_SEEK, d_scaled_seek);
    // the centre written with that size: the window moves with it
    wire [CENTRE_W-1:0]    size_px = m_write ? m_px[CENTRE_W-1:0] : (slot_write ? sw_px : {{(CENTRE_W - EV_XY_W - FP){1'b0}}, e_x, {FP{1'b0}}});
    wire [CENTRE_W-1:0]    size_py = m_write ? m_py[CENTRE_W-1:0] : (slot_write ? sw_py : {{(CENTRE_W - EV_XY_W - FP){1'b0}}, e_y, {FP{1'b0}}});
    wire [WINDOW_W-1:0]    d_window_x, d_window_y;
    evclust_seek_window #(.XY_BITS(EV_XY_W), .CENTRE_BITS(CENTRE_W), .REACH_BITS(REACH_W), .WINDOW_BITS(WINDOW_W)) window_x_unit (
        .centre(size_px), .reach(d_reach_x[REACH_W-1:0]), .window(d_window_x)
    );
    evclust_seek_window #(.XY_BITS(EV_XY_W), .CENTRE_BITS(CENTRE_W), .REACH_BITS(REACH_W), .WINDOW_BITS(WINDOW_W)) window_y_unit (
        .centre(size_py), .reach(d_reach_y[REACH_W-1:0]), .window(d_window_y)
    );
    wire signed [63:0]     d_grow = r64(size_r) * K_MERGE_SCALE;
    wire signed [63:0]     d_speed = abs64(s64v(f_vix[V_INT_W-1:0])) + abs64(s64v(f_viy[V_INT_W-1:0]));  // of the words written: <= 2^V_INT_W
    wire signed [63:0]     d_vrel = K_MERGE_V_REL * u64({{(63 - V_INT_W - 1){1'b0}}, d_speed[V_INT_W:0]});

    // The pipeline: stage A takes an event whenever it is empty or hands its event to stage B
    // in the same cycle; B (EXEC) takes it when B is empty (IDLE) or finishes an event that
    // starts no filter step. B writes at most one slot as it finishes, w, which the next
    // event's seek tests again.
    wire b_takes = (state == ST_IDLE || (finish && !sweep_due)) && !move_pending;
    wire a_advance = a_valid && b_takes;
    wire [SLOT_W-1:0] written_slot = UPDATE_DELAY == 0 ? (do_update ? e_slot : create_slot) : (do_create ? create_slot : c_slot);
    assign ev_ready = !dp_rst && (!a_valid || a_advance);  // no handshake during a reset or clear

    // ---------------------------------------------------------------- the FSM's next state
    // INIT -> IDLE; IDLE -> EXEC as stage A hands over; EXEC -> SCAN when no slot takes the
    // event; SCAN -> EVICT at the last slot; an event that finishes goes to PHASE when a filter
    // step is due (PHASE -> SWEEP <-> MERGE -> IDLE), else to IDLE, or straight to EXEC when A
    // hands over the next one in the same cycle.
    always @* begin
        state_next = state;
        case (state)
            ST_INIT: if (init_done) state_next = ST_IDLE;
            ST_IDLE: if (move_due) state_next = ST_PHASE;
            ST_EXEC: if (!finish && !split) state_next = ST_SCAN;
            ST_SCAN: if (scan_last) state_next = ST_EVICT;
            ST_SWEEP: if (moving) begin
                          if (index == LAST_SLOT) state_next = ST_IDLE;
                      end else if (sweep_merge) state_next = ST_MERGE;
                      else if (sweep_advance && index == LAST_SWEEP) state_next = ST_IDLE;
            ST_PHASE: if (moving) begin
                          if (!move_hold) state_next = ST_SWEEP;
                      end else case (phase_step)
                PHASE_DECIDE: if (!phase_hold && (no_boundary || !phase_start)) state_next = ST_SWEEP;
                PHASE_BY_TAU: if (by_tau_done && many_boundaries) state_next = ST_SWEEP;
                default: if (frame_done) state_next = ST_SWEEP;
            endcase
            ST_MERGE: if (m_write) state_next = ST_SWEEP;
            default: ;
        endcase
        if (finish)
            state_next = sweep_due ? ST_PHASE : ST_IDLE;
        if (a_advance)
            state_next = ST_EXEC;
    end

    always @(posedge clk)
        state <= dp_rst ? ST_INIT : state_next;

    // ---------------------------------------------------------------- status counters
    // What this cycle adds to each counter of evclust_regs, registered into count_inc. The
    // saturations are the model's `_store` sites (fixed_model.py), each counted where it applies.
    wire               stage0 = sweep_slot && !moving && !f_expire;
    // Against a reference time, what an activity's decay to the reference saturates (model:
    // _move_reference): the background's as PHASE ends, a slot's where it is first decayed.
    wire               phase_ends = state == ST_PHASE && state_next == ST_SWEEP;
    wire [1:0]         ref_saturations = !REFERENCED ? 2'd0
        : (phase_ends ? outside(u64({{(63 - ACT_ROW_W){1'b0}}, ref_dec_b}), 0, MAX_ACT) : 2'd0)
        + ((sweep_slot || m_write) && !k_decayed ? outside(u64({{(63 - ACT_ROW_W){1'b0}}, ref_dec_a}), 0, MAX_ACT) : 2'd0)
        + (m_write ? outside(u64({{(63 - ACT_ROW_W){1'b0}}, ref_dec_b}), 0, MAX_ACT) : 2'd0);
    wire               tail_out = tail_en && t2_live;  // a slot leaves the tail (T2)
    wire               bg_counts = finish && !(do_update && reported[e_slot]) && K_NOISE_GATE != 0;
    reg [COUNT_W-1:0]  inc;
    always @* begin
        inc = {COUNT_W{1'b0}};
        inc[COUNT_EVENTS * COUNTER_INC_W +: 2] = {1'b0, ev_valid && ev_ready};
        inc[COUNT_UPDATES * COUNTER_INC_W +: 2] = {1'b0, do_update};
        inc[COUNT_CREATES * COUNTER_INC_W +: 2] = {1'b0, do_create};
        inc[COUNT_EVICTIONS * COUNTER_INC_W +: 2] = {1'b0, state == ST_EVICT && finish && evict};
        inc[COUNT_DROPS * COUNTER_INC_W +: 2] = {1'b0, state == ST_EVICT && finish && !evict};
        inc[COUNT_UNSUPPORTED * COUNTER_INC_W +: 2] = {1'b0, finish && action == TRACE_UNSUPPORTED};
        inc[COUNT_EXPIRIES * COUNTER_INC_W +: 2] = {1'b0, sweep_slot && !moving && f_expire};
        inc[COUNT_EXITS * COUNTER_INC_W +: 2] = {1'b0, tail_out && f_exit};
        inc[COUNT_MERGES * COUNTER_INC_W +: 2] = {1'b0, m_write};
        inc[COUNT_RECORDS * COUNTER_INC_W +: 2] = {1'b0, tail_out && !f_exit && f_report};
        inc[COUNT_SAT_ACTIVITY * COUNTER_INC_W +: 2] = (slot_write ? sw_act_saturations : 2'd0)
            + (bg_counts ? outside(bg_counted_full, 0, MAX_ACT_ROW) : 2'd0)
            + (m_write ? outside(m_weight, 0, MAX_ACT) : 2'd0) + ref_saturations;
        inc[COUNT_SAT_CENTRE_STEP * COUNTER_INC_W +: 2] = do_update ? up_step_saturations : 2'd0;
        inc[COUNT_SAT_MCM_STEP * COUNTER_INC_W +: 2] = (H_STAGE ? h_fresh : do_update) ? up_mcm_saturations : 2'd0;
        inc[COUNT_SAT_EVENTS_IN_INTERVAL * COUNTER_INC_W +: 2] = (slot_write ? cm_evc_saturations : 2'd0)
            + (m_write ? outside(m_evc_full, 0, MAX_EVCOUNT) : 2'd0);
        inc[COUNT_SAT_GAMMA * COUNTER_INC_W +: 2] = (stage0 && f_gamma_by_activity ? outside(f_gamma_activity, 0, MAX_GAMMA) : 2'd0)
            + (stage0 && f_gamma_by_count ? outside(f_gamma_count, 0, MAX_GAMMA) : 2'd0);
        inc[COUNT_SAT_V_INT * COUNTER_INC_W +: 2] = stage0 && boundaries != 33'd0 ? outside(f_mx_full, MIN_VI, MAX_VI) + outside(f_my_full, MIN_VI, MAX_VI) : 2'd0;
        inc[COUNT_SAT_V_MCM * COUNTER_INC_W +: 2] = (tail_en && t_live && t_correct ? {1'b0, t_over_x} + {1'b0, t_over_y} : 2'd0)  // (at T1)
            + (do_commit ? cm_vm_saturations : 2'd0);  // (without delay, V's alpha step cannot leave its format)
    end
    assign idle = state == ST_IDLE && !a_valid && !rec_valid && !step_pending;

    // ---------------------------------------------------------------- the slot row's write port
    // One writer per cycle; the fields it leaves keep their value, read at port A (the written
    // slot's, for an update, a merge or the sweep; a creation writes every field).
    // Against a reference time nothing reads a slot's residual: writing it 0 leaves the paper's
    // decay unit (its dt * (1/T_half) multiply) without a reader, so that build has none.
    wire [DECAY_RESIDUAL_W-1:0] row_residual = REFERENCED ? {DECAY_RESIDUAL_W{1'b0}} : dec_residual;
    // A delayed update reads its slot at port E, so port A's address (the scan, the sweep, a
    // merge) does not hang on the event's search; without delay EXEC decays at port A.
    assign row_a_slot = state == ST_EXEC && UPDATE_DELAY == 0 ? e_slot : k;
    assign row_b_slot = state == ST_MERGE ? m_j : (commit_reads ? c_slot : t);
    always @* begin
        row_we = 1'b0;
        row_w_slot = k;
        row_w = row_a;
        if (slot_write) begin  // an update lands: EXEC's own (port A) or the event before's (port B)
            row_we = 1'b1;
            row_w_slot = sw_slot;
            row_w = sw_row;
            row_w[ROW_ACT +: ACT_ROW_W] = sw_act;
            row_w[ROW_RESIDUAL +: DECAY_RESIDUAL_W] = row_residual;
            row_w[ROW_T_LAST +: T_LAST_W] = sw_t;
            row_w[ROW_VMX +: V_MCM_W] = sw_vmx;
            row_w[ROW_VMY +: V_MCM_W] = sw_vmy;
            row_w[ROW_NORM +: MCM_NORM_W] = sw_norm;
            row_w[ROW_COL_Y +: COLOUR_W] = sw_cy;
            row_w[ROW_COL_CB +: COLOUR_W] = sw_ccb;
            row_w[ROW_COL_CR +: COLOUR_W] = sw_ccr;
            row_w[ROW_HIST +: P * HIST_W] = cm_hist;
            row_w[ROW_EV_COUNT +: EVENTS_IN_INTERVAL_W] = cm_evc;
        end
        if (do_create) begin
            row_we = 1'b1;
            row_w_slot = create_slot;
            row_w[ROW_ID +: ID_W] = next_id;
            row_w[ROW_PPX +: CENTRE_W] = {{(CENTRE_W - EV_XY_W - FP){1'b0}}, e_x, {FP{1'b0}}};
            row_w[ROW_PPY +: CENTRE_W] = {{(CENTRE_W - EV_XY_W - FP){1'b0}}, e_y, {FP{1'b0}}};
            row_w[ROW_ACT +: ACT_ROW_W] = REFERENCED ? e_weight : ONE_A[ACT_ROW_W-1:0];
            row_w[ROW_RESIDUAL +: DECAY_RESIDUAL_W] = {DECAY_RESIDUAL_W{1'b0}};
            row_w[ROW_T_LAST +: T_LAST_W] = e_t;
            row_w[ROW_GAMMA +: GAMMA_W] = gamma_new[GAMMA_W-1:0];
            row_w[ROW_VMX +: V_MCM_W] = {V_MCM_W{1'b0}};
            row_w[ROW_VMY +: V_MCM_W] = {V_MCM_W{1'b0}};
            row_w[ROW_NORM +: MCM_NORM_W] = {MCM_NORM_W{1'b0}};
            row_w[ROW_EV_COUNT +: EVENTS_IN_INTERVAL_W] = {EVENTS_IN_INTERVAL_W{1'b0}};
            row_w[ROW_COL_Y +: COLOUR_W] = {e_lum, {FC{1'b0}}};
            row_w[ROW_COL_CB +: COLOUR_W] = {e_cb, {FC{1'b0}}};
            row_w[ROW_COL_CR +: COLOUR_W] = {e_cr, {FC{1'b0}}};
            row_w[ROW_HIST +: P * HIST_W] = {(P * HIST_W){1'b0}};
        end
        if (m_write) begin  // k absorbs m_j: the survivor's identity, velocity, colour and histogram
            row_we = 1'b1;
            row_w_slot = k;
            if (m_from_j)
                row_w = row_b;
            row_w[ROW_ACT +: ACT_ROW_W] = m_act[ACT_ROW_W-1:0];
            row_w[ROW_RESIDUAL +: DECAY_RESIDUAL_W] = row_residual;
            row_w[ROW_T_LAST +: T_LAST_W] = e_t;
            row_w[ROW_PPX +: CENTRE_W] = m_ppx[CENTRE_W-1:0];
            row_w[ROW_PPY +: CENTRE_W] = m_ppy[CENTRE_W-1:0];
            row_w[ROW_EV_COUNT +: EVENTS_IN_INTERVAL_W] = m_evc[EVENTS_IN_INTERVAL_W-1:0];
        end
        if (sweep_slot) begin  // stage 0
            row_we = 1'b1;
            row_w_slot = k;
            row_w[ROW_ACT +: ACT_ROW_W] = act_now;
            row_w[ROW_RESIDUAL +: DECAY_RESIDUAL_W] = row_residual;
            row_w[ROW_T_LAST +: T_LAST_W] = e_t;
            if (!f_expire && !moving) begin
                row_w[ROW_GAMMA +: GAMMA_W] = f_gamma[GAMMA_W-1:0];
                row_w[ROW_EV_COUNT +: EVENTS_IN_INTERVAL_W] = f_evc[EVENTS_IN_INTERVAL_W-1:0];
                if (boundaries != 33'd0) begin
                    row_w[ROW_PPX +: CENTRE_W] = px[k];
                    row_w[ROW_PPY +: CENTRE_W] = py[k];
                end
            end
        end
        if (dp_rst)
            row_we = 1'b0;
    end

    integer i;
    always @(posedge clk) begin
        count_inc <= rst ? {COUNT_W{1'b0}} : inc;
        trace_valid <= 1'b0;
        if (rec_valid && rec_ready)
            rec_valid <= 1'b0;
        if (step_valid && step_ready)
            step_pending <= 1'b0;
        if (dp_rst) begin
            step_pending <= 1'b0;
            step_t <= 32'd0;
            index <= {SWEEP_W{1'b0}};
            rec_valid <= 1'b0;
            rec_data <= {REC_W{1'b0}};
            trace_data <= {TRACE_W{1'b0}};
            bg_act <= {ACT_ROW_W{1'b0}};
            moving <= 1'b0;
            k_decayed <= 1'b0;
            ref_m <= 64'd0;
            bg_residual <= {DECAY_RESIDUAL_W{1'b0}};
            bg_t <= {EV_T_W{1'b0}};
            init_cell <= {CELL_W{1'b0}};
            m_j <= {SLOT_W{1'b0}};
            m_started <= 1'b0;
            bg_y <= bg_init_y;
            bg_cb <= bg_init_cb;
            bg_cr <= bg_init_cr;
            inv_ww <= {(P * INV_WW_W){1'b0}};
            next_id <= {ID_W{1'b0}};
            step <= 32'd0;
            t_filter <= {EV_T_W{1'b0}};
            tau_phase <= {TAU_PHASE_W{1'b0}};
            since_filter <= {EVERY_W{1'b0}};
            started <= 1'b0;
            a_valid <= 1'b0;
            seek_w <= {SLOT_W{1'b0}};
            c_live <= 1'b0;
            c_bg_live <= 1'b0;
            h_live <= 1'b0;
            h_bg_live <= 1'b0;
            h_fresh <= 1'b0;
            // Stage H's fields pass to C whether live or not, and C's slot is the next seek's to
            // retest when nothing is written: both defined from reset.
            c_slot <= {SLOT_W{1'b0}};
            h_slot <= {SLOT_W{1'b0}};
            h_t <= {EV_T_W{1'b0}};
            h_dbg_y <= {DB_W{1'b0}};
            h_dbg_cb <= {DB_W{1'b0}};
            h_dbg_cr <= {DB_W{1'b0}};
            creating <= 1'b0;
            p_live <= 1'b0;
            t2_live <= 1'b0;
            boundaries <= 33'd0;
            per_frame <= {FRAME_PER_TAU_W{1'b0}};
            for (i = 0; i < N; i = i + 1) begin
                valid[i] <= 1'b0;
                reported[i] <= 1'b0;
            end
        end else begin
            case (state)
                ST_INIT: begin  // the mixing rule's table for the initial background; the support map cleared
                    if (index < LAST_INIT)
                        index <= index + 1'b1;
                    if (CREATE_SUPPORT != 0) begin
                        support_seen[init_cell] <= 1'b0;
                        if (init_cell != LAST_CELL)  // a small map waits here for the mixing table
                            init_cell <= init_cell + 1'b1;
                    end
                    if (init_done)
                        index <= {SWEEP_W{1'b0}};
                end
                ST_EXEC: if (!finish)
                    index <= {SWEEP_W{1'b0}};
                ST_SCAN: begin
                    if (scan_weaker) begin
                        weakest <= k;
                        weakest_a <= REFERENCED ? act_a : a_decayed[ACT_ROW_W-1:0];
                    end
                    index <= index + 1'b1;
                end
                ST_SWEEP: if (moving) begin  // the reference's move: every slot's activity decayed, nothing else
                    index <= index + 1'b1;
                    if (index == LAST_SLOT) begin
                        index <= {SWEEP_W{1'b0}};
                        moving <= 1'b0;
                    end
                end else if (sweep_merge) begin
                    m_j <= merge_j;
                end else if (sweep_advance) begin
                    index <= index + 1'b1;
                    k_decayed <= 1'b0;
                    if (index == LAST_SWEEP) begin
                        step <= step + 32'd1;
                        t_filter <= e_t;
                        step_pending <= 1'b1;
                        step_t <= e_t[31:0];
                    end
                end
                ST_IDLE: if (move_due) begin
                    moving <= 1'b1;
                    index <= {SWEEP_W{1'b0}};  // the pass starts at slot 0, wherever the last sweep or scan left it
                end
                ST_PHASE: if (!moving) case (phase_step)  // tau boundaries since the last step and T_frame / (n tau)
                    PHASE_DECIDE: if (phase_hold) begin
                        // the last step's end not taken yet
                    end else if (no_boundary) begin
                        boundaries <= 33'd0;
                        tau_phase <= phase_q[TAU_PHASE_W-1:0];
                        per_frame <= K_FRAME_PER_TAU;  // T_frame / tau: n counts as 1
                    end else if (!phase_start) begin  // one boundary
                        boundaries <= 33'd1;
                        tau_phase <= phase_q[TAU_PHASE_W-1:0] - TAU[TAU_PHASE_W-1:0];
                        per_frame <= K_FRAME_PER_TAU;
                    end else begin
                        phase_step <= PHASE_BY_TAU;
                    end
                    PHASE_BY_TAU: if (by_tau_done) begin
                        boundaries <= by_tau_q;
                        tau_phase <= by_tau_left[TAU_PHASE_W-1:0];
                        if (many_boundaries) begin  // T_frame / (n tau) leaves nothing
                            per_frame <= {FRAME_PER_TAU_W{1'b0}};
                        end else begin
                            phase_step <= PHASE_FRAME;
                        end
                    end
                    default: if (frame_done) begin
                        per_frame <= frame_q;
                    end
                endcase
                ST_MERGE: begin  // the dividers started in the first cycle; the slot written in the last
                    m_started <= 1'b1;
                    if (m_write) begin
                        m_started <= 1'b0;  // SWEEP then takes the same slot again: it may absorb another
                        k_decayed <= 1'b1;  // (with its activity decayed)
                    end
                end
                default: ;
            endcase

            // Against a reference time, the end of PHASE moves the reference to the step's event
            // (or, moving, to the event in A): the background decayed, the slots' steps kept.
            if (REFERENCED && phase_ends) begin
                ref_m <= ref_steps;
                bg_act <= ref_dec_port_b[ACT_ROW_W-1:0];
                bg_residual <= ref_residual;
                bg_t <= ref_time;
            end

            // The end of an event: trace, background, the filter-step counter.
            if (finish) begin
                trace_valid <= 1'b1;
                trace_data <= {TRACE_W{1'b0}};
                trace_data[TRACE_ACTION_LSB +: TRACE_ACTION_W] <= action;
                trace_data[TRACE_SLOT_LSB +: SLOT_W] <= action_slot;
                if (CREATE_SUPPORT != 0) begin
                    support_t[ev_cell] <= e_t;
                    support_seen[ev_cell] <= 1'b1;
                end
                // The background's activity counts the event if no reported cluster took it, and
                // is decayed to the filter step's time before a sweep.
                // Against a reference time it adds the event's weight (when the noise gate reads
                // it, as the model), and PHASE decays it to the step's time.
                if (REFERENCED) begin
                    if (!(do_update && reported[e_slot]) && K_NOISE_GATE != 0)
                        bg_act <= bg_counted[ACT_ROW_W-1:0];
                end else if (!(do_update && reported[e_slot])) begin
                    bg_act <= bg_counted[ACT_ROW_W-1:0];
                    bg_residual <= bg_dec_residual;
                    bg_t <= e_t;
                end else if (sweep_due) begin
                    bg_act <= bg_dec_wide[ACT_ROW_W-1:0];
                    bg_residual <= bg_dec_residual;
                    bg_t <= e_t;
                end
                if (bg_learns && UPDATE_DELAY == 0) begin
                    bg_y <= bg_y_next[BACKGROUND_W-1:0];
                    bg_cb <= bg_cb_next[BACKGROUND_W-1:0];
                    bg_cr <= bg_cr_next[BACKGROUND_W-1:0];
                end
                if (sweep_due) begin
                    since_filter <= {EVERY_W{1'b0}};
                    phase_q <= phase;
                    phase_step <= PHASE_DECIDE;
                    index <= {SWEEP_W{1'b0}};
                end else begin
                    since_filter <= since_filter + 1'b1;
                end
            end

            // The pipeline moves: A to B, the port to A.
            if (a_advance) begin
                e_t <= a_t;
                e_weight <= a_weight;
                e_x <= a_x;
                e_y <= a_y;
                e_lum <= a_lum;
                e_cb <= a_cb;
                e_cr <= a_cr;
                e_seek_first <= seek_first;
                e_seek_second <= seek_second;
                e_free_first <= free_first;
                e_free_second <= free_second;
                if (state != ST_IDLE)
                    seek_w <= written_slot;
            end
            if (ev_valid && ev_ready) begin
                a_t <= in_t;
                a_x <= in_x;
                a_y <= in_y;
                a_lum <= in_lum;
                a_cb <= in_cb;
                a_cr <= in_cr;
                if (!started) begin  // tau boundaries count from the first event
                    started <= 1'b1;
                    t_filter <= in_t;
                    tau_phase <= {TAU_PHASE_W{1'b0}};
                    if (REFERENCED) begin  // so does the activity's reference
                        bg_t <= in_t;
                        bg_residual <= {DECAY_RESIDUAL_W{1'b0}};
                    end
                end
            end
            if (ev_valid && ev_ready)
                a_valid <= 1'b1;
            else if (a_advance)
                a_valid <= 1'b0;

            // The commit (UPDATE_DELAY >= 1): the oldest update in flight (C) lands; C takes the
            // next (this event's, or stage H's while H takes this event's). A creation's split
            // first cycle commits; its second finishes.
            if (do_commit_bg) begin
                bg_y <= cm_bg_y[BACKGROUND_W-1:0];
                bg_cb <= cm_bg_cb[BACKGROUND_W-1:0];
                bg_cr <= cm_bg_cr[BACKGROUND_W-1:0];
            end
            if (slot_write) begin
                px[sw_slot] <= sw_px;
                py[sw_slot] <= sw_py;
                rx[sw_slot] <= sw_rx;
                ry[sw_slot] <= sw_ry;
            end
            if (UPDATE_DELAY != 0) begin
                if (commit_moment) begin
                    c_live <= 1'b0;
                    if (!split)
                        c_bg_live <= 1'b0;
                end
                if (split) begin
                    creating <= 1'b1;
                    creating_slot <= e_free_slot;
                end else if (finish) begin
                    creating <= 1'b0;
                end
                if (c_load) begin
                    c_live <= to_c_live;
                    c_bg_live <= to_c_bg_live;
                    c_slot <= to_c_slot;
                    c_t <= to_c_t;
                    c_weight <= H_STAGE ? h_weight : e_weight;
                    c_dpx <= i_px;
                    c_dpy <= i_py;
                    c_drx <= i_rx;
                    c_dry <= i_ry;
                    c_dvmx <= i_vmx;
                    c_dvmy <= i_vmy;
                    c_dnorm <= i_norm;
                    c_dcy <= i_cy;
                    c_dccb <= i_ccb;
                    c_dccr <= i_ccr;
                    c_class <= to_c_class;
                    c_vote <= to_c_vote;
                    c_dbg_y <= H_STAGE ? h_dbg_y : bg_y_d[DB_W-1:0];
                    c_dbg_cb <= H_STAGE ? h_dbg_cb : bg_cb_d[DB_W-1:0];
                    c_dbg_cr <= H_STAGE ? h_dbg_cr : bg_cr_d[DB_W-1:0];
                end
                h_fresh <= h_load && do_update;
                if (H_STAGE && state == ST_PHASE) begin  // the filter step drains H through C
                    h_live <= 1'b0;
                    h_bg_live <= 1'b0;
                end
                if (h_load) begin
                    h_live <= do_update;
                    h_bg_live <= bg_learns;
                    h_slot <= e_slot;
                    h_t <= e_t;
                    h_weight <= e_weight;
                    h_dbg_y <= bg_y_d[DB_W-1:0];
                    h_dbg_cb <= bg_cb_d[DB_W-1:0];
                    h_dbg_cr <= bg_cr_d[DB_W-1:0];
                end
            end

            if (do_create) begin
                valid[create_slot] <= 1'b1;
                next_id <= next_id + 1'b1;
                px[create_slot] <= {{(CENTRE_W - EV_XY_W - FP){1'b0}}, e_x, {FP{1'b0}}};
                py[create_slot] <= {{(CENTRE_W - EV_XY_W - FP){1'b0}}, e_y, {FP{1'b0}}};
                rx[create_slot] <= K_R_INIT;
                ry[create_slot] <= K_R_INIT;
                vix[create_slot] <= {V_INT_W{1'b0}};
                viy[create_slot] <= {V_INT_W{1'b0}};
                vi_count[create_slot] <= {INTERVAL_UPDATES_W{1'b0}};
                reported[create_slot] <= 1'b0;
                ever_reported[create_slot] <= 1'b0;
            end

            if (m_write) begin  // k absorbs m_j
                px[k] <= m_px[CENTRE_W-1:0];
                py[k] <= m_py[CENTRE_W-1:0];
                rx[k] <= m_rx[HALF_SIZE_W-1:0];
                ry[k] <= m_ry[HALF_SIZE_W-1:0];
                if (m_from_j) begin  // the survivor's velocities and flags (its row: slot_row_write)
                    vix[k] <= vix[m_j];
                    viy[k] <= viy[m_j];
                    vi_count[k] <= vi_count[m_j];
                    reported[k] <= reported[m_j];
                    ever_reported[k] <= ever_reported[m_j];
                end
                valid[m_j] <= 1'b0;
            end

            if (size_write) begin
                window_x[size_slot] <= d_window_x;
                window_y[size_slot] <= d_window_y;
                grow[size_slot] <= d_grow[GROW_W-1:0];
            end
            if (sweep_slot && !moving && !f_expire)
                vrel[k] <= d_vrel[VREL_W-1:0];
            else if (do_create)
                vrel[create_slot] <= {VREL_W{1'b0}};
            else if (m_write && m_from_j)
                vrel[k] <= vrel[m_j];

            if (sweep_slot && !moving) begin  // stage 0
                if (f_expire) begin
                    valid[k] <= 1'b0;
                end else begin
                    vix[k] <= f_vix[V_INT_W-1:0];
                    viy[k] <= f_viy[V_INT_W-1:0];
                    vi_count[k] <= f_vi_count;
                    if (boundaries != 33'd0) begin
                    end
                end
            end
            for (i = 0; i < P; i = i + 1)  // a mixing entry out of its divider
                if (inv_en && inv_out_live && {{(32 - CLASS_W){1'b0}}, inv_out_j} == i)
                    inv_ww[i * INV_WW_W +: INV_WW_W] <= refreshed;
            if (tail_en) begin  // the tail's first register
                p_live <= sweep_slot && !f_expire;
                p_slot <= k;
                p_vmx <= vmx_a;
                p_vmy <= vmy_a;
                p_w20 <= norm_cut[W20_W-1:0];
            end
            if (tail_en) begin  // the tail's stage T1: what T2 decides on
                t2_live <= t_live;
                t2_slot <= t;
                t2_record <= record;
                t2_speed_sq <= f_speed_sq[SPEED_SQ_W-1:0];
                t2_speed_sq_x <= f_speed_sq_x[SPEED_SQ_W-1:0];
                t2_speed_sq_y <= f_speed_sq_y[SPEED_SQ_W-1:0];
                t2_fast <= f_fast;
                t2_out_x <= f_out_x;
                t2_out_y <= f_out_y;
                t2_active_moving <= f_active_moving;
                t2_noise_signal <= f_noise_signal[NOISE_COUNT_W-1:0];
                t2_noise_scale <= f_noise_scale[NOISE_SCALE_W-1:0];
                t2_box <= f_box[BOX_W-1:0];
            end
            if (tail_en && t2_live) begin  // the tail's last stage, T2
                if (f_exit) begin
                    valid[t2_slot] <= 1'b0;
                end else begin
                    reported[t2_slot] <= f_report;
                    if (f_report) begin
                        ever_reported[t2_slot] <= 1'b1;
                        rec_valid <= 1'b1;
                        rec_data <= t2_record;
                    end
                end
            end
        end
    end

`ifdef FORMAL
`include "evclust_core_props.vh"  // formal/evclust_core/: the stream properties, for SymbiYosys only
`endif
endmodule
`default_nettype wire
