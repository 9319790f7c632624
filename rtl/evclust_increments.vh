// The widths of an event's update kept as increments (docs/DESIGN.md, "Pipeline semantics"):
// each its field's width and a sign. Shared by the update (evclust_update), the commit
// (evclust_commit) and the registers that carry an update in flight (evclust_core). Included
// inside a module body after evclust_params.vh; each module uses some of them.
// verilator lint_off UNUSEDPARAM
localparam integer DP_W = CENTRE_W + 1;                                                  // centre
localparam integer DR_W = (SIZE_TARGET_W > HALF_SIZE_W ? SIZE_TARGET_W : HALF_SIZE_W) + 1;  // half-size
localparam integer DV_W = V_MCM_W + 1;                                                   // MCM velocity
localparam integer DN_W = MCM_NORM_W + 1;                                                // its weight
localparam integer DC_W = COLOUR_W + 1;                                                  // colour
localparam integer DB_W = BACKGROUND_W + 1;                                              // background colour
// verilator lint_on UNUSEDPARAM
