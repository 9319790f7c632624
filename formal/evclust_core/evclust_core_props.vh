// Formal properties of evclust_core's stream ports, included in its body under `ifdef FORMAL
// (SymbiYosys: formal/evclust_core/evclust_core.sby, `make formal`). Inputs are free: any event
// stream, any back-pressure, any configuration, resets and clears at any time. Proved by
// k-induction for every reachable state:
//  - no event is accepted during a reset or a clear;
//  - a record on offer holds, data and all, until it is taken (none dropped or overwritten
//    under back-pressure);
//  - every accepted event gives exactly one trace pulse: the events accepted and not yet
//    traced are exactly those in stage A, in stage B and on the trace port, so none is lost or
//    traced twice (a reset or clear discards those in flight, as documented);
//  - the end of a filter step (step_valid, step_t) holds until it is taken, and never comes
//    while a record waits (the object unit sees every record of a step before its end);
//  - a filter step ends within F_FILTER_BOUND cycles in which neither a record nor the last
//    step's end waits for its consumer
//    (81 in the reference build, which has no merges; with MERGE = 1, up to N - 1 merges of
//    MERGE_MOMENT_W + 3 cycles more: 228 in the merge job's build), and the core, IDLE again,
//    takes the next event, or first moves the reference the event in stage A needs (a move is
//    PHASE and one SWEEP pass of N cycles, with no record, under the same bound);
//  - one record per reported slot per sweep: every slot visited once, each slot kept leaves the
//    sweep's tail once, a record only for a slot out of the tail and never two for one slot,
//    and at the sweep's end the records are exactly the table's reported clusters.
// The dividers' steps to go and the tail's stage tags reach the properties through ports that
// evclust_udiv and evclust_pipediv have only under `ifdef FORMAL. Three jobs: evclust_core.sby on
// the reference build's header (MERGE = 0, N = 16), evclust_core_merge.sby on a generated
// merge-enabled one (model/evclust/rtl/formal.py: the default parameters at N = 4), and
// evclust_core_reference.sby on that build with the activity kept against a reference time
// (ACTIVITY_REFERENCE = 1, UPDATE_DELAY = 2), the only one with the reference's move.

    genvar f_j, f_s;
    reg f_past_valid = 1'b0;
    always @(posedge clk)
        f_past_valid <= 1'b1;
    always @* if (!f_past_valid) assume (rst);

    // Events accepted and not yet traced.
    reg [2:0] f_open;
    always @(posedge clk)
        if (dp_rst)
            f_open <= 3'd0;
        else
            f_open <= f_open + {2'd0, ev_valid && ev_ready} - {2'd0, trace_valid};
    wire f_in_b = state == ST_EXEC || state == ST_SCAN || state == ST_EVICT;

    always @* begin
        assert (!(dp_rst && ev_ready));
        if (f_past_valid && !rst)
            assert (f_open == {2'd0, a_valid} + {2'd0, f_in_b} + {2'd0, trace_valid});
    end
    always @(posedge clk) if (f_past_valid && !$past(dp_rst) && $past(rec_valid && !rec_ready))
        assert (rec_valid && rec_data == $past(rec_data));
    // A filter step's end holds, time and all, until it is taken, and never comes while a record waits.
    always @(posedge clk) if (f_past_valid && !$past(dp_rst) && $past(step_valid && !step_ready))
        assert (step_valid && step_t == $past(step_t));
    always @* assert (!(step_valid && rec_valid));
    // What k-induction needs: no sweep runs while the last step's end waits (PHASE holds it).
    // The reference's move (below) may: it makes no record.
    always @* if (f_past_valid && step_pending && !moving)
        assert (state != ST_SWEEP && state != ST_MERGE && (state != ST_PHASE || phase_step == PHASE_DECIDE));

    // ---------------------------------------------------------------- the filter step ends
    // Bounded liveness: a filter step (PHASE, SWEEP, MERGE) ends within F_FILTER_BOUND cycles
    // in which no record waits for its consumer (a waiting record holds the sweep, for as long
    // as the consumer likes), after which the core is IDLE and takes the next event. The bound:
    // PHASE's deciding cycle, the division phase / tau (33 steps and the cycle it is read) and
    // T_frame / n (FRAME_PER_TAU_W steps and one), then one sweep cycle per slot and tail stage,
    // and with MERGE = 1 up to N - 1 merges (each absorbs a valid later slot, and slot 0 is
    // never absorbed) of F_MERGE_CYCLES each: the sweep cycle that finds it, the cycle that
    // starts the dividers, their MERGE_MOMENT_W steps and the cycle that writes the slot.
    localparam integer F_PHASE_MAX = 1 + (33 + 1) + (FRAME_PER_TAU_W + 1);
    localparam integer F_MERGE_CYCLES = MERGE_MOMENT_W + 3;
    localparam integer F_MERGES_MAX = MERGE != 0 ? N - 1 : 0;
    localparam integer F_FILTER_BOUND = F_PHASE_MAX + LAST_SWEEP_I + 1 + F_MERGES_MAX * F_MERGE_CYCLES;
    localparam integer F_CYCLES_W = $clog2(F_FILTER_BOUND + 1);
    localparam integer F_MOVE_DRAIN = 2;  // a move's PHASE cycles at most: one drains stage H through C, one goes on
    wire f_filter = state == ST_PHASE || state == ST_SWEEP || state == ST_MERGE;
    wire f_sweeping = state == ST_SWEEP || state == ST_MERGE;
    reg [F_CYCLES_W-1:0] f_filter_cycles;  // the filter step's cycles so far without a record waiting
    always @(posedge clk)
        if (dp_rst || !f_filter)
            f_filter_cycles <= {F_CYCLES_W{1'b0}};
        else if (!(rec_valid && !rec_ready) && !phase_hold)  // neither a record nor the last step's end waits
            f_filter_cycles <= f_filter_cycles + 1'b1;

    // The slots this sweep's merges have absorbed, and how many.
    reg [N-1:0] f_absorbed;
    always @(posedge clk)
        if (dp_rst || state == ST_PHASE)
            f_absorbed <= {N{1'b0}};
        else if (m_write)
            f_absorbed[m_j] <= 1'b1;
    function automatic integer f_count_ones;
        input [N-1:0] bits;
        integer b;
        begin
            f_count_ones = 0;
            for (b = 0; b < N; b = b + 1)
                f_count_ones = f_count_ones + bits[b];
        end
    endfunction
    wire [31:0] f_merges = f_count_ones(f_absorbed);
    wire [31:0] f_sweep_cycles = F_PHASE_MAX + index + f_merges * F_MERGE_CYCLES;  // the most cycles so far at this point of the sweep

    always @* if (f_past_valid) begin
        assert (!f_filter || f_filter_cycles < F_FILTER_BOUND);
        assert (state != ST_IDLE || dp_rst || ev_ready || move_due);  // (or it moves the reference first)
        // The reference's move (ACTIVITY_REFERENCE) is built only with the mode; these jobs prove
        // the builds without it, where k-induction must not start from a move under way.
        if (!REFERENCED)
            assert (!moving);
        // The reference's move: PHASE (stage H drained through C) from IDLE, then one pass of
        // SWEEP over the slots that decays each activity and moves nothing down the tail.
        if (moving) begin
            assert (state == ST_PHASE || state == ST_SWEEP);
            assert (state != ST_PHASE || (index == {SWEEP_W{1'b0}} && f_filter_cycles + move_hold < F_MOVE_DRAIN));
            assert (state != ST_SWEEP || (index <= LAST_SLOT && f_filter_cycles <= F_MOVE_DRAIN + index));
        end
        // What k-induction needs: where each phase of the step stands, against the dividers'
        // steps to go.
        if (MERGE == 0)
            assert (state != ST_MERGE && f_absorbed == {N{1'b0}});
        if (state == ST_PHASE) begin
            // (A move's PHASE finds phase_step as the last step left it, or unset after a reset.)
            assert (index == {SWEEP_W{1'b0}} && (moving || phase_step != 2'd3));
            if (phase_step == PHASE_DECIDE && !moving)  // (a move's PHASE: above)
                assert (f_filter_cycles == {F_CYCLES_W{1'b0}});
            if (phase_step == PHASE_BY_TAU && !moving)
                assert ((f_by_tau_count != 0 || by_tau_done) && f_filter_cycles + f_by_tau_count <= 1 + 33);
            if (phase_step == PHASE_FRAME && !moving)
                assert ((f_frame_count != 0 || frame_done) && f_filter_cycles + f_frame_count <= 1 + (33 + 1) + FRAME_PER_TAU_W);
        end
        if (state == ST_SWEEP)
            assert (index <= LAST_SWEEP && f_filter_cycles <= f_sweep_cycles);
        // A merge: slot k (the index) absorbs a valid later slot m_j, not yet absorbed; no record
        // is on offer (the sweep cycle that found it had none waiting and sent none to the tail);
        // the two dividers step together, and the cycles so far against their steps to go.
        assert (!f_absorbed[0]);
        assert (f_merge_x_count == f_merge_y_count && div_x_done == div_y_done);
        if (state != ST_MERGE)
            assert (!m_started);
        if (state == ST_MERGE) begin
            assert (index < N_SLOTS && m_j > k && m_j <= LAST_SLOT_I && valid[m_j] && !f_absorbed[m_j] && !rec_valid);
            if (!m_started)
                assert (f_filter_cycles <= f_sweep_cycles + 1);
            else
                assert (div_x_done == (f_merge_x_count == 0) && f_filter_cycles + f_merge_x_count <= f_sweep_cycles + 2 + MERGE_MOMENT_W);
        end
    end
    generate
        for (f_s = 0; f_s < N; f_s = f_s + 1) begin : f_absorbed_slot
            always @* if (f_past_valid && f_sweeping && f_absorbed[f_s])
                assert (!valid[f_s]);
        end
    endgenerate

    // ---------------------------------------------------------------- one record per reported slot
    // Within a sweep: stage 0 visits every slot once; each slot it keeps (valid, not expired)
    // leaves the tail exactly once and before the sweep ends; a record is offered (valid up
    // after a cycle with none waiting) only for a slot that has left the tail, never twice for
    // one slot; and when the sweep ends, the slots with a record are exactly the table's
    // reported clusters (valid and reported). With the stream property above (a record holds
    // until taken), each is taken once.
    localparam integer F_STAGES = (Q_W + SWEEP_DIV_STEP - 1) / SWEEP_DIV_STEP;  // div_vmx's stages
    localparam integer F_LAST = F_STAGES + 1;  // T1's register, which stage T2 reads
    // The tail's positions: 0, its first register (p_*); 1 to F_STAGES, div_vmx's stages; F_LAST,
    // T1's register (t2_*), out of which a slot leaves the tail.
    wire [F_LAST:0]            f_live;
    wire [SLOT_W-1:0]          f_slot [0:F_LAST];
    assign f_live[0] = p_live;
    assign f_slot[0] = p_slot;
    assign f_live[F_LAST] = t2_live;
    assign f_slot[F_LAST] = t2_slot;
    generate
        for (f_j = 1; f_j <= F_STAGES; f_j = f_j + 1) begin : f_tail
            assign f_live[f_j] = f_vmx_tags[(f_j - 1) * TAG_W + TAG_W - 1];
            assign f_slot[f_j] = f_vmx_tags[(f_j - 1) * TAG_W + TAG_W - 2 -: SLOT_W];
        end
    endgenerate

    reg [N-1:0] f_visited, f_kept, f_out, f_recorded;  // this sweep's slots: stage 0, the tail's exit, records
    reg         f_held_q, f_after_sweep;
    wire [REC_SLOT_W-1:0] f_rec_slot = rec_data[REC_SLOT_LSB +: REC_SLOT_W];
    wire        f_new_record = rec_valid && !f_held_q;  // a record offered this cycle for the first time
    wire [N-1:0] f_offered = f_recorded | (f_new_record ? {{(N - 1){1'b0}}, 1'b1} << f_rec_slot : {N{1'b0}});
    wire [N-1:0] f_reported;
    generate
        for (f_s = 0; f_s < N; f_s = f_s + 1) begin : f_table
            assign f_reported[f_s] = valid[f_s] && reported[f_s];
        end
    endgenerate
    always @(posedge clk) begin
        f_held_q <= rec_valid && !rec_ready;
        f_after_sweep <= !dp_rst && state == ST_SWEEP && !moving && state_next == ST_IDLE;
        if (dp_rst || state == ST_PHASE) begin
            f_visited <= {N{1'b0}};
            f_kept <= {N{1'b0}};
            f_out <= {N{1'b0}};
            f_recorded <= {N{1'b0}};
        end else begin
            if (tail_en && index < N_SLOTS)
                f_visited[k] <= 1'b1;
            if (stage0)
                f_kept[k] <= 1'b1;
            if (tail_out)
                f_out[t2_slot] <= 1'b1;
            if (f_new_record && f_rec_slot < N)
                f_recorded[f_rec_slot] <= 1'b1;
        end
    end

    always @* if (f_past_valid) begin
        if (tail_out)
            assert (f_kept[t2_slot] && !f_out[t2_slot]);
        if (f_new_record)
            assert (f_rec_slot < N && f_out[f_rec_slot] && !f_recorded[f_rec_slot]);
        if (f_after_sweep)
            assert (&f_visited && f_out == f_kept && f_offered == f_reported);
        // What k-induction needs: the sweep's shadows against the index and the tail's tags.
        if (f_new_record)
            assert (state == ST_SWEEP || f_after_sweep);
        // T1 registered its slot's record: the record T2 offers names that slot.
        if (t2_live)
            assert (t2_record[REC_SLOT_LSB +: REC_SLOT_W] == t2_slot);  // (zero-extended)
    end
    generate
        for (f_j = 0; f_j <= F_LAST; f_j = f_j + 1) begin : f_position
            always @* if (f_past_valid) begin
                if ((state != ST_SWEEP && state != ST_MERGE) || moving)
                    assert (!f_live[f_j]);
                if (f_live[f_j])
                    assert (index >= f_j + 1 && index - f_j - 1 < N && f_slot[f_j] == index - f_j - 1);
            end
        end
        for (f_s = 0; f_s < N; f_s = f_s + 1) begin : f_sweep_slot
            always @* if (f_past_valid && f_sweeping && !moving) begin
                assert (f_visited[f_s] == (f_s < index));
                assert (f_visited[f_s] || !f_kept[f_s]);
                assert (f_kept[f_s] || !f_out[f_s]);
                assert (!f_visited[f_s] || f_kept[f_s] || !valid[f_s]);
                assert (!f_kept[f_s] || f_out[f_s] || valid[f_s]);
                assert (f_offered[f_s] == (f_out[f_s] && f_reported[f_s]));
                if (index > f_s + F_LAST + 1)
                    assert (f_out[f_s] == f_kept[f_s]);
            end
            for (f_j = 0; f_j <= F_LAST; f_j = f_j + 1) begin : f_in_tail
                always @* if (f_past_valid && f_sweeping && !moving && index == f_s + f_j + 1)
                    assert (!f_out[f_s] && f_kept[f_s] == f_live[f_j]);
            end
        end
    endgenerate
