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

    function automatic [CENTRE_BITS-1:0] centre_gap;  // |a - b| of two centres
        input [CENTRE_BITS-1:0] a;
        input [CENTRE_BITS-1:0] b;
        begin
            centre_gap = a > b ? a - b : b - a;
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
    function automatic signed [63:0] w64;  // an unsigned word of up to 63 bits, as the model's int64
        input [62:0] v;
        begin
            w64 = {1'b0, v};
        end
    endfunction

    // Slot k's fields.
    wire [CENTRE_BITS-1:0] kx = centre_x[k*CENTRE_BITS +: CENTRE_BITS], ky = centre_y[k*CENTRE_BITS +: CENTRE_BITS];
    wire [HALF_BITS-1:0]   krx = half_x[k*HALF_BITS +: HALF_BITS], kry = half_y[k*HALF_BITS +: HALF_BITS];
    wire [V_BITS-1:0]      kvx = v_x[k*V_BITS +: V_BITS], kvy = v_y[k*V_BITS +: V_BITS];
    wire [COUNT_BITS-1:0]  kn = measured[k*COUNT_BITS +: COUNT_BITS];
    wire [GROW_BITS-1:0]   kgrow = grow[k*GROW_BITS +: GROW_BITS];
    wire [VREL_BITS-1:0]   kvrel = vrel[k*VREL_BITS +: VREL_BITS];

    integer s;
    reg signed [63:0] dx, dy, sx, sy, grown, dv, fast, tolerance;
    reg               ok;
    always @* begin
        found = 1'b0;
        j = {SLOT_BITS{1'b0}};
        for (s = N - 1; s >= 0; s = s - 1) begin  // downwards: the lowest match is the last written
            dx = w64({{(63 - CENTRE_BITS){1'b0}}, centre_gap(kx, centre_x[s*CENTRE_BITS +: CENTRE_BITS])});
            dy = w64({{(63 - CENTRE_BITS){1'b0}}, centre_gap(ky, centre_y[s*CENTRE_BITS +: CENTRE_BITS])});
            sx = (w64({{(63 - HALF_BITS){1'b0}}, krx}) + w64({{(63 - HALF_BITS){1'b0}}, half_x[s*HALF_BITS +: HALF_BITS]})) <<< UP;
            sy = (w64({{(63 - HALF_BITS){1'b0}}, kry}) + w64({{(63 - HALF_BITS){1'b0}}, half_y[s*HALF_BITS +: HALF_BITS]})) <<< UP;
            grown = align(w64({{(63 - GROW_BITS){1'b0}}, kgrow}) + w64({{(63 - GROW_BITS){1'b0}}, grow[s*GROW_BITS +: GROW_BITS]}), MERGE_SCALE_FRAC + FR, FP);
            dv = w64({{(63 - V_BITS - 1){1'b0}}, v_gap(kvx, v_x[s*V_BITS +: V_BITS])}) + w64({{(63 - V_BITS - 1){1'b0}}, v_gap(kvy, v_y[s*V_BITS +: V_BITS])});
            fast = kvrel > vrel[s*VREL_BITS +: VREL_BITS] ? w64({{(63 - VREL_BITS){1'b0}}, kvrel}) : w64({{(63 - VREL_BITS){1'b0}}, vrel[s*VREL_BITS +: VREL_BITS]});
            tolerance = w64({{(63 - V_TOL_BITS){1'b0}}, v_tol}) + (fast >>> MERGE_V_REL_FRAC);
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
