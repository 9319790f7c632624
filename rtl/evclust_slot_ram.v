// evclust_slot_ram: the cluster table's rows that no search compares (evclust_core), one row
// per slot: one synchronous write port and three asynchronous read ports, so synthesis maps it
// to distributed RAM (on ECP5, TRELLIS_DPR16X4 cells: one copy per read port; a port whose data
// nothing reads costs nothing) instead of flip-flops behind N-way multiplexers. The contents after power-up are undefined: the core
// reads a row only once its slot has been created.
`default_nettype none
module evclust_slot_ram #(
    parameter integer DEPTH = 16,
    parameter integer WIDTH = 8,
    parameter integer ADDR_W = 4
) (
    input  wire              clk,
    input  wire              we,
    input  wire [ADDR_W-1:0] waddr,
    input  wire [WIDTH-1:0]  wdata,
    input  wire [ADDR_W-1:0] raddr_a,
    output wire [WIDTH-1:0]  rdata_a,
    input  wire [ADDR_W-1:0] raddr_b,
    output wire [WIDTH-1:0]  rdata_b,
    input  wire [ADDR_W-1:0] raddr_e,
    output wire [WIDTH-1:0]  rdata_e
);
    reg [WIDTH-1:0] rows [0:DEPTH-1];

    always @(posedge clk)
        if (we)
            rows[waddr] <= wdata;

    assign rdata_a = rows[raddr_a];
    assign rdata_b = rows[raddr_b];
    assign rdata_e = rows[raddr_e];
endmodule
`default_nettype wire
