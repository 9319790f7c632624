// Formal properties of evclust_regs's AXI4-Lite slave, included in its body under `ifdef FORMAL
// (SymbiYosys: formal/evclust_regs/evclust_regs.sby, `make formal`). The master is any that keeps
// the AXI rules (assumed); the core's side (idle, count_inc) is free. Proved by k-induction for
// every reachable state, not only to a depth:
//  - B and R hold while not taken, R's data with them, responses always OKAY;
//  - no response without its request, and at most one write and one read in flight beyond the
//    response on offer, so none is lost or duplicated;
//  - bounded liveness: a request the master keeps offering is answered within a few cycles of
//    the master being ready for it;
//  - nothing is offered or accepted in the cycle after a reset.

    reg f_past_valid = 1'b0;
    always @(posedge clk)
        f_past_valid <= 1'b1;
    always @* if (!f_past_valid) assume (rst);

    // The master: a valid stays up, its payload unchanged, until it is taken.
    always @(posedge clk) if (f_past_valid && !$past(rst)) begin
        if ($past(s_axil_awvalid && !s_axil_awready)) assume (s_axil_awvalid && s_axil_awaddr == $past(s_axil_awaddr));
        if ($past(s_axil_wvalid && !s_axil_wready)) assume (s_axil_wvalid && s_axil_wdata == $past(s_axil_wdata) && s_axil_wstrb == $past(s_axil_wstrb));
        if ($past(s_axil_arvalid && !s_axil_arready)) assume (s_axil_arvalid && s_axil_araddr == $past(s_axil_araddr));
    end

    // Requests taken minus responses given.
    reg [2:0] f_aw_open, f_w_open, f_ar_open;
    wire f_b = s_axil_bvalid && s_axil_bready;
    wire f_r = s_axil_rvalid && s_axil_rready;
    always @(posedge clk) begin
        if (rst) begin
            f_aw_open <= 3'd0;
            f_w_open <= 3'd0;
            f_ar_open <= 3'd0;
        end else begin
            f_aw_open <= f_aw_open + {2'd0, s_axil_awvalid && s_axil_awready} - {2'd0, f_b};
            f_w_open <= f_w_open + {2'd0, s_axil_wvalid && s_axil_wready} - {2'd0, f_b};
            f_ar_open <= f_ar_open + {2'd0, s_axil_arvalid && s_axil_arready} - {2'd0, f_r};
        end
    end

    // Cycles a request has waited while the master could take its response.
    reg [3:0] f_w_wait, f_r_wait;
    wire f_w_asked = (f_aw_open != 3'd0 || s_axil_awvalid) && (f_w_open != 3'd0 || s_axil_wvalid) && !(s_axil_bvalid && !s_axil_bready);
    wire f_r_asked = (f_ar_open != 3'd0 || s_axil_arvalid) && !(s_axil_rvalid && !s_axil_rready);
    always @(posedge clk) begin
        if (rst || !f_w_asked || f_b)
            f_w_wait <= 4'd0;
        else if (f_w_wait != 4'hf)
            f_w_wait <= f_w_wait + 4'd1;
        if (rst || !f_r_asked || f_r)
            f_r_wait <= 4'd0;
        else if (f_r_wait != 4'hf)
            f_r_wait <= f_r_wait + 4'd1;
    end

    always @(posedge clk) if (f_past_valid && !$past(rst) && !rst) begin
        if ($past(s_axil_bvalid && !s_axil_bready)) assert (s_axil_bvalid);
        if ($past(s_axil_rvalid && !s_axil_rready)) assert (s_axil_rvalid && s_axil_rdata == $past(s_axil_rdata));
    end
    always @(posedge clk) if (f_past_valid && $past(rst))
        assert (!s_axil_awready && !s_axil_wready && !s_axil_arready && !s_axil_bvalid && !s_axil_rvalid && !clear);
    always @* if (f_past_valid && !rst) begin
        assert (s_axil_bresp == 2'b00 && s_axil_rresp == 2'b00);
        assert (!s_axil_bvalid || (f_aw_open != 3'd0 && f_w_open != 3'd0));  // no response without its request
        assert (!s_axil_rvalid || f_ar_open != 3'd0);
        assert (f_w_wait <= 4'd4 && f_r_wait <= 4'd3);
        // What is in flight is what the slave holds (the invariants the induction needs).
        assert (f_aw_open == {2'd0, aw_held} + {2'd0, s_axil_bvalid});
        assert (f_w_open == {2'd0, w_held} + {2'd0, s_axil_bvalid});
        assert (f_ar_open == {2'd0, s_axil_rvalid});
        assert (!(s_axil_awready && aw_held) && !(s_axil_wready && w_held) && !(s_axil_arready && s_axil_rvalid));
    end
