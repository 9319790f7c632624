// EVCLUST_FAIL(message): stop at elaboration (Verilator, Yosys) or at time 0 (Icarus 11, which
// has no elaboration tasks), for a module parameter that contradicts evclust_params.vh. Use it
// inside a generate-if on the contradiction. Included before a module (macros are global).
`ifndef EVCLUST_REQUIRE_VH
`define EVCLUST_REQUIRE_VH
`ifdef VERILATOR
`define EVCLUST_FAIL(message) $fatal(1, message); initial $fatal(1, message);
`else
`define EVCLUST_FAIL(message) initial $fatal(1, message);
`endif
`endif
