// The merge search of a filter step (model: fixed_model._mergeable, over j > k in slot order):
// the lowest live slot j after the swept slot k that is the same object, from N comparators
// at once. Boxes that overlap (velocities not disagreeing), or boxes grown by
// merge_scale * (max R_k + max R_j) that overlap with measured velocities (two interval
// measurements each) within merge_v_tol + merge_v_rel * max(speed_k, speed_j). Each slot brings
// the products merge_scale * max(Rx, Ry) and merge_v_rel * (|Vx| + |Vy|), unaligned, that the
// core derives as it writes the slot, so a comparator adds and compares (merge_v_rel >= 0: the
// larger product is the faster slot's). Differences are taken at the words' own width.
`default_nettype none
`include "evclust_require.vh"
module evclust_merge_search #(
    parameter integer N = 16,
    parameter integer SLOT_BITS = 4,
    parameter integer CENTRE_BITS = 26,  // the header's CENTRE_W (checked below)
    parameter integer HALF_BITS = 17,    // HALF_SIZE_W
    parameter integer V_BITS = 16,       // V_INT_W
    parameter integer COUNT_BITS = 2,    // INTERVAL_UPDATES_W
    parameter integer V_TOL_BITS = 15,   // MERGE_V_TOL_W
    parameter integer GROW_BITS = 24,    // the core's stored products
    parameter integer VREL_BITS = 24
) (
    input  wire [SLOT_BITS-1:0]     k,
    input  wire [N-1:0]             valid,     // slot i at bit i, and likewise below
    input  wire [N*CENTRE_BITS-1:0] centre_x,
    input  wire [N*CENTRE_BITS-1:0] centre_y,
    input  wire [N*HALF_BITS-1:0]   half_x,
    input  wire [N*HALF_BITS-1:0]   half_y,
    input  wire [N*V_BITS-1:0]      v_x,       // the interval velocity
    input  wire [N*V_BITS-1:0]      v_y,
    input  wire [N*COUNT_BITS-1:0]  measured,  // interval measurements + 1 (vi_count)
    input  wire [N*GROW_BITS-1:0]   grow,
    input  wire [N*VREL_BITS-1:0]   vrel,
    input  wire [V_TOL_BITS-1:0]    v_tol,     // merge_v_tol, a run-time register
    output reg                      found,
    output reg  [SLOT_BITS-1:0]     j
);
`include "evclust_params.vh"
`include "evclust_arith.vh"

    generate
        if (CENTRE_BITS != CENTRE_W || HALF_BITS != HALF_SIZE_W || V_BITS != V_INT_W || COUNT_BITS != INTERVAL_UPDATES_W
            || V_TOL_BITS != MERGE_V_TOL_W) begin : widths_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_merge_search: a width differs from evclust_params.vh")
        end
    endgenerate

    localparam integer FP = CENTRE_FRAC, FR = HALF_SIZE_FRAC, UP = FP - FR;
    localparam [COUNT_BITS-1:0] MEASURED = 2;  // two interval measurements: vi_count >= 2

    function automatic [CENTRE_BITS-1:0] centre_gap;  // |a - b| of two centres: a subtraction, negated if it borrowed
        input [CENTRE_BITS-1:0] a;
        input [CENTRE_BITS-1:0] b;
        reg [CENTRE_BITS:0] d;
        begin
            d = {1'b0, a} - {1'b0, b};
            centre_gap = d[CENTRE_BITS] ? ~d[CENTRE_BITS-1:0] + 1'b1 : d[CENTRE_BITS-1:0];
        end
    endfunction
    function automatic [V_BITS:0] v_gap;  // |a - b| of two v_int words, < 2^V_BITS
        input [V_BITS-1:0] a;
        input [V_BITS-1:0] b;
        reg signed [V_BITS:0] d;
        begin
            d = $signed({a[V_BITS-1], a}) - $signed({b[V_BITS-1], b});
            v_gap = d[V_BITS] ? -d : d;
        end
    endfunction

    // Slot k's fields.
    wire [CENTRE_BITS-1:0] kx = centre_x[k*CENTRE_BITS +: CENTRE_BITS], ky = centre_y[k*CENTRE_BITS +: CENTRE_BITS];
    wire [HALF_BITS-1:0]   krx = half_x[k*HALF_BITS +: HALF_BITS], kry = half_y[k*HALF_BITS +: HALF_BITS];
    wire [V_BITS-1:0]      kvx = v_x[k*V_BITS +: V_BITS], kvy = v_y[k*V_BITS +: V_BITS];
    wire [COUNT_BITS-1:0]  kn = measured[k*COUNT_BITS +: COUNT_BITS];
    wire [GROW_BITS-1:0]   kgrow = grow[k*GROW_BITS +: GROW_BITS];
    wire [VREL_BITS-1:0]   kvrel = vrel[k*VREL_BITS +: VREL_BITS];

    // Every quantity is non-negative: the comparators work at widths that hold them (a 64-bit
    // comparison per slot would cost a 64-bit carry chain each).
    localparam integer SHIFT_UP = FP - MERGE_SCALE_FRAC - FR;  // the grown reach's alignment to P
    localparam integer GROWN_W = SHIFT_UP >= 0 ? GROW_BITS + 1 + SHIFT_UP : GROW_BITS + 1;
    localparam integer BOX_W = HALF_BITS + 1 + UP;
    localparam integer POS_W = (CENTRE_BITS > BOX_W ? (CENTRE_BITS > GROWN_W ? CENTRE_BITS : GROWN_W) : (BOX_W > GROWN_W ? BOX_W : GROWN_W)) + 1;
    localparam integer VEL_W = (V_BITS + 2 > V_TOL_BITS ? (V_BITS + 2 > VREL_BITS ? V_BITS + 2 : VREL_BITS) : (V_TOL_BITS > VREL_BITS ? V_TOL_BITS : VREL_BITS)) + 1;
    function automatic [POS_W-1:0] pos;  // an unsigned word at the position comparators' width
        input [62:0] v;
        /* verilator lint_off UNUSEDSIGNAL */  // the bits above the width are zero
        reg [63:0] wide;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            wide = {1'b0, v};
            pos = wide[POS_W-1:0];
        end
    endfunction
    function automatic [VEL_W-1:0] vel;  // ... at the velocity comparators' width
        input [62:0] v;
        /* verilator lint_off UNUSEDSIGNAL */  // the bits above the width are zero
        reg [63:0] wide;
        /* verilator lint_on UNUSEDSIGNAL */
        begin
            wide = {1'b0, v};
            vel = wide[VEL_W-1:0];
        end
    endfunction

    integer s;
    reg [POS_W-1:0] dx, dy, sx, sy, grow_sum, grown;
    reg [VEL_W-1:0] dv, fast, tolerance;
    reg             ok;
    always @* begin
        found = 1'b0;
        j = {SLOT_BITS{1'b0}};
        for (s = N - 1; s >= 0; s = s - 1) begin  // downwards: the lowest match is the last written
            dx = pos({{(63 - CENTRE_BITS){1'b0}}, centre_gap(kx, centre_x[s*CENTRE_BITS +: CENTRE_BITS])});
            dy = pos({{(63 - CENTRE_BITS){1'b0}}, centre_gap(ky, centre_y[s*CENTRE_BITS +: CENTRE_BITS])});
            sx = (pos({{(63 - HALF_BITS){1'b0}}, krx}) + pos({{(63 - HALF_BITS){1'b0}}, half_x[s*HALF_BITS +: HALF_BITS]})) << UP;
            sy = (pos({{(63 - HALF_BITS){1'b0}}, kry}) + pos({{(63 - HALF_BITS){1'b0}}, half_y[s*HALF_BITS +: HALF_BITS]})) << UP;
            grow_sum = pos({{(63 - GROW_BITS){1'b0}}, kgrow}) + pos({{(63 - GROW_BITS){1'b0}}, grow[s*GROW_BITS +: GROW_BITS]});
            grown = SHIFT_UP >= 0 ? grow_sum << SHIFT_UP : grow_sum >> (-SHIFT_UP);  // align, floored
            dv = vel({{(63 - V_BITS - 1){1'b0}}, v_gap(kvx, v_x[s*V_BITS +: V_BITS])}) + vel({{(63 - V_BITS - 1){1'b0}}, v_gap(kvy, v_y[s*V_BITS +: V_BITS])});
            fast = kvrel > vrel[s*VREL_BITS +: VREL_BITS] ? vel({{(63 - VREL_BITS){1'b0}}, kvrel}) : vel({{(63 - VREL_BITS){1'b0}}, vrel[s*VREL_BITS +: VREL_BITS]});
            tolerance = vel({{(63 - V_TOL_BITS){1'b0}}, v_tol}) + (fast >> MERGE_V_REL_FRAC);
            ok = dx <= sx + grown && dy <= sy + grown;
            if (kn >= MEASURED && measured[s*COUNT_BITS +: COUNT_BITS] >= MEASURED)
                ok = ok && dv <= tolerance;
            else
                ok = ok && dx <= sx && dy <= sy;
            if (MERGE != 0 && s > k && valid[s] && ok) begin
                found = 1'b1;
                j = s[SLOT_BITS-1:0];
            end
        end
    end
endmodule
`default_nettype wire
