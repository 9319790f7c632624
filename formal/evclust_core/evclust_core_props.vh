// Formal properties of evclust_core's stream ports, included in its body under `ifdef FORMAL
// (SymbiYosys: formal/evclust_core/evclust_core.sby, `make formal`). Inputs are free: any event
// stream, any back-pressure, any configuration, resets and clears at any time. Proved by
// k-induction for every reachable state:
//  - no event is accepted during a reset or a clear;
//  - a record on offer holds, data and all, until it is taken (none dropped or overwritten
//    under back-pressure);
//  - every accepted event gives exactly one trace pulse: the events accepted and not yet
//    traced are exactly those in stage A, in stage B and on the trace port, so none is lost or
//    traced twice (a reset or clear discards those in flight, as documented).

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
