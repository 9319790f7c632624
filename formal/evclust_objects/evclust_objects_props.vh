// Formal properties of evclust_objects's stream ports, included in its body under `ifdef FORMAL
// (SymbiYosys: formal/evclust_objects/evclust_objects.sby, `make formal`). The record and step
// ports are driven as evclust_core is proved to drive them (evclust_core_props.vh): a record and
// a step's end hold until taken, never together, at most N records a step. Every other input is
// free: any back-pressure on both outputs, resets and clears at any time. Proved by k-induction:
//  - an object record on offer holds, data and all, until it is taken;
//  - a cluster record passed on holds, data and all, until the consumer takes it, and the unit
//    takes a record from the core exactly when the consumer takes it (none dropped, duplicated
//    or held back from the consumer);
//  - the unit keeps every record of the step it collects (m counts them, at most N), and takes
//    neither a record nor a step's end while it works on a step.

    reg f_past_valid = 1'b0;
    always @(posedge clk)
        f_past_valid <= 1'b1;
    always @* if (!f_past_valid) assume (rst);

    // The core's side.
    always @(posedge clk) if (f_past_valid && !$past(rst || clear) && $past(rec_valid && !rec_ready))
        assume (rec_valid && rec_data == $past(rec_data));
    always @(posedge clk) if (f_past_valid && !$past(rst || clear) && $past(step_valid && !step_ready))
        assume (step_valid && step_t == $past(step_t));
    always @* assume (!(step_valid && rec_valid));
    reg [M_W:0] f_recs;  // records taken since the last step's end
    always @(posedge clk)
        if (rst || clear || take_step)
            f_recs <= {(M_W + 1){1'b0}};
        else if (take_rec)
            f_recs <= f_recs + 1'b1;
    always @* assume (!rec_valid || f_recs < N);

    // Object records.
    always @(posedge clk) if (f_past_valid && !$past(rst || clear) && $past(obj_valid && !obj_ready))
        assert (obj_valid && obj_data == $past(obj_data));
    // Cluster records passed on.
    always @(posedge clk) if (f_past_valid && !$past(rst || clear) && $past(out_rec_valid && !out_rec_ready))
        assert (out_rec_valid && out_rec_data == $past(out_rec_data));
    always @* assert ((rec_valid && rec_ready) == (out_rec_valid && out_rec_ready));
    // The step's records, all kept; nothing taken while the unit works.
    always @* if (f_past_valid && !rst) begin
        assert ({1'b0, m} <= N);
        if (collecting)
            assert ({1'b0, m} == f_recs);
        else
            assert (f_recs == {(M_W + 1){1'b0}} && !rec_ready && !step_ready);
    end
