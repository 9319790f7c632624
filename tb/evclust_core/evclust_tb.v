// Harness for the cocotb testbench (test_evclust_core.py): cocotb loads a batch of events into
// ev_mem and pulses start; the harness streams them into evclust_core at full speed, with random
// input gaps and random output back-pressure from a xorshift generator, and captures every
// record (tagged with the number of events traced before it), every object record of the
// object unit behind the core (evclust_objects, when the header has OBJECTS = 1; same tags) and
// every trace word. Python thus
// touches each event twice, not each clock cycle, which keeps co-simulation fast. The register
// file's AXI4-Lite port is the harness's own (cocotbext-axi drives it); it holds the build's
// parameter set from reset.
`default_nettype none
module evclust_tb #(
    parameter integer DEPTH = 4096,      // events per batch
    parameter integer REC_DEPTH = 16384, // records per batch (and object records)
    parameter integer RUNTIME_CONFIG = 1 // the core's: 0 folds the build's constants in
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,
    input  wire [31:0] count,           // events in this batch
    input  wire [31:0] seed,            // the generator's seed (non-zero), taken at start
    input  wire [7:0]  gap_threshold,   // P(input gap) = gap_threshold / 256 per cycle
    input  wire [7:0]  stall_threshold, // P(output stall) = stall_threshold / 256 per cycle
    output reg         done,
    output reg  [31:0] accepted,
    output reg  [31:0] traced,
    output reg  [31:0] captured,
    output reg  [31:0] objects_captured,
    output reg         overflow,
    output reg  [31:0] cycles,
    output reg  [31:0] filter_cycles,
    output reg  [31:0] filter_steps,
    output reg  [31:0] object_wait_cycles,  // filter-step cycles the core waits on the object unit
    output reg  [31:0] object_busy_cycles,  // cycles the object unit works on a step
    output reg  [31:0] object_drain_cycles, // ... of them with the core idle (the last step of a batch)
    // Latency, in clock edges from the one that takes an event to the one that writes its slot
    // (the trace word leaves on that edge): the smallest, the largest and the sum over the batch.
    output reg  [31:0] latency_min,
    output reg  [31:0] latency_max,
    output reg  [31:0] latency_sum,
    output wire        idle,
    output wire        irq,
    // AXI4-Lite: the register file
    input  wire [11:0] s_axil_awaddr,
    input  wire [2:0]  s_axil_awprot,
    input  wire        s_axil_awvalid,
    output wire        s_axil_awready,
    input  wire [31:0] s_axil_wdata,
    input  wire [3:0]  s_axil_wstrb,
    input  wire        s_axil_wvalid,
    output wire        s_axil_wready,
    output wire [1:0]  s_axil_bresp,
    output wire        s_axil_bvalid,
    input  wire        s_axil_bready,
    input  wire [11:0] s_axil_araddr,
    input  wire [2:0]  s_axil_arprot,
    input  wire        s_axil_arvalid,
    output wire        s_axil_arready,
    output wire [31:0] s_axil_rdata,
    output wire [1:0]  s_axil_rresp,
    output wire        s_axil_rvalid,
    input  wire        s_axil_rready
);
`include "evclust_params.vh"

    localparam integer EV_W = IN_WORD_W, REC_W = REC_WORD_W, OBJ_W = OBJ_WORD_W;  // the layouts of vectors/pack.py

    reg [EV_W-1:0]  ev_mem    [0:DEPTH-1];
    reg [REC_W-1:0] rec_mem   [0:REC_DEPTH-1];
    reg [31:0]      rec_tag   [0:REC_DEPTH-1];  // events traced when the record left
    reg [OBJ_W-1:0] obj_mem   [0:REC_DEPTH-1];
    reg [31:0]      obj_tag   [0:REC_DEPTH-1];
    reg [TRACE_WORD_W-1:0] trace_mem [0:DEPTH-1];
    reg [31:0]      taken_at  [0:DEPTH-1];  // `cycles` when event i was taken
    wire [31:0]     latency = cycles - taken_at[traced[$clog2(DEPTH)-1:0]] - 32'd1;  // trace_valid follows the write by one edge

    reg              running;
    reg [31:0]       random;
    reg              ev_valid;
    reg [EV_W-1:0]   ev_data;
    wire             ev_ready;
    wire             rec_valid;
    wire [REC_W-1:0] rec_data;
    wire             core_rec_valid, core_rec_ready;
    wire [REC_W-1:0] core_rec_data;
    wire             step_valid, step_ready;
    wire [31:0]      step_t;
    wire             obj_valid;
    wire [OBJ_W-1:0] obj_data;
    wire             core_idle, objects_idle;
    wire             obj_ready = running && random[23:16] >= stall_threshold;
    wire             trace_valid;
    wire [TRACE_WORD_W-1:0] trace_data;
    wire [32*CFG_WORDS-1:0] cfg;
    wire             clear;
    wire [N_COUNTERS*COUNTER_INC_W-1:0] count_inc;
    wire             filter_active;
    reg              filter_was_active;
    wire             rec_ready = running && random[15:8] >= stall_threshold;
    // xorshift32 (Marsaglia): x ^= x << 13; x ^= x >> 17; x ^= x << 5.
    wire [31:0]      xs1 = random ^ (random << 13);
    wire [31:0]      xs2 = xs1 ^ (xs1 >> 17);
    wire [31:0]      next_random = xs2 ^ (xs2 << 5);

    evclust_regs #(.RUNTIME_CONFIG(RUNTIME_CONFIG)) regs (
        .clk(clk), .rst(rst),
        .s_axil_awaddr(s_axil_awaddr), .s_axil_awprot(s_axil_awprot), .s_axil_awvalid(s_axil_awvalid), .s_axil_awready(s_axil_awready),
        .s_axil_wdata(s_axil_wdata), .s_axil_wstrb(s_axil_wstrb), .s_axil_wvalid(s_axil_wvalid), .s_axil_wready(s_axil_wready),
        .s_axil_bresp(s_axil_bresp), .s_axil_bvalid(s_axil_bvalid), .s_axil_bready(s_axil_bready),
        .s_axil_araddr(s_axil_araddr), .s_axil_arprot(s_axil_arprot), .s_axil_arvalid(s_axil_arvalid), .s_axil_arready(s_axil_arready),
        .s_axil_rdata(s_axil_rdata), .s_axil_rresp(s_axil_rresp), .s_axil_rvalid(s_axil_rvalid), .s_axil_rready(s_axil_rready),
        .cfg(cfg), .clear(clear), .idle(idle), .count_inc(count_inc), .irq(irq)
    );
    assign idle = core_idle && objects_idle;

    evclust_core #(.RUNTIME_CONFIG(RUNTIME_CONFIG)) core (
        .clk(clk),
        .rst(rst),
        .clear(clear),
        .cfg(cfg),
        .ev_valid(ev_valid),
        .ev_ready(ev_ready),
        .ev_data(ev_data),
        .rec_valid(core_rec_valid),
        .rec_ready(core_rec_ready),
        .rec_data(core_rec_data),
        .trace_valid(trace_valid),
        .trace_data(trace_data),
        .step_valid(step_valid),
        .step_ready(step_ready),
        .step_t(step_t),
        .filter_active(filter_active),
        .idle(core_idle),
        .count_inc(count_inc)
    );

    // The object unit behind the core's record port, passing the records on to the harness.
    generate
        if (OBJECTS != 0) begin : object_unit
            evclust_objects #(.RUNTIME_CONFIG(RUNTIME_CONFIG)) objects (
                .clk(clk), .rst(rst), .clear(clear), .cfg(cfg),
                .rec_valid(core_rec_valid), .rec_ready(core_rec_ready), .rec_data(core_rec_data),
                .out_rec_valid(rec_valid), .out_rec_ready(rec_ready), .out_rec_data(rec_data),
                .step_valid(step_valid), .step_ready(step_ready), .step_t(step_t),
                .obj_valid(obj_valid), .obj_ready(obj_ready), .obj_data(obj_data), .idle(objects_idle)
            );
        end else begin : no_object_unit
            assign rec_valid = core_rec_valid;
            assign core_rec_ready = rec_ready;
            assign rec_data = core_rec_data;
            assign step_ready = 1'b1;
            assign obj_valid = 1'b0;
            assign obj_data = {OBJ_W{1'b0}};
            assign objects_idle = 1'b1;
        end
    endgenerate

    // Functional coverage (evclust.rtl.coverage reads it at the end of a run): cycles in each FSM
    // state, each state change, the filter step's division paths, and the stream conditions
    // (records held by back-pressure, input gaps while the core is ready). The core is reached
    // by hierarchical reference, so the IP itself carries no debug port.
    reg [31:0] cov_state [0:7];   // cycles in state s (ST_INIT .. ST_PHASE)
    reg [31:0] cov_arc   [0:63];  // changes from state a to state b, at a * 8 + b
    reg [31:0] cov_phase [0:3];   // cycles in ST_PHASE per phase_step (decide, divide by τ, divide the frame)
    reg [31:0] cov_stream [0:3];  // record held (valid, not ready); input gap (ready, not valid); both; event and record in one cycle
    reg [2:0]  cov_prev;
    reg        cov_armed;  // from the first reset on: the core's state before it is not the design's
    integer    cov_i;
    initial begin
        for (cov_i = 0; cov_i < 8; cov_i = cov_i + 1) cov_state[cov_i] = 32'd0;
        for (cov_i = 0; cov_i < 64; cov_i = cov_i + 1) cov_arc[cov_i] = 32'd0;
        for (cov_i = 0; cov_i < 4; cov_i = cov_i + 1) begin
            cov_phase[cov_i] = 32'd0;
            cov_stream[cov_i] = 32'd0;
        end
        cov_prev = 3'd0;
        cov_armed = 1'b0;
    end
    always @(posedge clk) begin
        if (rst)
            cov_armed <= 1'b1;
        if (cov_armed && !rst) begin
            cov_state[core.state] <= cov_state[core.state] + 32'd1;
            if (core.state != cov_prev)
                cov_arc[{cov_prev, core.state}] <= cov_arc[{cov_prev, core.state}] + 32'd1;
            if (core.state == core.ST_PHASE)
                cov_phase[core.phase_step] <= cov_phase[core.phase_step] + 32'd1;
            if (rec_valid && !rec_ready)
                cov_stream[0] <= cov_stream[0] + 32'd1;
            if (running && ev_ready && !ev_valid)
                cov_stream[1] <= cov_stream[1] + 32'd1;
            if (rec_valid && !rec_ready && ev_valid && !ev_ready)
                cov_stream[2] <= cov_stream[2] + 32'd1;
            if (ev_valid && ev_ready && rec_valid && rec_ready)
                cov_stream[3] <= cov_stream[3] + 32'd1;
        end
        cov_prev <= core.state;
    end

    // The next event to offer, once the current one (if any) has been taken.
    wire [31:0] next_index = accepted + ((ev_valid && ev_ready) ? 32'd1 : 32'd0);
    wire        offer = running && next_index < count && random[7:0] >= gap_threshold;

    always @(posedge clk) begin
        if (rst || start) begin  // a reset idles the harness; a start begins a batch
            running <= !rst;
            done <= 1'b0;
            ev_valid <= 1'b0;
            random <= (rst || seed == 32'd0) ? 32'd1 : seed;
            accepted <= 32'd0;
            traced <= 32'd0;
            captured <= 32'd0;
            objects_captured <= 32'd0;
            overflow <= 1'b0;
            cycles <= 32'd0;
            filter_cycles <= 32'd0;
            filter_steps <= 32'd0;
            object_wait_cycles <= 32'd0;
            object_busy_cycles <= 32'd0;
            object_drain_cycles <= 32'd0;
            latency_min <= 32'hffffffff;
            latency_max <= 32'd0;
            latency_sum <= 32'd0;
            filter_was_active <= 1'b0;
        end else if (running) begin
            random <= next_random;
            cycles <= cycles + 32'd1;
            filter_was_active <= filter_active;
            if (filter_active)
                filter_cycles <= filter_cycles + 32'd1;
            if (filter_active && !filter_was_active)
                filter_steps <= filter_steps + 32'd1;
            // In a step the core waits on the object unit while it holds a record back, and in the
            // next step's first phase cycle while the last step's end is not taken.
            if (filter_active && ((core_rec_valid && !core_rec_ready) || step_valid))
                object_wait_cycles <= object_wait_cycles + 32'd1;
            if (!objects_idle)
                object_busy_cycles <= object_busy_cycles + 32'd1;
            if (!objects_idle && core_idle)
                object_drain_cycles <= object_drain_cycles + 32'd1;
            // Input: hold an offered event until it is taken (valid may not drop before ready).
            if (ev_valid && ev_ready) begin
                accepted <= accepted + 32'd1;
                taken_at[accepted[$clog2(DEPTH)-1:0]] <= cycles;
            end
            if (!ev_valid || ev_ready) begin
                ev_valid <= offer;
                // Junk while not valid, so a core that samples ev_data at the wrong time fails.
                ev_data <= offer ? ev_mem[next_index[$clog2(DEPTH)-1:0]] : {(EV_W / 32 + 1){next_random}};
            end
            if (trace_valid) begin
                trace_mem[traced[$clog2(DEPTH)-1:0]] <= trace_data;
                traced <= traced + 32'd1;
                latency_sum <= latency_sum + latency;
                if (latency < latency_min)
                    latency_min <= latency;
                if (latency > latency_max)
                    latency_max <= latency;
            end
            if (rec_valid && rec_ready) begin
                if (captured < REC_DEPTH) begin
                    rec_mem[captured[$clog2(REC_DEPTH)-1:0]] <= rec_data;
                    rec_tag[captured[$clog2(REC_DEPTH)-1:0]] <= traced;
                end else begin
                    overflow <= 1'b1;
                end
                captured <= captured + 32'd1;
            end
            if (obj_valid && obj_ready) begin
                if (objects_captured < REC_DEPTH) begin
                    obj_mem[objects_captured[$clog2(REC_DEPTH)-1:0]] <= obj_data;
                    obj_tag[objects_captured[$clog2(REC_DEPTH)-1:0]] <= traced;
                end else begin
                    overflow <= 1'b1;
                end
                objects_captured <= objects_captured + 32'd1;
            end
            // Done: every event taken and traced, the core and the object unit idle again, no record waiting.
            if (accepted == count && traced == count && ev_ready && !ev_valid && !rec_valid && !filter_active && core_idle && objects_idle) begin
                running <= 1'b0;
                done <= 1'b1;
            end
        end
    end
endmodule
`default_nettype wire
