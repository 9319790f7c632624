// evclust_axis: the clusterer as it sits in a system. Events in, cluster records and object
// records out on AXI4-Stream, the register file (evclust_regs) on AXI4-Lite, an interrupt, and
// the trace as a monitor port. Each word is the core's or the object unit's, zero-padded to
// whole bytes (TDATA widths must be). With OBJECTS = 0 in the header there is no object unit
// and the object stream stays idle.
//
// The event stream's tready depends on the core's state only, never on tvalid, and the record
// stream's tvalid and tdata come from registers, as AXI4-Stream asks. One clock and one
// synchronous active-high reset (`rst`) for everything; CTRL.CLEAR restarts the datapath alone.
`default_nettype none
`include "evclust_require.vh"
module evclust_axis #(
`define EVCLUST_PORT_PARAMETERS
`include "evclust_params.vh"
`undef EVCLUST_PORT_PARAMETERS
,
    parameter integer EV_BYTES = (EV_W + 7) / 8,
    parameter integer REC_BYTES = (REC_W + 7) / 8,
    parameter integer OBJ_BYTES = (OBJ_W + 7) / 8,
    parameter integer RUNTIME_CONFIG = 1,  // 0: the build's parameter set only, in the smaller core
    parameter integer MIXING_DSP = 6       // the palette's multiplier blocks (evclust_core)
) (
    input  wire                   clk,
    input  wire                   rst,
    // events: the word of vectors/*/events.hex (IN_* fields)
    input  wire [8*EV_BYTES-1:0]  s_axis_event_tdata,
    input  wire                   s_axis_event_tvalid,
    output wire                   s_axis_event_tready,
    // cluster records: the word of expected.hex (REC_* fields); tie tready high if unused
    output wire [8*REC_BYTES-1:0] m_axis_record_tdata,
    output wire                   m_axis_record_tvalid,
    input  wire                   m_axis_record_tready,
    // object records: the word of objects.hex (OBJ_* fields)
    output wire [8*OBJ_BYTES-1:0] m_axis_object_tdata,
    output wire                   m_axis_object_tvalid,
    input  wire                   m_axis_object_tready,
    // each event's action (TRACE_* fields), one cycle, no back-pressure
    output wire                   trace_valid,
    output wire [TRACE_W-1:0]     trace_data,
    // AXI4-Lite: the register file (docs/REGISTERS.md)
    input  wire [11:0]            s_axil_awaddr,
    input  wire [2:0]             s_axil_awprot,
    input  wire                   s_axil_awvalid,
    output wire                   s_axil_awready,
    input  wire [31:0]            s_axil_wdata,
    input  wire [3:0]             s_axil_wstrb,
    input  wire                   s_axil_wvalid,
    output wire                   s_axil_wready,
    output wire [1:0]             s_axil_bresp,
    output wire                   s_axil_bvalid,
    input  wire                   s_axil_bready,
    input  wire [11:0]            s_axil_araddr,
    input  wire [2:0]             s_axil_arprot,
    input  wire                   s_axil_arvalid,
    output wire                   s_axil_arready,
    output wire [31:0]            s_axil_rdata,
    output wire [1:0]             s_axil_rresp,
    output wire                   s_axil_rvalid,
    input  wire                   s_axil_rready,
    output wire                   irq
);
`include "evclust_params.vh"

    generate
        if (EV_BYTES * 8 < EV_W || REC_BYTES * 8 < REC_W || OBJ_BYTES * 8 < OBJ_W) begin : stream_too_narrow
            `EVCLUST_FAIL("evclust_axis: EV_BYTES, REC_BYTES or OBJ_BYTES too small for the words")
        end
    endgenerate

    wire [CFG_W-1:0]   cfg;
    wire               clear, idle, core_idle, objects_idle;
    wire [COUNT_W-1:0] count_inc;
    wire [REC_W-1:0]   core_record, record;
    wire               core_rec_valid, core_rec_ready;
    wire               step_valid, step_ready;
    wire [31:0]        step_t;
    wire [OBJ_W-1:0]   object;
    wire               unused_filter_active;
    assign idle = core_idle && objects_idle;

    evclust_regs #(.N(N), .EV_W(EV_W), .REC_W(REC_W), .TRACE_W(TRACE_W), .OBJ_W(OBJ_W), .CFG_W(CFG_W), .COUNT_W(COUNT_W), .RUNTIME_CONFIG(RUNTIME_CONFIG)) regs (
        .clk(clk), .rst(rst),
        .s_axil_awaddr(s_axil_awaddr), .s_axil_awprot(s_axil_awprot), .s_axil_awvalid(s_axil_awvalid), .s_axil_awready(s_axil_awready),
        .s_axil_wdata(s_axil_wdata), .s_axil_wstrb(s_axil_wstrb), .s_axil_wvalid(s_axil_wvalid), .s_axil_wready(s_axil_wready),
        .s_axil_bresp(s_axil_bresp), .s_axil_bvalid(s_axil_bvalid), .s_axil_bready(s_axil_bready),
        .s_axil_araddr(s_axil_araddr), .s_axil_arprot(s_axil_arprot), .s_axil_arvalid(s_axil_arvalid), .s_axil_arready(s_axil_arready),
        .s_axil_rdata(s_axil_rdata), .s_axil_rresp(s_axil_rresp), .s_axil_rvalid(s_axil_rvalid), .s_axil_rready(s_axil_rready),
        .cfg(cfg), .clear(clear), .idle(idle), .count_inc(count_inc), .irq(irq)
    );

    evclust_core #(.N(N), .EV_W(EV_W), .REC_W(REC_W), .TRACE_W(TRACE_W), .OBJ_W(OBJ_W), .CFG_W(CFG_W), .COUNT_W(COUNT_W), .RUNTIME_CONFIG(RUNTIME_CONFIG), .MIXING_DSP(MIXING_DSP)) core (
        .clk(clk), .rst(rst), .clear(clear), .cfg(cfg),
        .ev_valid(s_axis_event_tvalid), .ev_ready(s_axis_event_tready), .ev_data(s_axis_event_tdata[EV_W-1:0]),
        .rec_valid(core_rec_valid), .rec_ready(core_rec_ready), .rec_data(core_record),
        .trace_valid(trace_valid), .trace_data(trace_data),
        .step_valid(step_valid), .step_ready(step_ready), .step_t(step_t),
        .filter_active(unused_filter_active), .idle(core_idle), .count_inc(count_inc)
    );
    generate
        if (OBJECTS != 0) begin : object_unit
            evclust_objects #(.N(N), .EV_W(EV_W), .REC_W(REC_W), .TRACE_W(TRACE_W), .OBJ_W(OBJ_W), .CFG_W(CFG_W), .COUNT_W(COUNT_W),
                              .RUNTIME_CONFIG(RUNTIME_CONFIG)) objects (
                .clk(clk), .rst(rst), .clear(clear), .cfg(cfg),
                .rec_valid(core_rec_valid), .rec_ready(core_rec_ready), .rec_data(core_record),
                .out_rec_valid(m_axis_record_tvalid), .out_rec_ready(m_axis_record_tready), .out_rec_data(record),
                .step_valid(step_valid), .step_ready(step_ready), .step_t(step_t),
                .obj_valid(m_axis_object_tvalid), .obj_ready(m_axis_object_tready), .obj_data(object), .idle(objects_idle)
            );
        end else begin : no_object_unit
            assign m_axis_record_tvalid = core_rec_valid;
            assign core_rec_ready = m_axis_record_tready;
            assign record = core_record;
            assign step_ready = 1'b1;
            assign m_axis_object_tvalid = 1'b0;
            assign object = {OBJ_W{1'b0}};
            assign objects_idle = 1'b1;
            wire unused_step = &{1'b0, step_valid, step_t, m_axis_object_tready};
        end
    endgenerate
    assign m_axis_record_tdata = {{(8 * REC_BYTES - REC_W){1'b0}}, record};
    assign m_axis_object_tdata = {{(8 * OBJ_BYTES - OBJ_W){1'b0}}, object};

    wire [8*EV_BYTES-1:0] unused_event_padding = s_axis_event_tdata;  // the bits above EV_W are padding
endmodule
`default_nettype wire
