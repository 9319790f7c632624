// evclust_objects: the object layer behind evclust_core's record port, bit for bit the fixed
// model's (model/evclust/fixed/objects.py; docs/OBJECTS.md walks through it).
//
// Streams: the core's cluster records in (valid/ready), passed on unchanged to `out_rec_*`;
// the end of each filter step in (valid/ready with its time, from the core's step port); object
// records out (valid/ready, the word of vectors/*/objects.hex). Reset is synchronous and active
// high; `clear` restarts the unit as it does the core.
//
// Schedule: the unit collects a step's records (at most one per cycle, as they pass), then, at
// the step's end, runs the six steps of the model one operation at a time with one multiplier
// (COLLECT, DT, GAIN, PREDICT, PREP, LINK, GROUP, OWNER, CLAIM, ASSOC, JOIN, UPDATE, MERGE, OUT):
// about 10 + 2K + 3M + M(M-1)/2 + 4M + (3K per new group) + 12 per updated object + K per
// merge scan + K cycles for M clusters and K object slots, plus output stalls. Meanwhile it
// takes no record, which holds the core's next sweep (not its events).
//
// Every width and constant comes from evclust_params.vh, generated from the formats table.
`default_nettype none
`include "evclust_require.vh"
module evclust_objects #(
`define EVCLUST_PORT_PARAMETERS
`include "evclust_params.vh"
`undef EVCLUST_PORT_PARAMETERS
,
    parameter integer RUNTIME_CONFIG = 1  // 1: the constants from `cfg`; 0: the header's (CFG_RESET)
) (
    input  wire             clk,
    input  wire             rst,
    input  wire             clear,
    input  wire [CFG_W-1:0] cfg,
    input  wire             rec_valid,      // the core's cluster records
    output wire             rec_ready,
    input  wire [REC_W-1:0] rec_data,
    output wire             out_rec_valid,  // ... passed on (tie out_rec_ready high if unused)
    input  wire             out_rec_ready,
    output wire [REC_W-1:0] out_rec_data,
    input  wire             step_valid,     // the end of a filter step, after its last record
    output wire             step_ready,
    input  wire [31:0]      step_t,
    output reg              obj_valid,      // object records
    input  wire             obj_ready,
    output reg  [OBJ_W-1:0] obj_data,
    output wire             idle            // between steps, no record waiting
);
`include "evclust_params.vh"
`include "evclust_arith.vh"

    generate
        if (N != N_CLUSTERS || REC_W != REC_WORD_W || OBJ_W != OBJ_WORD_W || CFG_W != 32 * CFG_WORDS) begin : parameters_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_objects: N, REC_W, OBJ_W or CFG_W differs from evclust_params.vh")
        end
    endgenerate

    localparam integer K = N_OBJECTS;
    localparam integer SLOT_W = N > 1 ? $clog2(N) : 1;         // a cluster slot, an index into the step's clusters
    localparam integer OSLOT_W = K > 1 ? $clog2(K) : 1;        // an object slot
    localparam integer OIDX_W = OSLOT_W + 1;                     // an object slot or -1 (none)
    localparam integer M_W = $clog2(N + 1);                      // clusters in a step, members of an object
    localparam integer FP = OBJ_CENTRE_FRAC, FR = OBJ_HALF_FRAC, FV = OBJ_VELOCITY_FRAC;
    localparam integer FVI = V_INT_FRAC, FVM = V_MCM_FRAC, FG = OBJ_GAIN_FRAC, FT = OBJ_DT_FRAMES_FRAC;
    localparam integer FI = OBJECT_INV_TRACK_FRAC, FS = OBJECT_LINK_ALONG_FRAC;
    localparam integer UP = FP - FR;                             // half-size to the centre's format
    localparam integer MOVE = FT + FV - FP;                      // V·Δt to the centre's format
    localparam integer PW = OBJ_CENTRE_W;                        // centre, box edges (signed)
    localparam integer RW = CENTRE_W + 1;                        // a cluster's half-size in the centre's format
    localparam integer REACH_W = OBJECT_LINK_ALONG_W + RW - FS;  // link_along·R
    localparam integer VW = OBJ_VELOCITY_W, TW = OBJ_TOLERANCE_W, WW = OBJ_WEIGHT_W, AW = ACTIVITY_W, CW = COLOUR_W;
    localparam signed [63:0] ONE_G = 64'sd1 <<< FG;
    localparam signed [63:0] V_MIN = -(64'sd1 <<< (VW - 1)), V_MAX = (64'sd1 <<< (VW - 1)) - 1;
    localparam signed [63:0] P_MIN = -(64'sd1 <<< (PW - 1)), P_MAX = (64'sd1 <<< (PW - 1)) - 1;
    localparam signed [63:0] DT_MAX = (64'sd1 <<< OBJ_DT_W) - 1;
    localparam signed [63:0] DTF_MAX = (64'sd1 <<< OBJ_DT_FRAMES_W) - 1;
    localparam signed [63:0] LAST_X = ($signed({32'd0, SENSOR_WIDTH[31:0]}) - 64'sd1) <<< FP;
    localparam signed [63:0] LAST_Y = ($signed({32'd0, SENSOR_HEIGHT[31:0]}) - 64'sd1) <<< FP;

    // ---------------------------------------------------------------- configuration
    /* verilator lint_off UNUSEDSIGNAL */  // a field's word holds only its width's bits
    wire [CFG_W-1:0] cfg_used = RUNTIME_CONFIG != 0 ? cfg : CFG_RESET;
    /* verilator lint_on UNUSEDSIGNAL */
    // Its fields, cfg_<register name>, each of its own width (generated from the register map).
`define EVCLUST_CONFIG_FIELDS
`include "evclust_params.vh"
`undef EVCLUST_CONFIG_FIELDS
    function automatic signed [63:0] field;  // an unsigned configuration field as a 64-bit value
        input [63:0] bits;
        begin
            field = $signed(bits);
        end
    endfunction
    wire signed [63:0] K_INV_T_FRAME = field({{(64 - CFG_INV_T_FRAME_W){1'b0}}, cfg_inv_t_frame});
    wire signed [63:0] K_GATE = field({{(64 - CFG_OBJECT_GATE_W){1'b0}}, cfg_object_gate});
    wire signed [63:0] K_LINK = field({{(64 - CFG_OBJECT_LINK_ALONG_W){1'b0}}, cfg_object_link_along});
    wire signed [63:0] K_V_TOL = field({{(64 - CFG_OBJECT_V_TOL_W){1'b0}}, cfg_object_v_tol});
    wire signed [63:0] K_V_REL = field({{(64 - CFG_OBJECT_V_REL_W){1'b0}}, cfg_object_v_rel});
    wire signed [63:0] K_INV_TRACK = field({{(64 - CFG_OBJECT_INV_TRACK_W){1'b0}}, cfg_object_inv_track});
    wire signed [63:0] K_INV_RATE = field({{(64 - CFG_OBJECT_INV_RATE_W){1'b0}}, cfg_object_inv_rate});
    wire signed [63:0] K_INV_VELOCITY = field({{(64 - CFG_OBJECT_INV_VELOCITY_W){1'b0}}, cfg_object_inv_velocity});
    wire signed [63:0] K_INV_SIZE = field({{(64 - CFG_OBJECT_INV_SIZE_W){1'b0}}, cfg_object_inv_size});
    wire signed [63:0] K_INV_COLOUR = field({{(64 - CFG_OBJECT_INV_COLOUR_W){1'b0}}, cfg_object_inv_colour});
    wire [31:0] K_BIRTH = {{(32 - CFG_OBJECT_BIRTH_US_W){1'b0}}, cfg_object_birth_us};
    wire [31:0] K_COAST = {{(32 - CFG_OBJECT_COAST_US_W){1'b0}}, cfg_object_coast_us};
    wire [31:0] K_KEEP = {{(32 - CFG_OBJECT_KEEP_US_W){1'b0}}, cfg_object_keep_us};

    // ---------------------------------------------------------------- the one multiplier
    reg  signed [63:0] mul_a, mul_b;  // chosen by the state below; every operand fits 36 bits
    wire signed [71:0] mul_full = $signed(mul_a[35:0]) * $signed(mul_b[35:0]);
    wire signed [63:0] product = mul_full[63:0];

    // ---------------------------------------------------------------- state
    // The machine's states (S_*) and the association's scans (SCAN_*), generated from
    // model/evclust/fixed/enums.py.
`include "evclust_objects_enums.vh"
    reg [3:0]  state;
    reg [4:0]  sub;            // the operation within an item (a multiply per cycle)
    reg [8:0]  i, j;           // cluster indices, or an object slot and a scan position
    reg [M_W-1:0] m;           // the step's clusters
    reg [31:0] t, t_prev, step_count, next_id;
    reg        started;
    reg signed [63:0] dt, dtf;                                  // Δt since the last step (µs, frames): the prediction's
    reg signed [63:0] seen, g_pos, g_rate, g_vel, g_size, g_col;  // UPDATE: Δ since the object was last seen (frames), the gains

    // The step's clusters (index = arrival order = slot order).
    reg [SLOT_W-1:0]      c_slot   [0:N-1];
    reg [31:0]            c_id     [0:N-1];
    reg [PW-1:0]          c_x      [0:N-1];
    reg [PW-1:0]          c_y      [0:N-1];
    reg [RW-1:0]          c_rx     [0:N-1];  // in the centre's format
    reg [RW-1:0]          c_ry     [0:N-1];
    reg [AW-1:0]          c_act    [0:N-1];
    reg [VW-1:0]          c_vx     [0:N-1];
    reg [VW-1:0]          c_vy     [0:N-1];
    reg                   c_meas   [0:N-1];
    reg [TW-1:0]          c_tol    [0:N-1];
    reg [REACH_W-1:0]     c_reach_x[0:N-1];
    reg [REACH_W-1:0]     c_reach_y[0:N-1];
    reg [7:0]             c_class  [0:N-1];
    reg [CW-1:0]          c_lum    [0:N-1];
    reg [CW-1:0]          c_cb     [0:N-1];
    reg [CW-1:0]          c_cr     [0:N-1];
    reg [SLOT_W-1:0]      c_group  [0:N-1];
    // Per group (indexed by its lowest member).
    reg [PW-1:0]          g_lo_x   [0:N-1];
    reg [PW-1:0]          g_hi_x   [0:N-1];
    reg [PW-1:0]          g_lo_y   [0:N-1];
    reg [PW-1:0]          g_hi_y   [0:N-1];
    reg [WW-1:0]          g_weight [0:N-1];
    reg [VW-1:0]          g_vx     [0:N-1];
    reg [VW-1:0]          g_vy     [0:N-1];
    reg [AW-1:0]          g_vw     [0:N-1];
    reg                   g_vset   [0:N-1];  // a member's velocity taken (the first member's always is)
    reg                   g_meas   [0:N-1];
    reg [TW-1:0]          g_tol    [0:N-1];
    reg [OIDX_W-1:0]      g_pref   [0:N-1];
    reg [AW-1:0]          g_prefw  [0:N-1];
    reg [OIDX_W-1:0]      g_obj    [0:N-1];
    // Per cluster slot: the object its cluster joined last, and that cluster's id.
    reg                   s_known  [0:N-1];
    reg [OIDX_W-1:0]      s_obj    [0:N-1];
    reg [31:0]            s_id     [0:N-1];
    // The objects.
    reg                   o_valid  [0:K-1];
    reg [31:0]            o_id     [0:K-1];
    reg [PW-1:0]          o_x      [0:K-1];
    reg [PW-1:0]          o_y      [0:K-1];
    reg [OBJ_HALF_W-1:0]  o_rx     [0:K-1];
    reg [OBJ_HALF_W-1:0]  o_ry     [0:K-1];
    reg [VW-1:0]          o_vx     [0:K-1];
    reg [VW-1:0]          o_vy     [0:K-1];
    reg [TW-1:0]          o_tol    [0:K-1];
    reg [CW-1:0]          o_lum    [0:K-1];
    reg [CW-1:0]          o_cb     [0:K-1];
    reg [CW-1:0]          o_cr     [0:K-1];
    reg [7:0]             o_class  [0:K-1];
    reg [31:0]            o_t_born [0:K-1];
    reg [31:0]            o_t_seen [0:K-1];
    reg                   o_conf   [0:K-1];
    reg                   o_ever   [0:K-1];
    // ... and the step's sums of its members.
    reg [M_W-1:0]         o_members[0:K-1];
    reg                   o_claimed[0:K-1];
    reg [WW-1:0]          o_owner_w[0:K-1];
    reg [PW-1:0]          o_lo_x   [0:K-1];
    reg [PW-1:0]          o_hi_x   [0:K-1];
    reg [PW-1:0]          o_lo_y   [0:K-1];
    reg [PW-1:0]          o_hi_y   [0:K-1];
    reg [AW-1:0]          o_vw     [0:K-1];
    reg                   o_vset   [0:K-1];
    reg [VW-1:0]          o_mvx    [0:K-1];
    reg [VW-1:0]          o_mvy    [0:K-1];
    reg [AW-1:0]          o_cw     [0:K-1];
    reg [7:0]             o_mclass [0:K-1];
    reg [CW-1:0]          o_mlum   [0:K-1];
    reg [CW-1:0]          o_mcb    [0:K-1];
    reg [CW-1:0]          o_mcr    [0:K-1];

    // 64-bit views of the stored fields (sign- or zero-extended).
    function automatic signed [63:0] sx64;  // a signed PW-bit field
        input [PW-1:0] v;
        begin
            sx64 = {{(64 - PW){v[PW-1]}}, v};
        end
    endfunction
    function automatic signed [63:0] sv64;  // a signed VW-bit field
        input [VW-1:0] v;
        begin
            sv64 = {{(64 - VW){v[VW-1]}}, v};
        end
    endfunction
    function automatic signed [63:0] s8;  // a signed 8-bit class
        input [7:0] v;
        begin
            s8 = {{56{v[7]}}, v};
        end
    endfunction
    function automatic signed [63:0] tol_of;  // v_tol + floor(v_rel·|V|₁) from the product v_rel·|V|₁
        input signed [63:0] prod;
        input signed [63:0] v_tol;
        begin
            tol_of = v_tol + (prod >>> FS);
        end
    endfunction
    function automatic agree;  // |a - b|₁ <= max(tol_a, tol_b)
        input signed [63:0] ax, ay, a_tol, bx, by, b_tol;
        begin
            agree = abs64(ax - bx) + abs64(ay - by) <= (a_tol > b_tol ? a_tol : b_tol);
        end
    endfunction
    function automatic signed [63:0] gain_of;  // min(dtf·(1/T) >> FI, 1)
        input signed [63:0] prod;
        begin
            gain_of = (prod >>> FI) < ONE_G ? (prod >>> FI) : ONE_G;
        end
    endfunction

    // ---------------------------------------------------------------- the record passing by
    wire collecting = state == S_COLLECT;
    assign rec_ready = collecting && out_rec_ready;
    assign out_rec_valid = collecting && rec_valid;
    assign out_rec_data = rec_data;
    assign step_ready = collecting;
    assign idle = collecting && m == {M_W{1'b0}} && !obj_valid;
    wire take_rec = rec_valid && rec_ready;
    wire take_step = step_valid && step_ready;

    // The arriving record's fields; its velocity in the object's format (V_int once measured, else V_MCM).
    wire [SLOT_W-1:0] in_slot = rec_data[REC_SLOT_LSB +: SLOT_W];
    wire signed [63:0] in_vix = {{(64 - REC_VX_INT_W){rec_data[REC_VX_INT_LSB + REC_VX_INT_W - 1]}}, rec_data[REC_VX_INT_LSB +: REC_VX_INT_W]};
    wire signed [63:0] in_viy = {{(64 - REC_VY_INT_W){rec_data[REC_VY_INT_LSB + REC_VY_INT_W - 1]}}, rec_data[REC_VY_INT_LSB +: REC_VY_INT_W]};
    wire signed [63:0] in_vmx = {{(64 - REC_VX_MCM_W){rec_data[REC_VX_MCM_LSB + REC_VX_MCM_W - 1]}}, rec_data[REC_VX_MCM_LSB +: REC_VX_MCM_W]};
    wire signed [63:0] in_vmy = {{(64 - REC_VY_MCM_W){rec_data[REC_VY_MCM_LSB + REC_VY_MCM_W - 1]}}, rec_data[REC_VY_MCM_LSB +: REC_VY_MCM_W]};
    wire               in_meas = in_vix != 64'sd0 || in_viy != 64'sd0;
    wire signed [63:0] in_vx = saturate(in_meas ? align(in_vix, FVI, FV) : align(in_vmx, FVM, FV), V_MIN, V_MAX);
    wire signed [63:0] in_vy = saturate(in_meas ? align(in_viy, FVI, FV) : align(in_vmy, FVM, FV), V_MIN, V_MAX);
    wire signed [63:0] in_rx = $signed({{(64 - REC_RX_W){1'b0}}, rec_data[REC_RX_LSB +: REC_RX_W]}) <<< UP;
    wire signed [63:0] in_ry = $signed({{(64 - REC_RY_W){1'b0}}, rec_data[REC_RY_LSB +: REC_RY_W]}) <<< UP;

    // ---------------------------------------------------------------- the items the states work on
    wire [SLOT_W-1:0]  ci = i[SLOT_W-1:0];                   // a cluster (PREP, LINK, GROUP, JOIN)
    wire [SLOT_W-1:0]  cj = j[SLOT_W-1:0];                   // its partner (LINK)
    wire [OSLOT_W-1:0] oi = i[OSLOT_W-1:0];                  // an object (PREDICT, UPDATE, MERGE, OUT)
    wire [OSLOT_W-1:0] oj = j[OSLOT_W-1:0];                  // a scanned object (ASSOC, MERGE)
    wire signed [63:0] o_xs = sx64(o_x[oi]), o_ys = sx64(o_y[oi]);
    wire signed [63:0] o_vxs = sv64(o_vx[oi]), o_vys = sv64(o_vy[oi]);
    wire signed [63:0] o_tols = {{(64 - TW){1'b0}}, o_tol[oi]};  // the velocity's tolerance (UPDATE: before this step's)

    // LINK: clusters ci and cj.
    wire signed [63:0] l_vxi = sv64(c_vx[ci]), l_vyi = sv64(c_vy[ci]), l_vxj = sv64(c_vx[cj]), l_vyj = sv64(c_vy[cj]);
    wire signed [63:0] l_toli = {{(64 - TW){1'b0}}, c_tol[ci]}, l_tolj = {{(64 - TW){1'b0}}, c_tol[cj]};
    wire signed [63:0] l_rchxi = {{(64 - REACH_W){1'b0}}, c_reach_x[ci]}, l_rchxj = {{(64 - REACH_W){1'b0}}, c_reach_x[cj]};
    wire signed [63:0] l_rchyi = {{(64 - REACH_W){1'b0}}, c_reach_y[ci]}, l_rchyj = {{(64 - REACH_W){1'b0}}, c_reach_y[cj]};
    wire signed [63:0] l_dx = abs64(sx64(c_x[ci]) - sx64(c_x[cj])), l_dy = abs64(sx64(c_y[ci]) - sx64(c_y[cj]));
    wire signed [63:0] l_sx0 = {{(64 - RW){1'b0}}, c_rx[ci]} + {{(64 - RW){1'b0}}, c_rx[cj]} + K_GATE;
    wire signed [63:0] l_sy0 = {{(64 - RW){1'b0}}, c_ry[ci]} + {{(64 - RW){1'b0}}, c_ry[cj]} + K_GATE;
    wire               l_both = c_meas[ci] && c_meas[cj];
    wire               l_agree = agree(l_vxi, l_vyi, l_toli, l_vxj, l_vyj, l_tolj);
    wire signed [63:0] l_sum_x = abs64(l_vxi + l_vxj), l_sum_y = abs64(l_vyi + l_vyj);
    wire               l_moving = l_sum_x + l_sum_y > 64'sd2 * (l_toli > l_tolj ? l_toli : l_tolj);  // the motion is known
    wire               l_along_x = l_sum_x >= l_sum_y;
    wire signed [63:0] l_sx = l_sx0 + (l_both && l_moving && l_along_x ? (l_rchyi > l_rchyj ? l_rchyi : l_rchyj) : 64'sd0);
    wire signed [63:0] l_sy = l_sy0 + (l_both && l_moving && !l_along_x ? (l_rchxi > l_rchxj ? l_rchxi : l_rchxj) : 64'sd0);
    wire               linked = (!l_both || l_agree) && l_dx <= l_sx && l_dy <= l_sy;
    wire [SLOT_W-1:0]  keep_label = c_group[ci] < c_group[cj] ? c_group[ci] : c_group[cj];
    wire [SLOT_W-1:0]  drop_label = c_group[ci] < c_group[cj] ? c_group[cj] : c_group[ci];

    // GROUP: cluster ci into its group.
    wire [SLOT_W-1:0]  gg = c_group[ci];
    wire signed [63:0] c_lo_x = sx64(c_x[ci]) - {{(64 - RW){1'b0}}, c_rx[ci]}, c_hi_x = sx64(c_x[ci]) + {{(64 - RW){1'b0}}, c_rx[ci]};
    wire signed [63:0] c_lo_y = sx64(c_y[ci]) - {{(64 - RW){1'b0}}, c_ry[ci]}, c_hi_y = sx64(c_y[ci]) + {{(64 - RW){1'b0}}, c_ry[ci]};
    wire [OIDX_W-1:0]  c_prev = s_known[c_slot[ci]] && s_id[c_slot[ci]] == c_id[ci] ? s_obj[c_slot[ci]] : {OIDX_W{1'b1}};
    wire               c_prev_live = !c_prev[OIDX_W-1] && o_valid[c_prev[OSLOT_W-1:0]];

    // OWNER, CLAIM, ASSOC: group gi (a group is named by its lowest member, ci).
    wire               g_root = c_group[ci] == ci;
    wire [OIDX_W-1:0]  gp = g_pref[ci];
    wire [OSLOT_W-1:0] gpo = gp[OSLOT_W-1:0];
    wire signed [63:0] g_lo_xs = sx64(g_lo_x[ci]), g_hi_xs = sx64(g_hi_x[ci]), g_lo_ys = sx64(g_lo_y[ci]), g_hi_ys = sx64(g_hi_y[ci]);
    wire signed [63:0] g_cx = (g_lo_xs + g_hi_xs) >>> 1, g_cy = (g_lo_ys + g_hi_ys) >>> 1;
    function automatic meets;  // the object's box grown by the gate meets the box
        input signed [63:0] x, y, rx, ry, lo_x, hi_x, lo_y, hi_y, gate;
        begin
            meets = lo_x <= x + rx + gate && hi_x >= x - rx - gate && lo_y <= y + ry + gate && hi_y >= y - ry - gate;
        end
    endfunction
    wire signed [63:0] p_rxs = {{(64 - OBJ_HALF_W){1'b0}}, o_rx[gpo]} <<< UP, p_rys = {{(64 - OBJ_HALF_W){1'b0}}, o_ry[gpo]} <<< UP;
    wire               pref_meets = meets(sx64(o_x[gpo]), sx64(o_y[gpo]), p_rxs, p_rys, g_lo_xs, g_hi_xs, g_lo_ys, g_hi_ys, K_GATE);
    wire [WW-1:0]      g_w = g_weight[ci];
    // The scanned object oj against group ci.
    wire signed [63:0] s_xs = sx64(o_x[oj]), s_ys = sx64(o_y[oj]);
    wire signed [63:0] s_rxs = {{(64 - OBJ_HALF_W){1'b0}}, o_rx[oj]} <<< UP, s_rys = {{(64 - OBJ_HALF_W){1'b0}}, o_ry[oj]} <<< UP;
    wire signed [63:0] s_d = abs64(g_cx - s_xs) + abs64(g_cy - s_ys);
    wire               s_agree = !g_meas[ci] || agree(sv64(g_vx[ci]), sv64(g_vy[ci]), {{(64 - TW){1'b0}}, g_tol[ci]},
                                                      sv64(o_vx[oj]), sv64(o_vy[oj]), {{(64 - TW){1'b0}}, o_tol[oj]});
    wire               s_inside = o_valid[oj] && abs64(g_cx - s_xs) <= s_rxs && abs64(g_cy - s_ys) <= s_rys && s_agree;
    wire               s_gate = o_valid[oj] && !o_claimed[oj] && o_owner_w[oj] == {WW{1'b0}}
                                && meets(s_xs, s_ys, s_rxs, s_rys, g_lo_xs, g_hi_xs, g_lo_ys, g_hi_ys, K_GATE) && s_agree;
    wire [31:0]        s_unseen = t - o_t_seen[oj];
    // ASSOC's scans: INSIDE (an object the group lies inside), GATE (the nearest unclaimed object
    // it meets), FREE (the first free slot, else the lost object unseen the longest), then TAKE.
    reg  [1:0]         scan;
    reg  [OIDX_W-1:0]  best;       // the object found so far (-1: none)
    reg  signed [63:0] best_d;     // its distance (INSIDE, GATE)
    reg  [31:0]        lost_for;   // FREE: how long the lost object found has been unseen
    reg                creating;   // TAKE: `best` is a slot to create the object in
    wire               s_match = scan == SCAN_INSIDE ? s_inside : s_gate;
    wire               s_better = s_match && (best[OIDX_W-1] || s_d < best_d);
    wire               s_lost = o_valid[oj] && o_conf[oj] && s_unseen > K_COAST && (best[OIDX_W-1] || s_unseen > lost_for);

    // JOIN: cluster ci into object jo.
    wire [OIDX_W-1:0]  jo_idx = g_obj[c_group[ci]];
    wire [OSLOT_W-1:0] jo = jo_idx[OSLOT_W-1:0];

    // UPDATE: object oi.
    wire signed [63:0] u_zx = (sx64(o_lo_x[oi]) + sx64(o_hi_x[oi])) >>> 1, u_zy = (sx64(o_lo_y[oi]) + sx64(o_hi_y[oi])) >>> 1;
    wire signed [63:0] u_hx = (sx64(o_hi_x[oi]) - sx64(o_lo_x[oi])) >>> (1 + UP), u_hy = (sx64(o_hi_y[oi]) - sx64(o_lo_y[oi])) >>> (1 + UP);
    wire signed [63:0] u_rx = {{(64 - OBJ_HALF_W){1'b0}}, o_rx[oi]}, u_ry = {{(64 - OBJ_HALF_W){1'b0}}, o_ry[oi]};
    wire               u_born = o_t_born[oi] == t;
    wire               u_colour = o_cw[oi] != {AW{1'b0}};
    wire signed [63:0] u_gcol = o_class[oi][7] ? ONE_G : g_col;  // the first colour as it is
    wire [31:0]        u_unseen = t - o_t_seen[oi];
    wire signed [63:0] u_seen_us = $signed({32'd0, u_unseen}) > DT_MAX ? DT_MAX : $signed({32'd0, u_unseen});
    // 2^-ceil(log2 Δ) in the gains' format, from the bit length of Δ's raw value minus one.
    function automatic signed [63:0] rate_bound;
        input signed [63:0] v;  // Δ, raw, >= 1
        integer b, n;
        reg [63:0] x;
        begin
            x = v - 64'sd1;
            n = 0;
            for (b = 0; b < 64; b = b + 1)
                if (x[b])
                    n = b + 1;
            rate_bound = 64'sd1 <<< (FG + FT - n);
        end
    endfunction
    reg  signed [63:0] ex, ey, rate_x, rate_y;
    // MERGE: object oi inside object oj.
    wire               m_inside = oj != oi && o_valid[oj] && o_id[oj] < o_id[oi]
                                  && abs64(o_xs - s_xs) <= s_rxs && abs64(o_ys - s_ys) <= s_rys
                                  && agree(o_vxs, o_vys, {{(64 - TW){1'b0}}, o_tol[oi]}, sv64(o_vx[oj]), sv64(o_vy[oj]), {{(64 - TW){1'b0}}, o_tol[oj]});
    // OUT: object oi.
    wire [31:0]        q_unseen = t - o_t_seen[oi];
    wire               q_outside = o_xs < 64'sd0 || o_ys < 64'sd0 || o_xs > LAST_X || o_ys > LAST_Y;
    wire [OBJ_W-1:0]   q_record;
    assign q_record[OBJ_T_US_LSB +: OBJ_T_US_W] = t;
    assign q_record[OBJ_STEP_LSB +: OBJ_STEP_W] = step_count;
    assign q_record[OBJ_SLOT_LSB +: OBJ_SLOT_W] = oi;
    assign q_record[OBJ_ID_LSB +: OBJ_ID_W] = o_id[oi];
    assign q_record[OBJ_X_LSB +: OBJ_X_W] = o_x[oi];
    assign q_record[OBJ_Y_LSB +: OBJ_Y_W] = o_y[oi];
    assign q_record[OBJ_RX_LSB +: OBJ_RX_W] = o_rx[oi];
    assign q_record[OBJ_RY_LSB +: OBJ_RY_W] = o_ry[oi];
    assign q_record[OBJ_VX_LSB +: OBJ_VX_W] = o_vx[oi];
    assign q_record[OBJ_VY_LSB +: OBJ_VY_W] = o_vy[oi];
    assign q_record[OBJ_LUM_LSB +: OBJ_LUM_W] = o_lum[oi];
    assign q_record[OBJ_CB_LSB +: OBJ_CB_W] = o_cb[oi];
    assign q_record[OBJ_CR_LSB +: OBJ_CR_W] = o_cr[oi];
    assign q_record[OBJ_CLASS_LSB +: OBJ_CLASS_W] = o_class[oi];
    assign q_record[OBJ_MEMBERS_LSB +: OBJ_MEMBERS_W] = o_members[oi];
    assign q_record[OBJ_FLAGS_LSB +: OBJ_FLAGS_W] = {o_members[oi] == {M_W{1'b0}}, !o_ever[oi]};

    wire signed [63:0] g_rx_new = (g_hi_xs - g_lo_xs) >>> (1 + UP), g_ry_new = (g_hi_ys - g_lo_ys) >>> (1 + UP);
    wire               q_confirmed = o_conf[oi] || (o_members[oi] != {M_W{1'b0}} && t - o_t_born[oi] >= K_BIRTH);
    wire               q_dies = o_members[oi] == {M_W{1'b0}} && (q_unseen > (o_conf[oi] ? K_KEEP : K_BIRTH) || q_outside);
    wire               q_report = o_valid[oi] && !q_dies && q_confirmed && q_unseen <= K_COAST;

    // ---------------------------------------------------------------- the multiplier's operands
    always @* begin
        mul_a = 64'sd0;
        mul_b = 64'sd0;
        case (state)
            S_DT: begin mul_a = dt; mul_b = K_INV_T_FRAME; end
            S_PREDICT: begin mul_a = sub == 5'd0 ? o_vxs : o_vys; mul_b = dtf; end
            S_PREP: case (sub)
                5'd0: begin mul_a = K_V_REL; mul_b = abs64(sv64(c_vx[ci])) + abs64(sv64(c_vy[ci])); end
                5'd1: begin mul_a = K_LINK; mul_b = {{(64 - RW){1'b0}}, c_rx[ci]}; end
                default: begin mul_a = K_LINK; mul_b = {{(64 - RW){1'b0}}, c_ry[ci]}; end
            endcase
            S_UPDATE: case (sub)
                5'd0: begin mul_a = u_seen_us; mul_b = K_INV_T_FRAME; end
                5'd1: begin mul_a = seen; mul_b = K_INV_TRACK; end
                5'd2: begin mul_a = seen; mul_b = K_INV_RATE; end
                5'd3: begin mul_a = g_rate; mul_b = K_INV_RATE; end  // g_rate holds min(Δ/T_rate, 1) here
                5'd4: begin mul_a = seen; mul_b = K_INV_VELOCITY; end
                5'd5: begin mul_a = seen; mul_b = K_INV_SIZE; end
                5'd6: begin mul_a = seen; mul_b = K_INV_COLOUR; end
                5'd7: begin mul_a = g_pos; mul_b = u_zx - o_xs; end
                5'd8: begin mul_a = g_pos; mul_b = u_zy - o_ys; end
                5'd9: begin mul_a = g_rate; mul_b = ex; end
                5'd10: begin mul_a = g_vel; mul_b = sv64(o_mvx[oi]) - o_vxs; end
                5'd11: begin mul_a = g_rate; mul_b = ey; end
                5'd12: begin mul_a = g_vel; mul_b = sv64(o_mvy[oi]) - o_vys; end
                5'd13: begin mul_a = g_size; mul_b = u_hx - u_rx; end
                5'd14: begin mul_a = g_size; mul_b = u_hy - u_ry; end
                5'd15: begin mul_a = u_gcol; mul_b = {{(64 - CW){1'b0}}, o_mlum[oi]} - {{(64 - CW){1'b0}}, o_lum[oi]}; end
                5'd16: begin mul_a = u_gcol; mul_b = {{(64 - CW){1'b0}}, o_mcb[oi]} - {{(64 - CW){1'b0}}, o_cb[oi]}; end
                5'd17: begin mul_a = u_gcol; mul_b = {{(64 - CW){1'b0}}, o_mcr[oi]} - {{(64 - CW){1'b0}}, o_cr[oi]}; end
                default: begin mul_a = K_V_REL; mul_b = abs64(o_vxs) + abs64(o_vys); end
            endcase
            default: ;
        endcase
    end

    // The stores' values, each in its register's width (the datapath computes in 64 bits).
    wire signed [63:0] next_pred_x = saturate(o_xs + (product >>> MOVE), P_MIN, P_MAX);
    wire signed [63:0] next_pred_y = saturate(o_ys + (product >>> MOVE), P_MIN, P_MAX);
    wire signed [63:0] next_tol = tol_of(product, K_V_TOL);
    wire signed [63:0] next_reach = product >>> FS;
    wire signed [63:0] next_x = o_xs + (product >>> FG), next_y = o_ys + (product >>> FG);
    wire signed [63:0] next_vx = saturate(o_vxs + rate_x + (product >>> FG), V_MIN, V_MAX);
    wire signed [63:0] next_vy = saturate(o_vys + rate_y + (product >>> FG), V_MIN, V_MAX);
    wire signed [63:0] next_rx = u_rx + (product >>> FG), next_ry = u_ry + (product >>> FG);
    wire signed [63:0] next_lum = {{(64 - CW){1'b0}}, o_lum[oi]} + (product >>> FG);
    wire signed [63:0] next_cb = {{(64 - CW){1'b0}}, o_cb[oi]} + (product >>> FG);
    wire signed [63:0] next_cr = {{(64 - CW){1'b0}}, o_cr[oi]} + (product >>> FG);

    // ---------------------------------------------------------------- the sequence
    wire last_cluster = i + 9'd1 >= {{(9 - M_W){1'b0}}, m};
    wire last_object = {23'd0, i} + 32'd1 >= K;
    wire scan_last = {23'd0, j} + 32'd1 >= K;
    wire [SLOT_W-1:0] mi = m[SLOT_W-1:0];  // the next cluster's index (m < N while collecting)
    wire out_free = !obj_valid || obj_ready;
    wire [OSLOT_W-1:0] bo = best[OSLOT_W-1:0];
    integer q;
    always @(posedge clk) begin
        if (obj_valid && obj_ready)
            obj_valid <= 1'b0;
        if (rst || clear) begin
            state <= S_COLLECT;
            sub <= 5'd0;
            i <= 9'd0;
            j <= 9'd0;
            m <= {M_W{1'b0}};
            t <= 32'd0;
            t_prev <= 32'd0;
            step_count <= 32'd0;
            next_id <= 32'd0;
            started <= 1'b0;
            obj_valid <= 1'b0;
            obj_data <= {OBJ_W{1'b0}};
            for (q = 0; q < K; q = q + 1)
                o_valid[q] <= 1'b0;
            for (q = 0; q < N; q = q + 1)
                s_known[q] <= 1'b0;
        end else begin
            case (state)
                S_COLLECT: begin  // the step's records as they pass; at its end, Δt (saturated)
                    if (take_rec && {{(32 - M_W){1'b0}}, m} < N) begin
                        c_slot[mi] <= in_slot;
                        c_id[mi] <= rec_data[REC_ID_LSB +: 32];
                        c_x[mi] <= {{(PW - REC_X_W){1'b0}}, rec_data[REC_X_LSB +: REC_X_W]};
                        c_y[mi] <= {{(PW - REC_Y_W){1'b0}}, rec_data[REC_Y_LSB +: REC_Y_W]};
                        c_rx[mi] <= in_rx[RW-1:0];
                        c_ry[mi] <= in_ry[RW-1:0];
                        c_act[mi] <= rec_data[REC_ACTIVITY_LSB +: AW];
                        c_vx[mi] <= in_vx[VW-1:0];
                        c_vy[mi] <= in_vy[VW-1:0];
                        c_meas[mi] <= in_meas;
                        c_class[mi] <= rec_data[REC_CLASS_LSB +: 8];
                        c_lum[mi] <= rec_data[REC_LUM_LSB +: CW];
                        c_cb[mi] <= rec_data[REC_CB_LSB +: CW];
                        c_cr[mi] <= rec_data[REC_CR_LSB +: CW];
                        c_group[mi] <= mi;
                        m <= m + 1'b1;
                    end
                    if (take_step) begin
                        t <= step_t;
                        dt <= !started ? 64'sd0 : ($signed({32'd0, step_t - t_prev}) > DT_MAX ? DT_MAX : $signed({32'd0, step_t - t_prev}));
                        started <= 1'b1;
                        t_prev <= step_t;
                        state <= S_DT;
                    end
                end
                S_DT: begin  // Δt in frames, saturated
                    dtf <= (product >>> (INV_T_FRAME_FRAC - FT)) > DTF_MAX ? DTF_MAX : (product >>> (INV_T_FRAME_FRAC - FT));
                    sub <= 5'd0;
                    i <= 9'd0;
                    state <= S_PREDICT;
                end
                S_PREDICT: begin  // 1. each object moves by V·Δt; its step sums are cleared
                    if (o_valid[oi]) begin
                        if (sub == 5'd0)
                            o_x[oi] <= next_pred_x[PW-1:0];
                        else
                            o_y[oi] <= next_pred_y[PW-1:0];
                    end
                    o_members[oi] <= {M_W{1'b0}};
                    o_claimed[oi] <= 1'b0;
                    o_owner_w[oi] <= {WW{1'b0}};
                    o_vset[oi] <= 1'b0;
                    o_mvx[oi] <= {VW{1'b0}};  // (multiplied by a gain of 0 when no member sets it: never X)
                    o_mvy[oi] <= {VW{1'b0}};
                    o_cw[oi] <= {AW{1'b0}};
                    o_lo_x[oi] <= P_MAX[PW-1:0];
                    o_lo_y[oi] <= P_MAX[PW-1:0];
                    o_hi_x[oi] <= P_MIN[PW-1:0];
                    o_hi_y[oi] <= P_MIN[PW-1:0];
                    sub <= 5'd1;
                    if (!o_valid[oi] || sub == 5'd1) begin
                        sub <= 5'd0;
                        i <= i + 1'b1;
                        if (last_object) begin
                            i <= 9'd0;
                            state <= m == {M_W{1'b0}} ? S_UPDATE : S_PREP;
                        end
                    end
                end
                S_PREP: begin  // each cluster's velocity tolerance and link reaches
                    case (sub)
                        5'd0: c_tol[ci] <= next_tol[TW-1:0];
                        5'd1: c_reach_x[ci] <= next_reach[REACH_W-1:0];
                        default: c_reach_y[ci] <= next_reach[REACH_W-1:0];
                    endcase
                    sub <= sub + 1'b1;
                    if (sub == 5'd2) begin
                        sub <= 5'd0;
                        i <= i + 1'b1;
                        if (last_cluster) begin  // LINK from the pair (1, 0); one cluster has no pair
                            i <= m == 1 ? 9'd0 : 9'd1;
                            j <= 9'd0;
                            state <= m == 1 ? S_GROUP : S_LINK;
                        end
                    end
                end
                S_LINK: begin  // 2. the pairs (i, j < i) in the model's order; a link joins the two groups
                    if (c_group[cj] != c_group[ci] && linked)
                        for (q = 0; q < N; q = q + 1)
                            if (q <= i && c_group[q] == drop_label)
                                c_group[q] <= keep_label;
                    j <= j + 1'b1;
                    if (j + 9'd1 >= i) begin
                        j <= 9'd0;
                        i <= i + 1'b1;
                        if (last_cluster) begin
                            i <= 9'd0;
                            state <= S_GROUP;
                        end
                    end
                end
                S_GROUP: begin  // each group's box, activity, velocity and preferred object
                    if (i == 9'd0)
                        for (q = 0; q < N; q = q + 1) begin
                            g_obj[q] <= {OIDX_W{1'b1}};
                            if (q[SLOT_W-1:0] != gg) begin
                                g_weight[q] <= {WW{1'b0}};
                                g_vset[q] <= 1'b0;
                                g_prefw[q] <= {AW{1'b0}};
                                g_pref[q] <= {OIDX_W{1'b1}};
                                g_lo_x[q] <= P_MAX[PW-1:0];
                                g_lo_y[q] <= P_MAX[PW-1:0];
                                g_hi_x[q] <= P_MIN[PW-1:0];
                                g_hi_y[q] <= P_MIN[PW-1:0];
                            end
                        end
                    g_lo_x[gg] <= i == 9'd0 || c_lo_x < sx64(g_lo_x[gg]) ? c_lo_x[PW-1:0] : g_lo_x[gg];
                    g_hi_x[gg] <= i == 9'd0 || c_hi_x > sx64(g_hi_x[gg]) ? c_hi_x[PW-1:0] : g_hi_x[gg];
                    g_lo_y[gg] <= i == 9'd0 || c_lo_y < sx64(g_lo_y[gg]) ? c_lo_y[PW-1:0] : g_lo_y[gg];
                    g_hi_y[gg] <= i == 9'd0 || c_hi_y > sx64(g_hi_y[gg]) ? c_hi_y[PW-1:0] : g_hi_y[gg];
                    g_weight[gg] <= (i == 9'd0 ? {WW{1'b0}} : g_weight[gg]) + {{(WW - AW){1'b0}}, c_act[ci]};
                    if (i == 9'd0 || !g_vset[gg] || c_act[ci] > g_vw[gg]) begin
                        g_vset[gg] <= 1'b1;
                        g_vw[gg] <= c_act[ci];
                        g_vx[gg] <= c_vx[ci];
                        g_vy[gg] <= c_vy[ci];
                        g_meas[gg] <= c_meas[ci];
                        g_tol[gg] <= c_tol[ci];
                    end
                    if (c_prev_live && (i == 9'd0 || c_act[ci] > g_prefw[gg])) begin
                        g_pref[gg] <= c_prev;
                        g_prefw[gg] <= c_act[ci];
                    end else if (i == 9'd0) begin
                        g_pref[gg] <= {OIDX_W{1'b1}};
                        g_prefw[gg] <= {AW{1'b0}};
                    end
                    i <= i + 1'b1;
                    if (last_cluster) begin
                        i <= 9'd0;
                        state <= S_OWNER;
                    end
                end
                S_OWNER: begin  // 3. each object's most active group that continues it, its box still met
                    if (g_root && !gp[OIDX_W-1] && g_w > o_owner_w[gpo] && pref_meets)
                        o_owner_w[gpo] <= g_w;
                    i <= i + 1'b1;
                    if (last_cluster) begin
                        i <= 9'd0;
                        state <= S_CLAIM;
                    end
                end
                S_CLAIM: begin
                    if (g_root && !gp[OIDX_W-1] && !o_claimed[gpo] && o_owner_w[gpo] == g_w) begin
                        g_obj[ci] <= gp;
                        o_claimed[gpo] <= 1'b1;
                    end
                    i <= i + 1'b1;
                    if (last_cluster) begin
                        i <= 9'd0;
                        j <= 9'd0;
                        scan <= SCAN_INSIDE;
                        best <= {OIDX_W{1'b1}};
                        state <= S_ASSOC;
                    end
                end
                S_ASSOC: begin  // every other group: an object it lies inside, the nearest unclaimed one it meets, or a new one
                    if (!g_root || !g_obj[ci][OIDX_W-1]) begin
                        i <= i + 1'b1;
                        if (last_cluster) begin
                            i <= 9'd0;
                            state <= S_JOIN;
                        end
                    end else case (scan)
                        SCAN_INSIDE, SCAN_GATE: begin
                            if (s_better) begin
                                best <= {1'b0, oj};
                                best_d <= s_d;
                            end
                            j <= j + 1'b1;
                            if (scan_last) begin
                                j <= 9'd0;
                                creating <= 1'b0;
                                lost_for <= 32'd0;
                                if (!best[OIDX_W-1] || s_better)
                                    scan <= SCAN_TAKE;
                                else
                                    scan <= scan == SCAN_INSIDE ? SCAN_GATE : SCAN_FREE;
                            end
                        end
                        SCAN_FREE: begin
                            j <= j + 1'b1;
                            if (!o_valid[oj]) begin
                                best <= {1'b0, oj};
                                creating <= 1'b1;
                                j <= 9'd0;
                                scan <= SCAN_TAKE;
                            end else begin
                                if (s_lost) begin
                                    best <= {1'b0, oj};
                                    lost_for <= s_unseen;
                                end
                                if (scan_last) begin
                                    j <= 9'd0;
                                    creating <= !best[OIDX_W-1] || s_lost;  // in place of a lost object
                                    scan <= SCAN_TAKE;
                                end
                            end
                        end
                        default: begin  // TAKE: the group's object, created in the slot found if it came from FREE
                            g_obj[ci] <= best;
                            if (!best[OIDX_W-1])
                                o_claimed[bo] <= 1'b1;
                            if (creating) begin
                                o_valid[bo] <= 1'b1;
                                o_id[bo] <= next_id;
                                next_id <= next_id + 32'd1;
                                o_x[bo] <= g_cx[PW-1:0];
                                o_y[bo] <= g_cy[PW-1:0];
                                o_rx[bo] <= g_rx_new[OBJ_HALF_W-1:0];
                                o_ry[bo] <= g_ry_new[OBJ_HALF_W-1:0];
                                o_vx[bo] <= g_vx[ci];
                                o_vy[bo] <= g_vy[ci];
                                o_tol[bo] <= g_tol[ci];
                                o_lum[bo] <= {CW{1'b0}};
                                o_cb[bo] <= {CW{1'b0}};
                                o_cr[bo] <= {CW{1'b0}};
                                o_class[bo] <= 8'hff;
                                o_t_born[bo] <= t;
                                o_t_seen[bo] <= t;
                                o_conf[bo] <= 1'b0;
                                o_ever[bo] <= 1'b0;
                                o_members[bo] <= {M_W{1'b0}};
                                o_owner_w[bo] <= {WW{1'b0}};
                                o_vset[bo] <= 1'b0;
                                o_mvx[bo] <= {VW{1'b0}};
                                o_mvy[bo] <= {VW{1'b0}};
                                o_cw[bo] <= {AW{1'b0}};
                                o_lo_x[bo] <= P_MAX[PW-1:0];
                                o_lo_y[bo] <= P_MAX[PW-1:0];
                                o_hi_x[bo] <= P_MIN[PW-1:0];
                                o_hi_y[bo] <= P_MIN[PW-1:0];
                            end
                            scan <= SCAN_INSIDE;
                            best <= {OIDX_W{1'b1}};
                            i <= i + 1'b1;
                            if (last_cluster) begin
                                i <= 9'd0;
                                state <= S_JOIN;
                            end
                        end
                    endcase
                end
                S_JOIN: begin  // every member joins its group's object; each slot remembers it
                    if (!jo_idx[OIDX_W-1]) begin
                        o_members[jo] <= o_members[jo] + 1'b1;
                        if (c_lo_x < sx64(o_lo_x[jo])) o_lo_x[jo] <= c_lo_x[PW-1:0];
                        if (c_hi_x > sx64(o_hi_x[jo])) o_hi_x[jo] <= c_hi_x[PW-1:0];
                        if (c_lo_y < sx64(o_lo_y[jo])) o_lo_y[jo] <= c_lo_y[PW-1:0];
                        if (c_hi_y > sx64(o_hi_y[jo])) o_hi_y[jo] <= c_hi_y[PW-1:0];
                        if (c_meas[ci] && (!o_vset[jo] || c_act[ci] > o_vw[jo])) begin  // a measured velocity
                            o_vset[jo] <= 1'b1;
                            o_vw[jo] <= c_act[ci];
                            o_mvx[jo] <= c_vx[ci];
                            o_mvy[jo] <= c_vy[ci];
                        end
                        if (!c_class[ci][7] && c_act[ci] > o_cw[jo]) begin
                            o_cw[jo] <= c_act[ci];
                            o_mclass[jo] <= c_class[ci];
                            o_mlum[jo] <= c_lum[ci];
                            o_mcb[jo] <= c_cb[ci];
                            o_mcr[jo] <= c_cr[ci];
                        end
                    end
                    s_known[c_slot[ci]] <= 1'b1;
                    s_obj[c_slot[ci]] <= jo_idx;
                    s_id[c_slot[ci]] <= c_id[ci];
                    i <= i + 1'b1;
                    if (last_cluster) begin
                        i <= 9'd0;
                        sub <= 5'd0;
                        state <= S_UPDATE;
                    end
                end
                S_UPDATE: begin  // 4. each object with members: its gains over Δ, the α-β filter, its size, colour, class and tolerance
                    if (!o_valid[oi] || o_members[oi] == {M_W{1'b0}}) begin
                        sub <= 5'd0;
                        i <= i + 1'b1;
                        if (last_object) begin
                            i <= 9'd0;
                            j <= 9'd0;
                            state <= S_MERGE;
                        end
                    end else begin
                        sub <= sub + 1'b1;
                        case (sub)
                            5'd0: seen <= (product >>> (INV_T_FRAME_FRAC - FT)) > DTF_MAX ? DTF_MAX : (product >>> (INV_T_FRAME_FRAC - FT));
                            5'd1: g_pos <= gain_of(product);
                            5'd2: g_rate <= gain_of(product);
                            5'd3: g_rate <= seen == 64'sd0 ? 64'sd0 : ((product >>> FI) < rate_bound(seen) ? (product >>> FI) : rate_bound(seen));
                            5'd4: g_vel <= o_vset[oi] ? gain_of(product) : 64'sd0;  // no measured member: no pull
                            5'd5: g_size <= gain_of(product);
                            5'd6: begin
                                g_col <= gain_of(product);
                                if (u_born) begin  // born this step: the measurement as it is
                                    o_x[oi] <= u_zx[PW-1:0];
                                    o_y[oi] <= u_zy[PW-1:0];
                                    o_rx[oi] <= u_hx[OBJ_HALF_W-1:0];
                                    o_ry[oi] <= u_hy[OBJ_HALF_W-1:0];
                                    if (o_vset[oi]) begin
                                        o_vx[oi] <= o_mvx[oi];
                                        o_vy[oi] <= o_mvy[oi];
                                    end
                                    sub <= u_colour ? 5'd15 : 5'd18;
                                end
                            end
                            5'd7: begin
                                ex <= u_zx - o_xs;
                                o_x[oi] <= next_x[PW-1:0];
                            end
                            5'd8: begin
                                ey <= u_zy - o_ys;
                                o_y[oi] <= next_y[PW-1:0];
                            end
                            5'd9: rate_x <= saturate(align(product, FG + FP, FV), -o_tols, o_tols);  // the residual's pull, within the tolerance
                            5'd10: o_vx[oi] <= next_vx[VW-1:0];
                            5'd11: rate_y <= saturate(align(product, FG + FP, FV), -o_tols, o_tols);
                            5'd12: o_vy[oi] <= next_vy[VW-1:0];
                            5'd13: o_rx[oi] <= next_rx[OBJ_HALF_W-1:0];
                            5'd14: begin
                                o_ry[oi] <= next_ry[OBJ_HALF_W-1:0];
                                sub <= u_colour ? 5'd15 : 5'd18;
                            end
                            5'd15: o_lum[oi] <= next_lum[CW-1:0];
                            5'd16: o_cb[oi] <= next_cb[CW-1:0];
                            5'd17: begin
                                o_cr[oi] <= next_cr[CW-1:0];
                                o_class[oi] <= o_mclass[oi];
                            end
                            default: begin
                                o_tol[oi] <= next_tol[TW-1:0];
                                o_t_seen[oi] <= t;
                                sub <= 5'd0;
                                i <= i + 1'b1;
                                if (last_object) begin
                                    i <= 9'd0;
                                    j <= 9'd0;
                                    state <= S_MERGE;
                                end
                            end
                        endcase
                    end
                end
                S_MERGE: begin  // 5. an object inside an older one, velocities agreeing: the older absorbs it
                    if (!o_valid[oi] || o_members[oi] == {M_W{1'b0}} || m_inside || scan_last) begin
                        if (o_valid[oi] && o_members[oi] != {M_W{1'b0}} && m_inside) begin
                            o_valid[oi] <= 1'b0;
                            for (q = 0; q < N; q = q + 1)
                                if (s_obj[q] == {1'b0, oi})
                                    s_obj[q] <= {1'b0, oj};
                        end
                        j <= 9'd0;
                        i <= i + 1'b1;
                        if (last_object) begin
                            i <= 9'd0;
                            state <= S_OUT;
                        end
                    end else begin
                        j <= j + 1'b1;
                    end
                end
                S_OUT: if (out_free) begin  // 6. birth and death; a record for each reported object
                    if (o_valid[oi]) begin
                        if (o_members[oi] != {M_W{1'b0}}) begin
                            if (!o_conf[oi] && t - o_t_born[oi] >= K_BIRTH)
                                o_conf[oi] <= 1'b1;
                        end else if (q_unseen > (o_conf[oi] ? K_KEEP : K_BIRTH) || q_outside) begin
                            o_valid[oi] <= 1'b0;
                        end
                        if (q_report) begin
                            obj_valid <= 1'b1;
                            obj_data <= q_record;
                            o_ever[oi] <= 1'b1;
                        end
                    end
                    i <= i + 1'b1;
                    if (last_object) begin
                        i <= 9'd0;
                        m <= {M_W{1'b0}};
                        step_count <= step_count + 32'd1;
                        state <= S_COLLECT;
                    end
                end
                default: state <= S_COLLECT;
            endcase
        end
    end
`ifdef FORMAL
`include "evclust_objects_props.vh"
`endif
endmodule
`default_nettype wire
