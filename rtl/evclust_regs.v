// evclust_regs: the clusterer's register file on an AXI4-Lite slave (docs/REGISTERS.md, generated
// with the addresses from model/evclust/fixed/registers.py).
//
// Configuration: CFG_WORDS 32-bit words from 0x100, reset to the build's parameter set
// (CFG_RESET) and driven to the core as one flat block; write them while STATUS.IDLE, then
// CTRL.CLEAR restarts the datapath with them. Status: the counters add the core's per-cycle
// increments (modulo 2^32); SATURATED and DROPPED are sticky (write 1 to clear) and raise `irq`
// where IRQ_ENABLE allows. One transaction at a time per direction; responses are OKAY, and an
// address outside the map reads 0 and ignores writes.
`default_nettype none
`include "evclust_require.vh"
module evclust_regs #(
`define EVCLUST_PORT_PARAMETERS
`include "evclust_params.vh"
`undef EVCLUST_PORT_PARAMETERS
,
    parameter integer ADDR_W = 12,
    parameter integer RUNTIME_CONFIG = 1  // 0: the configuration words are the build's, read-only
) (
    input  wire               clk,
    input  wire               rst,
    // AXI4-Lite slave
    input  wire [ADDR_W-1:0]  s_axil_awaddr,
    input  wire [2:0]         s_axil_awprot,
    input  wire               s_axil_awvalid,
    output reg                s_axil_awready,
    input  wire [31:0]        s_axil_wdata,
    input  wire [3:0]         s_axil_wstrb,
    input  wire               s_axil_wvalid,
    output reg                s_axil_wready,
    output wire [1:0]         s_axil_bresp,
    output reg                s_axil_bvalid,
    input  wire               s_axil_bready,
    input  wire [ADDR_W-1:0]  s_axil_araddr,
    input  wire [2:0]         s_axil_arprot,
    input  wire               s_axil_arvalid,
    output reg                s_axil_arready,
    output reg  [31:0]        s_axil_rdata,
    output wire [1:0]         s_axil_rresp,
    output reg                s_axil_rvalid,
    input  wire               s_axil_rready,
    // to and from the core
    output wire [CFG_W-1:0]   cfg,
    output reg                clear,
    input  wire               idle,
    input  wire [COUNT_W-1:0] count_inc,
    output wire               irq
);
`include "evclust_params.vh"

    generate
        if (N != N_CLUSTERS || CFG_W != 32 * CFG_WORDS || COUNT_W != N_COUNTERS * COUNTER_INC_W || ADDR_W < 12) begin : parameters_differ_from_evclust_params_vh
            `EVCLUST_FAIL("evclust_regs: N, CFG_W or COUNT_W differs from evclust_params.vh, or ADDR_W < 12")
        end
    endgenerate

    localparam [ADDR_W-1:0] A_ID = 'h000, A_VERSION = 'h004, A_CTRL = 'h008, A_STATUS = 'h00c, A_IRQ_ENABLE = 'h010, A_BUILD = 'h014;
    // Word addresses (byte address / 4) of the counters and the configuration block.
    localparam integer WORD_W = ADDR_W - 2;
    localparam [WORD_W-1:0] COUNTERS_WORD = 'h040 >> 2, CONFIG_WORD = 'h100 >> 2;
    localparam integer COUNTER_INDEX_W = N_COUNTERS > 1 ? $clog2(N_COUNTERS) : 1;
    localparam integer CFG_INDEX_W = CFG_WORDS > 1 ? $clog2(CFG_WORDS) : 1;
    localparam [WORD_W-1:0] N_COUNTER_WORDS = N_COUNTERS[WORD_W-1:0], N_CFG_WORDS = CFG_WORDS[WORD_W-1:0];
    localparam [31:0] BUILD_VALUE = {PALETTE_SIZE[15:0], N_CLUSTERS[15:0]};

    reg [31:0] config_words [0:CFG_WORDS-1];
    reg [31:0] counters [0:N_COUNTERS-1];
    reg        saturated, dropped;
    reg [2:0]  irq_enable;

    genvar w;
    generate
        for (w = 0; w < CFG_WORDS; w = w + 1) begin : config_out
            assign cfg[32*w +: 32] = config_words[w];
        end
    endgenerate

    assign s_axil_bresp = 2'b00;
    assign s_axil_rresp = 2'b00;
    assign irq = (saturated && irq_enable[1]) || (dropped && irq_enable[2]);

    // Any saturation counter or the drop counter moving this cycle.
    integer c;
    reg any_saturation;
    always @* begin
        any_saturation = 1'b0;
        for (c = COUNT_SAT_ACTIVITY; c < N_COUNTERS; c = c + 1)
            if (count_inc[c * COUNTER_INC_W +: COUNTER_INC_W] != {COUNTER_INC_W{1'b0}})
                any_saturation = 1'b1;
    end
    wire any_drop = count_inc[COUNT_DROPS * COUNTER_INC_W +: COUNTER_INC_W] != {COUNTER_INC_W{1'b0}};

    // Write: address and data may come in either order; the write happens once both are held.
    reg [ADDR_W-1:0] aw_addr;
    reg              aw_held, w_held;
    reg [31:0]       w_data;
    reg [3:0]        w_strb;
    wire             do_write = aw_held && w_held && !s_axil_bvalid;
    wire [WORD_W-1:0] aw_word = aw_addr[ADDR_W-1:2];
    wire [WORD_W-1:0] cfg_offset = aw_word - CONFIG_WORD;
    wire             cfg_hit = aw_word >= CONFIG_WORD && cfg_offset < N_CFG_WORDS;
    wire [CFG_INDEX_W-1:0] cfg_index = cfg_offset[CFG_INDEX_W-1:0];
    wire             write_ctrl = do_write && aw_addr == A_CTRL && w_strb[0];
    wire             write_status = do_write && aw_addr == A_STATUS && w_strb[0];
    wire             clear_counters = write_ctrl && w_data[1];

    function automatic [31:0] strobed;
        input [31:0] old;
        input [31:0] data;
        input [3:0]  strb;
        integer b;
        begin
            for (b = 0; b < 4; b = b + 1)
                strobed[8*b +: 8] = strb[b] ? data[8*b +: 8] : old[8*b +: 8];
        end
    endfunction

    integer i;
    always @(posedge clk) begin
        clear <= 1'b0;
        if (rst) begin
            s_axil_awready <= 1'b0;
            s_axil_wready <= 1'b0;
            s_axil_bvalid <= 1'b0;
            s_axil_arready <= 1'b0;
            s_axil_rvalid <= 1'b0;
            s_axil_rdata <= 32'd0;
            aw_held <= 1'b0;
            w_held <= 1'b0;
            irq_enable <= 3'd0;
            for (i = 0; i < CFG_WORDS; i = i + 1)
                config_words[i] <= CFG_RESET[32*i +: 32];
        end else begin
            // Address and data: one cycle of ready per transfer.
            s_axil_awready <= !aw_held && !s_axil_awready && s_axil_awvalid;
            if (s_axil_awvalid && s_axil_awready) begin
                aw_addr <= s_axil_awaddr;
                aw_held <= 1'b1;
            end
            s_axil_wready <= !w_held && !s_axil_wready && s_axil_wvalid;
            if (s_axil_wvalid && s_axil_wready) begin
                w_data <= s_axil_wdata;
                w_strb <= s_axil_wstrb;
                w_held <= 1'b1;
            end
            if (do_write) begin
                aw_held <= 1'b0;
                w_held <= 1'b0;
                s_axil_bvalid <= 1'b1;
                if (cfg_hit && RUNTIME_CONFIG != 0)
                    config_words[cfg_index] <= strobed(config_words[cfg_index], w_data, w_strb);
                if (aw_addr == A_IRQ_ENABLE && w_strb[0])
                    irq_enable <= w_data[2:0];
                if (write_ctrl && w_data[0])
                    clear <= 1'b1;
            end
            if (s_axil_bvalid && s_axil_bready)
                s_axil_bvalid <= 1'b0;
            // Read
            s_axil_arready <= !s_axil_rvalid && !s_axil_arready && s_axil_arvalid;
            if (s_axil_arvalid && s_axil_arready) begin
                s_axil_rvalid <= 1'b1;
                s_axil_rdata <= read_word(s_axil_araddr);
            end
            if (s_axil_rvalid && s_axil_rready)
                s_axil_rvalid <= 1'b0;
        end
    end

    // Counters and sticky flags: cleared by a reset or CTRL.CLEAR_COUNTERS (flags: STATUS, write 1).
    always @(posedge clk) begin
        if (rst || clear_counters) begin
            for (i = 0; i < N_COUNTERS; i = i + 1)
                counters[i] <= 32'd0;
            saturated <= 1'b0;
            dropped <= 1'b0;
        end else begin
            for (i = 0; i < N_COUNTERS; i = i + 1)
                counters[i] <= counters[i] + {{(32 - COUNTER_INC_W){1'b0}}, count_inc[i * COUNTER_INC_W +: COUNTER_INC_W]};
            saturated <= any_saturation || (saturated && !(write_status && w_data[1]));
            dropped <= any_drop || (dropped && !(write_status && w_data[2]));
        end
    end

    function automatic [31:0] read_word;
        input [ADDR_W-1:0] addr;
        reg [WORD_W-1:0] word, counter, offset;
        begin
            read_word = 32'd0;
            word = addr[ADDR_W-1:2];
            counter = word - COUNTERS_WORD;
            offset = word - CONFIG_WORD;
            if (addr == A_ID)
                read_word = REG_ID_VALUE;
            else if (addr == A_VERSION)
                read_word = REG_VERSION_VALUE;
            else if (addr == A_STATUS)
                read_word = {29'd0, dropped, saturated, idle};
            else if (addr == A_IRQ_ENABLE)
                read_word = {29'd0, irq_enable};
            else if (addr == A_BUILD)
                read_word = BUILD_VALUE;
            else if (word >= COUNTERS_WORD && counter < N_COUNTER_WORDS)
                read_word = counters[counter[COUNTER_INDEX_W-1:0]];
            else if (word >= CONFIG_WORD && offset < N_CFG_WORDS)
                read_word = config_words[offset[CFG_INDEX_W-1:0]];
        end
    endfunction

    wire [7:0] unused_bus_bits = {s_axil_awprot, s_axil_arprot, aw_addr[1:0]};  // protection and byte offsets

`ifdef FORMAL
`include "evclust_regs_props.vh"  // formal/evclust_regs/: the bus properties, for SymbiYosys only
`endif
endmodule
`default_nettype wire
