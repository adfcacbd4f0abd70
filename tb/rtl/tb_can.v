// Icarus self-checks for rtl/can_top: two nodes on a wired-AND bus.
//  0. can_top #(.ACK_LEVEL(1)) polled like the thesis's PIO driver: a strobe
//     held for 60 cycles is served once and wb_ack_o stays high until it
//     falls; the default pulse ack is one cycle long.
//  1. BasicCAN, thesis frame (seed 000): node 0 sends ID 0x529, DLC 1,
//     data 0x51 (TX buffer A5 21 51); tx_o is checked bit by bit against the expected stuffed
//     frame, node 1 acknowledges and receives it (RX buffer, RI, TCS, TI).
//  2. PeliCAN self test (STM) + self reception request (SRR), node 1 in
//     reset mode: the frame goes out unacknowledged and comes back in RXFIFO.
//  3. PeliCAN arbitration: both nodes start together; the lower ID wins,
//     the loser captures ALC, receives the winner, then retransmits.
//  4. PeliCAN, lone node without self test: ACK errors raise TEC by 8 up
//     to 128 (error passive, EPI), then stay (rule 3 exception 1).
//  5. Bus stuck recessive: bit error at SOF and at every bit of the active
//     error flag (+8 each); the flag after the error that reaches TEC = 128
//     is still active (exactly 17 dominant bits sent), then passive flags;
//     bus-off at TEC > 255 (RM set, TXERR = 127, bus_off_on low), recovery after 128 x 11 recessive bits.
//  6. Sleep: MOD.SM accepted when idle, bus activity wakes the node (WUI).
//  7. PeliCAN single acceptance filter (ID + RTR + data byte 1), extended
//     8-byte frames in the RX FIFO, FIFO overrun (DOS, DOI, RMC), RRB/RBSA.
//  8. A dominant glitch in node 1's data field: node 1 (transmitter) sees a
//     bit error (ECC direction TX, TEC + 8), node 0 (receiver) an error with
//     ECC direction RX; the retransmission succeeds (TEC 8 - 1 = 7); then a
//     dominant first intermission bit: overload frame, counters unchanged.
//  9. Listen only + single shot: node 0 in listen-only mode never drives the
//     bus (no ACK), node 1's single-shot frame fails once with an ACK error
//     (TEC + 8), is not repeated (TBS = 1, TCS = 0); node 0's RXERR frozen.
// 10. PeliCAN dual filter, standard frames: filter 1 = ID + RTR + data
//     byte 1 (nibbles in ACR1/ACR3), filter 2 = ID + RTR; two accepted,
//     two rejected.
// 11. BasicCAN ACR/AMR filter on ID.10..3; an extended frame whose base ID
//     matches is acknowledged but not stored (extended frame passive), the
//     standard frame with that ID is.
// 12. Triple sampling (BTR1.SAM = 1) on both nodes, SJW 1: a frame goes
//     through with node 1 still on its drifting clock.
// Node 1 runs on a clk_i 0.03 % off node 0's, so it resynchronises.
// Exits with $fatal on the first failure; prints "PASS" at the end.
`timescale 1ns/1ps
module tb_can;
    reg wb_clk = 0, clk0 = 0, clk1 = 0, wb_rst = 1;
    always #10 wb_clk = ~wb_clk;              // 50 MHz host clock
    always #20.833 clk0 = ~clk0;              // 24 MHz CAN clock node 0
    always #20.840 clk1 = ~clk1;              // node 1: slightly off, resyncs

    reg  [7:0] adr [0:1];
    reg  [7:0] dwr [0:1];
    reg        cyc [0:1];
    reg        we  [0:1];
    wire [7:0] dout0, dout1;
    wire       ack0, ack1, tx0, tx1, bo0, bo1, irq0, irq1, ck0, ck1;
    reg        force_rec = 0;             // fault injector: bus stuck recessive
    reg        force_dom = 0;             // fault injector: bus stuck dominant
    wire       bus = ((tx0 & tx1) | force_rec) & ~force_dom;

    can_top n0 (.wb_clk_i(wb_clk), .wb_rst_i(wb_rst), .wb_dat_i(dwr[0]), .wb_dat_o(dout0),
        .wb_cyc_i(cyc[0]), .wb_stb_i(cyc[0]), .wb_we_i(we[0]), .wb_adr_i(adr[0]), .wb_ack_o(ack0),
        .clk_i(clk0), .rx_i(bus), .tx_o(tx0), .bus_off_on(bo0), .irq_on(irq0), .clkout_o(ck0));
    can_top n1 (.wb_clk_i(wb_clk), .wb_rst_i(wb_rst), .wb_dat_i(dwr[1]), .wb_dat_o(dout1),
        .wb_cyc_i(cyc[1]), .wb_stb_i(cyc[1]), .wb_we_i(we[1]), .wb_adr_i(adr[1]), .wb_ack_o(ack1),
        .clk_i(clk1), .rx_i(bus), .tx_o(tx1), .bus_off_on(bo1), .irq_on(irq1), .clkout_o(ck1));

    // node 2: level-ack variant, off the bus, driven by a PIO-style master
    reg        cyc2 = 0, we2 = 0;
    reg  [7:0] adr2 = 0, dwr2 = 0;
    wire [7:0] dout2;
    wire       ack2, tx2, bo2, irq2, ck2;
    can_top #(.ACK_LEVEL(1)) n2 (.wb_clk_i(wb_clk), .wb_rst_i(wb_rst), .wb_dat_i(dwr2), .wb_dat_o(dout2),
        .wb_cyc_i(cyc2), .wb_stb_i(cyc2), .wb_we_i(we2), .wb_adr_i(adr2), .wb_ack_o(ack2),
        .clk_i(clk0), .rx_i(1'b1), .tx_o(tx2), .bus_off_on(bo2), .irq_on(irq2), .clkout_o(ck2));
    integer n2_acc = 0;
    always @(posedge clk0) if (n2.u_cdc.acc_stb) n2_acc = n2_acc + 1;
    // hold cyc/stb for `hold` cycles, polling ack every 5 cycles like a GPIO read
    task pio2(input w, input [7:0] a, input [7:0] d, output [7:0] qq);
        integer c, seen;
        begin
            @(posedge wb_clk); #1;
            adr2 = a; dwr2 = d; we2 = w; cyc2 = 1; n2_acc = 0; seen = 0;
            for (c = 0; c < 60; c = c + 1) begin
                @(posedge wb_clk);
                if (c % 5 == 4 && ack2) seen = seen + 1;
            end
            qq = dout2;
            if (seen == 0) fail("level ack never seen by the polling master");
            if (!ack2) fail("level ack must stay high while the strobe is held");
            if (n2_acc != 1) begin $display("FAIL: level ack: %0d accesses for one strobe", n2_acc); $fatal(1); end
            #1; cyc2 = 0; we2 = 0;
            #1; if (ack2) fail("level ack must fall with the strobe");
        end
    endtask
    integer max_lat = 0;
    // access length seen by a Wishbone monitor: wb_clk_i cycles with
    // cyc&stb high, the ack cycle included (node 0)
    integer acc_cyc = 0, lat_min = 1000, lat_max = 0;
    always @(posedge wb_clk) begin
        if (cyc[0] && ack0) begin
            if (acc_cyc + 1 < lat_min) lat_min = acc_cyc + 1;
            if (acc_cyc + 1 > lat_max) lat_max = acc_cyc + 1;
            acc_cyc <= 0;
        end else if (cyc[0]) acc_cyc <= acc_cyc + 1;
    end
    task fail(input [8*64-1:0] msg);
        begin $display("FAIL: %0s (t=%0t)", msg, $time); $fatal(1); end
    endtask

    // step 2: a self reception changes SR in one step (TCS never without RBS)
    reg self_chk = 0;
    always @(posedge clk0)
        if (self_chk && n0.u_regs.sr[3] && !n0.u_regs.sr[0]) fail("SR: TCS = 1 before RBS after a self reception");

    // one Wishbone classic access; checks the ack is a single-cycle pulse
    task automatic wb(input integer n, input w, input [7:0] a, input [7:0] d, output [7:0] q);
        integer t;
        begin
            @(posedge wb_clk); #1;
            adr[n] = a; dwr[n] = d; we[n] = w; cyc[n] = 1;
            t = 0;
            @(posedge wb_clk);
            while (!(n == 0 ? ack0 : ack1)) begin
                #1; t = t + 1;
                if (t > 200) fail("no wb_ack_o within 200 cycles");
                @(posedge wb_clk);
            end
            q = (n == 0) ? dout0 : dout1;
            if (t + 1 > max_lat) max_lat = t + 1;
            #1; cyc[n] = 0; we[n] = 0;
            @(posedge wb_clk);
            if ((n == 0 ? ack0 : ack1)) fail("wb_ack_o longer than one cycle");
        end
    endtask
    reg [7:0] tmp;
    task automatic wr(input integer n, input [7:0] a, input [7:0] d); reg [7:0] t; wb(n, 1, a, d, t); endtask
    task automatic rd(input integer n, input [7:0] a, output [7:0] q); wb(n, 0, a, 8'h00, q); endtask
    task expect_reg(input integer n, input [7:0] a, input [7:0] v, input [8*40-1:0] what);
        reg [7:0] q;
        begin
            rd(n, a, q);
            if (q !== v) begin
                $display("FAIL: node %0d %0s: addr %0d read %02h, expected %02h", n, what, a, q, v);
                $fatal(1);
            end
        end
    endtask

    // ---- expected frame bits (reference: CAN 2.0B framing, not the RTL) ----
    reg [0:199] exp_bits;    // stuffed SOF..CRC, then CRC delim, ACK, ACK delim, EOF
    integer exp_len;
    function [14:0] crc_add(input [14:0] c, input b);
        crc_add = {c[13:0], 1'b0} ^ ((b ^ c[14]) ? 15'h4599 : 15'h0);
    endfunction
    task build_std(input [10:0] id, input rtr, input [3:0] dlc, input [63:0] data, input ack);
        reg [0:127] raw; integer n, i, run; reg last; reg [14:0] c; integer nd;
        begin
            nd = (rtr || dlc == 0) ? 0 : (dlc > 8 ? 8 : dlc);
            n = 0;
            raw[n] = 0; n = n + 1;
            for (i = 10; i >= 0; i = i - 1) begin raw[n] = id[i]; n = n + 1; end
            raw[n] = rtr; n = n + 1; raw[n] = 0; n = n + 1; raw[n] = 0; n = n + 1;
            for (i = 3; i >= 0; i = i - 1) begin raw[n] = dlc[i]; n = n + 1; end
            for (i = 0; i < nd * 8; i = i + 1) begin raw[n] = data[63 - i]; n = n + 1; end
            c = 0;
            for (i = 0; i < n; i = i + 1) c = crc_add(c, raw[i]);
            for (i = 14; i >= 0; i = i - 1) begin raw[n] = c[i]; n = n + 1; end
            exp_len = 0; run = 0; last = 1'bx;
            for (i = 0; i < n; i = i + 1) begin
                exp_bits[exp_len] = raw[i]; exp_len = exp_len + 1;
                if (raw[i] === last) run = run + 1; else begin run = 1; last = raw[i]; end
                if (run == 5) begin
                    exp_bits[exp_len] = ~last; exp_len = exp_len + 1; last = ~last; run = 1;
                end
            end
            exp_bits[exp_len] = 1; exp_len = exp_len + 1;            // CRC delimiter
            exp_bits[exp_len] = ack ? 1'b0 : 1'b1; exp_len = exp_len + 1; // ACK slot (bus)
            for (i = 0; i < 8; i = i + 1) begin exp_bits[exp_len] = 1; exp_len = exp_len + 1; end
        end
    endtask

    // capture node 0's sampled bus bits and its own tx_o at each sample point
    reg [0:255] cap_bus, cap_tx;
    integer cap_n = 0;
    reg capturing = 0;
    always @(posedge clk0) begin
        if (n0.u_btl.sample && (capturing || (cap_n == 0 && n0.u_btl.rx_bit == 1'b0 && capturing === 1'b0 && arm))) begin
            if (cap_n < 256) begin cap_bus[cap_n] <= n0.u_btl.rx_bit; cap_tx[cap_n] <= tx0; end
            cap_n <= cap_n + 1;
            capturing <= 1;
        end
    end
    reg arm = 0;
    task start_capture; begin cap_n = 0; capturing = 0; arm = 1; end endtask

    task check_frame(input check_tx, input [8*32-1:0] what);
        integer i;
        begin
            wait (cap_n >= exp_len);
            arm = 0; capturing = 0;
            for (i = 0; i < exp_len; i = i + 1) begin
                if (cap_bus[i] !== exp_bits[i]) begin
                    $display("FAIL: %0s: bus bit %0d is %b, expected %b", what, i, cap_bus[i], exp_bits[i]);
                    $fatal(1);
                end
                // tx_o equals the frame except the ACK slot, which the sender leaves recessive
                if (check_tx && cap_tx[i] !== ((i == exp_len - 9) ? 1'b1 : exp_bits[i])) begin
                    $display("FAIL: %0s: tx_o bit %0d is %b", what, i, cap_tx[i]);
                    $fatal(1);
                end
            end
            $display("  %0s: %0d bits on the bus as expected", what, exp_len);
        end
    endtask

    task wait_bits(input integer nbits);
        integer k;
        begin
            for (k = 0; k < nbits; k = k + 1) @(posedge n0.u_btl.sample);
        end
    endtask

    // +trace: log protocol events of both nodes
    always @(posedge clk0) if ($test$plusargs("trace")) begin
        if (n0.u_bsp.alc_evt) $display("%0t n0 arbitration lost at %0d", $time, n0.u_bsp.alc_val);
        if (n0.u_bsp.err_evt) $display("%0t n0 bus error ecc=%02h", $time, n0.u_bsp.ecc_val);
        if (n0.u_bsp.tx_done) $display("%0t n0 tx done", $time);
        if (n0.u_bsp.rx_valid) $display("%0t n0 rx valid id=%h", $time, n0.u_bsp.rx_id);
    end
    always @(posedge clk1) if ($test$plusargs("trace")) begin
        if (n1.u_bsp.alc_evt) $display("%0t n1 arbitration lost at %0d", $time, n1.u_bsp.alc_val);
        if (n1.u_bsp.err_evt) $display("%0t n1 bus error ecc=%02h", $time, n1.u_bsp.ecc_val);
        if (n1.u_bsp.tx_done) $display("%0t n1 tx done", $time);
        if (n1.u_bsp.rx_valid) $display("%0t n1 rx valid id=%h", $time, n1.u_bsp.rx_id);
    end

    // length of node 0's first run of dominant tx_o bits (test 5)
    integer dom_run = 0, dom_first = 0;
    reg count_dom = 0;
    always @(posedge clk0) if (count_dom && n0.u_btl.sample && dom_first == 0) begin
        if (!tx0) dom_run <= dom_run + 1;
        else if (dom_run != 0) dom_first <= dom_run;
    end

    // node 1 sends one PeliCAN frame (frame info, 4 ID bytes, n data bytes)
    // and the task waits until node 1 reports it complete (SR.TCS)
    task send1(input [7:0] fi, input [7:0] i1, input [7:0] i2, input [7:0] i3, input [7:0] i4,
               input [63:0] data, input integer n);
        integer j, base, t; reg [7:0] st;
        begin
            wr(1, 8'd16, fi); wr(1, 8'd17, i1); wr(1, 8'd18, i2);
            base = 19;
            if (fi[7]) begin wr(1, 8'd19, i3); wr(1, 8'd20, i4); base = 21; end
            for (j = 0; j < n; j = j + 1) wr(1, base + j, data[63 - 8 * j -: 8]);
            wr(1, 8'd1, 8'h01);
            t = 0; st = 0;
            while (st[3] !== 1'b1) begin
                rd(1, 8'd2, st); t = t + 1;
                if (t > 2000) fail("node 1 transmission never completed");
            end
            wait_bits(4);
        end
    endtask

    reg [7:0] q, rbsa0, rec0;
    // rising CLKOUT edges of node 0 during n clk_i cycles
    integer ck_edges = 0; reg ck_count = 0;
    always @(posedge ck0) if (ck_count) ck_edges = ck_edges + 1;
    task count_ck(input integer n, output integer e);
        begin
            @(posedge clk0); #1; ck_edges = 0; ck_count = 1;
            repeat (n) @(posedge clk0);
            #1; ck_count = 0; e = ck_edges;
        end
    endtask
    reg tx0_dom = 0, watch_tx0 = 0;
    always @(posedge clk0) if (watch_tx0 && !tx0) tx0_dom <= 1;
    // glitch injector (test 8): one dominant bit on the bus, centred on
    // node 1's next sample point after the chosen position
    integer glitch_at = 0, ovl_seen = 0;
    always @(posedge clk1) begin
        if (n1.u_btl.sample && glitch_at != 0) begin
            #1;
            if ($test$plusargs("trace")) $display("%0t glitch? st=%0d cnt=%0d", $time, n1.u_bsp.st, n1.u_bsp.cnt);
            if ((glitch_at == 1 && n1.u_bsp.st == 5'd12 && n1.u_bsp.cnt == 6'd2) ||
                (glitch_at == 2 && n1.u_bsp.st == 5'd18 && n1.u_bsp.cnt == 6'd0)) begin
                glitch_at = 0;
                repeat (20) @(posedge clk1);
                force_dom = 1;
                repeat (40) @(posedge clk1);
                force_dom = 0;
            end
        end
        if (n1.u_bsp.st == 5'd23) ovl_seen = 1;
    end
    integer k;
    initial begin
        cyc[0] = 0; cyc[1] = 0; we[0] = 0; we[1] = 0; adr[0] = 0; adr[1] = 0; dwr[0] = 0; dwr[1] = 0;
        repeat (3) @(posedge wb_clk);
        #1 wb_rst = 0;

        // ================= 0. level ack for GPIO-polled masters =================
        $display("0. ACK_LEVEL = 1: one access per held strobe, ack until the strobe falls");
        pio2(1'b1, 8'd4, 8'h5A, q);          // reset mode after reset: ACR writable
        pio2(1'b0, 8'd4, 8'h00, q);
        if (q !== 8'h5A) fail("level-ack node: ACR read back");

        // ================= 1. BasicCAN thesis frame =================
        $display("1. BasicCAN: thesis frame A5 21 51, node 1 acknowledges and receives");
        for (k = 0; k < 2; k = k + 1) begin
            expect_reg(k, 8'd0, 8'h21, "CR after reset");
            // the first access also waits for the clk_i domain to leave reset
            if (k == 0) begin $display("  first access after reset: %0d cycles", lat_max); lat_max = 0; end
            expect_reg(k, 8'd2, 8'h0C, "SR after reset (BasicCAN: RS = TS = 0)");
            expect_reg(k, 8'd3, 8'hE0, "IR after reset");
            wr(k, 8'd0, 8'h01);            // CR: reset request
            wr(k, 8'd4, 8'hFF);            // ACR
            wr(k, 8'd5, 8'hFF);            // AMR: accept all
            wr(k, 8'd6, 8'h41);            // BTR0: SJW 2, BRP 1 -> tq = 4 clk
            wr(k, 8'd7, 8'h25);            // BTR1: TSEG1 6, TSEG2 3 -> 10 tq
            wr(k, 8'd8, 8'h1A);            // OCR
            wr(k, 8'd31, 8'h07);           // CDR: BasicCAN, CLKOUT fosc
            expect_reg(k, 8'd6, 8'h41, "BTR0 in reset mode");
            wr(k, 8'd0, 8'h06);            // CR: operating, RIE + TIE
            expect_reg(k, 8'd6, 8'hFF, "BTR0 in operating mode");
        end
        wait_bits(12);                      // bus integration (11 recessive bits)
        wr(0, 8'd10, 8'hA5);
        wr(0, 8'd11, 8'h21);
        wr(0, 8'd12, 8'h51);
        expect_reg(0, 8'd10, 8'hA5, "TX buffer readback");
        build_std(11'b10100101001, 1'b0, 4'd1, {8'h51, 56'd0}, 1'b1);
        if (exp_bits[0:19] !== 20'b0_10100101001_0_0_0_0_0_1_0_1)
            fail("reference frame head differs from the thesis");
        start_capture;
        wr(0, 8'd1, 8'h01);                 // CMR: transmission request
        check_frame(1'b1, "thesis frame");
        wait_bits(4);
        expect_reg(1, 8'd2, 8'h01 | 8'h0C, "node 1 SR (RBS, TBS, TCS)");
        if (irq1 !== 1'b0) fail("node 1 irq_on not asserted");
        expect_reg(1, 8'd3, 8'hE1, "node 1 IR (RI)");
        expect_reg(1, 8'd20, 8'hA5, "node 1 RX byte 0");
        expect_reg(1, 8'd21, 8'h21, "node 1 RX byte 1");
        expect_reg(1, 8'd22, 8'h51, "node 1 RX byte 2");
        wr(1, 8'd1, 8'h04);                 // RRB
        expect_reg(1, 8'd2, 8'h0C, "node 1 SR after RRB");
        expect_reg(0, 8'd2, 8'h0C, "node 0 SR (TBS, TCS)");
        expect_reg(0, 8'd3, 8'hE2, "node 0 IR (TI)");
        if (irq0 !== 1'b1) fail("node 0 irq_on not released by IR read");
        $display("  Wishbone ack latency: %0d wb_clk_i cycles (max so far)", max_lat);

        // ================= 2. PeliCAN self test + self reception =================
        $display("2. PeliCAN self test (STM) + SRR on a lone node");
        for (k = 0; k < 2; k = k + 1) begin
            wr(k, 8'd0, 8'h01);             // reset mode (BasicCAN CR)
            wr(k, 8'd31, 8'h87);            // CDR: PeliCAN
            wr(k, 8'd0, 8'h05);             // MOD: RM + STM
            for (q = 16; q < 20; q = q + 1) wr(k, q, 8'h00);   // ACR0-3
            for (q = 20; q < 24; q = q + 1) wr(k, q, 8'hFF);   // AMR0-3: accept all
            wr(k, 8'd4, 8'hFF);             // IER: all
        end
        expect_reg(0, 8'd0, 8'h05, "MOD");
        count_ck(60, k);
        if (k != 60) begin $display("FAIL: CLKOUT fosc: %0d edges in 60 clk", k); $fatal(1); end
        wr(0, 8'd31, 8'h82);                // CLKOUT fosc/6
        count_ck(60, k);
        if (k < 9 || k > 11) begin $display("FAIL: CLKOUT fosc/6: %0d edges in 60 clk", k); $fatal(1); end
        wr(0, 8'd31, 8'h88);                // clock off
        count_ck(60, k);
        if (k != 0) fail("CLKOUT must stop with CDR.3");
        wr(0, 8'd31, 8'h87);
        expect_reg(0, 8'd13, 8'd96, "EWLR reset value");
        wr(0, 8'd0, 8'h04);                 // node 0: operating, self test
        wait_bits(12);
        wr(0, 8'd16, 8'h01);                // frame info: std, DLC 1
        wr(0, 8'd17, 8'hA5);
        wr(0, 8'd18, 8'h20);
        wr(0, 8'd19, 8'h51);
        expect_reg(0, 8'd97, 8'hA5, "TX RAM readback");
        build_std(11'b10100101001, 1'b0, 4'd1, {8'h51, 56'd0}, 1'b0);
        start_capture;
        wr(0, 8'd1, 8'h10);                 // CMR: self reception request
        self_chk = 1;
        check_frame(1'b1, "self-test frame");
        wait_bits(4);
        expect_reg(0, 8'd29, 8'd1, "RMC");
        expect_reg(0, 8'd16, 8'h01, "RX frame info");
        expect_reg(0, 8'd17, 8'hA5, "RX ID1");
        expect_reg(0, 8'd18, 8'h20, "RX ID2");
        expect_reg(0, 8'd19, 8'h51, "RX data 1");
        expect_reg(0, 8'd32, 8'h01, "RXFIFO RAM byte 0");
        expect_reg(0, 8'd3, 8'h03, "IR (RI, TI)");
        expect_reg(0, 8'd3, 8'h01, "IR after read (RI stays)");
        expect_reg(0, 8'd15, 8'd0, "TXERR");
        self_chk = 0;
        wr(0, 8'd1, 8'h04);                 // RRB
        expect_reg(0, 8'd29, 8'd0, "RMC after RRB");
        expect_reg(0, 8'd30, 8'd4, "RBSA after RRB");

        // ================= 3. arbitration =================
        $display("3. PeliCAN arbitration: ID 0x123 against ID 0x124");
        wr(0, 8'd0, 8'h01);                 // node 0 back to reset, normal mode
        wr(0, 8'd0, 8'h00);
        wr(1, 8'd0, 8'h00);
        wait_bits(14);
        expect_reg(0, 8'd3, 8'h00, "IR clear before arbitration");
        rd(0, 8'd11, q); rd(1, 8'd11, q);   // arm ALC capture
        // node 0: ID 0x124 (loses at ID.20 = bit 8), node 1: ID 0x123
        wr(0, 8'd16, 8'h02); wr(0, 8'd17, 8'h24); wr(0, 8'd18, 8'h80); wr(0, 8'd19, 8'hAA); wr(0, 8'd20, 8'hBB);
        wr(1, 8'd16, 8'h01); wr(1, 8'd17, 8'h24); wr(1, 8'd18, 8'h60); wr(1, 8'd19, 8'hCC);
        // Both requests must be pending when the bus becomes free: hold the
        // bus dominant (stuff error, error flags, both nodes wait for a
        // recessive bus), queue both, release: both start after the error
        // delimiter and intermission, in the same bit.
        force_dom = 1;
        wait_bits(10);
        fork
            wr(0, 8'd1, 8'h01);
            wr(1, 8'd1, 8'h01);
        join
        wait_bits(4);
        force_dom = 0;
        wait_bits(70);
        expect_reg(0, 8'd11, 8'd8, "node 0 ALC (lost at ID.20, bit 8)");
        expect_reg(0, 8'd29, 8'd1, "node 0 RMC (received the winner)");
        expect_reg(0, 8'd17, 8'h24, "node 0 RX ID1");
        expect_reg(0, 8'd18, 8'h60, "node 0 RX ID2");
        expect_reg(0, 8'd19, 8'hCC, "node 0 RX data");
        wait_bits(80);
        expect_reg(1, 8'd29, 8'd1, "node 1 RMC (received the retransmission)");
        expect_reg(1, 8'd16, 8'h02, "node 1 RX frame info");
        expect_reg(1, 8'd18, 8'h80, "node 1 RX ID2");
        expect_reg(1, 8'd20, 8'hBB, "node 1 RX data 2");
        expect_reg(0, 8'd2, 8'h0D, "node 0 SR: RBS TBS TCS");

        // ================= 4. ACK errors on a lone node =================
        $display("4. ACK errors: TEC +8 per frame up to error passive");
        wr(1, 8'd0, 8'h01);                 // node 1 leaves (reset mode)
        wr(0, 8'd4, 8'h20);                 // IER: EPI only
        rd(0, 8'd3, q);
        rd(0, 8'd12, q);                    // arm ECC
        wr(0, 8'd1, 8'h01);                 // TR
        wait_bits(16 * 72 + 300);
        expect_reg(0, 8'd15, 8'd128, "TXERR after ACK errors");
        expect_reg(0, 8'd12, 8'hD9, "ECC: other error, TX, ACK slot");
        rd(0, 8'd2, q);
        if (q[6] !== 1'b1 || q[7] !== 1'b0) fail("SR: ES set, BS clear expected");
        expect_reg(0, 8'd3, 8'h20, "IR: EPI");
        if (bo0 !== 1'b1) fail("bus_off_on must stay high");
        wr(0, 8'd1, 8'h02);                 // abort: no retransmission after the next error
        wait_bits(100);
        rd(0, 8'd2, q);
        if (q[2] !== 1'b1) fail("TBS after abort");

        // ================= 5. bus stuck recessive: bus-off and recovery =================
        $display("5. bus stuck recessive: error flags, error passive, bus-off, recovery");
        wr(0, 8'd0, 8'h01);                 // reset mode
        wr(0, 8'd15, 8'd0);                 // TXERR = 0
        wr(0, 8'd4, 8'h04);                 // IER: EI
        wr(0, 8'd0, 8'h00);
        wait_bits(12);
        rd(0, 8'd3, q);
        rd(0, 8'd12, q);                    // arm ECC
        force_rec = 1;
        dom_run = 0; dom_first = 0; count_dom = 1;
        wr(0, 8'd1, 8'h01);                 // TR
        k = 0;
        while (bo0 !== 1'b0) begin
            @(posedge wb_clk); k = k + 1;
            if (k > 2_000_000) fail("never went bus-off");
        end
        count_dom = 0;
        // SOF + 16 active flags: the error that makes TEC 128 is still
        // signalled by an active flag (CAN 2.0B 8, note to rule 9)
        if (dom_first != 17) begin
            $display("FAIL: %0d dominant bits before the passive flag, expected 17", dom_first);
            $fatal(1);
        end
        $display("  17 dominant bits (SOF + 16 one-bit active flags) then passive flags; bus-off");
        expect_reg(0, 8'd12, 8'h03, "ECC: bit error at SOF, TX");
        expect_reg(0, 8'd15, 8'd127, "TXERR at bus-off");
        expect_reg(0, 8'd14, 8'd0, "RXERR at bus-off");
        expect_reg(0, 8'd0, 8'h01, "MOD: RM set by bus-off");
        rd(0, 8'd2, q);
        if (q[7] !== 1'b1 || q[2] !== 1'b1) fail("SR: BS and TBS expected at bus-off");
        if (irq0 !== 1'b0) fail("EI expected at bus-off");
        expect_reg(0, 8'd3, 8'h04, "IR: EI");
        force_rec = 0;
        wr(0, 8'd0, 8'h00);                 // leave reset mode: recovery starts
        wait_bits(700);
        rd(0, 8'd15, q);
        if (q == 0 || q >= 127 || bo0 !== 1'b0) fail("TXERR must count the recovery down");
        $display("  recovery under way, TXERR = %0d", q);
        k = 0;
        while (bo0 !== 1'b1) begin
            @(posedge wb_clk); k = k + 1;
            if (k > 2_000_000) fail("never recovered from bus-off");
        end
        expect_reg(0, 8'd15, 8'd0, "TXERR after recovery");
        expect_reg(0, 8'd2, 8'h04, "SR after recovery (TBS; TCS stays 0: the request was cancelled)");
        expect_reg(0, 8'd3, 8'h04, "IR: EI at bus-on");

        // ================= 6. sleep and wake-up =================
        $display("6. sleep mode, wake-up by bus activity");
        wr(0, 8'd4, 8'h10);                 // IER: WUI
        wait_bits(12);
        wr(0, 8'd0, 8'h10);                 // MOD.SM
        expect_reg(0, 8'd0, 8'h10, "MOD: sleeping");
        if (ck0 !== 1'b0) fail("CLKOUT must stop in sleep mode");
        wr(1, 8'd0, 8'h00);                 // node 1 operating, sends its frame again
        #20000;                             // (node 0 is asleep: no sample points to count)
        wr(1, 8'd1, 8'h01);
        k = 0;
        while (irq0 !== 1'b0) begin
            @(posedge wb_clk); k = k + 1;
            if (k > 200_000) fail("no wake-up interrupt");
        end
        expect_reg(0, 8'd0, 8'h00, "MOD: awake");
        expect_reg(0, 8'd3, 8'h10, "IR: WUI");

        // ================= 7. filters, extended frames, FIFO overrun =================
        $display("7. single filter, extended frames, RX FIFO overrun");
        wr(0, 8'd0, 8'h09);                 // node 0: reset mode, single filter
        wr(0, 8'd16, 8'h24); wr(0, 8'd17, 8'h60); wr(0, 8'd18, 8'h55); wr(0, 8'd19, 8'h00);
        wr(0, 8'd20, 8'h00); wr(0, 8'd21, 8'h0F); wr(0, 8'd22, 8'h00); wr(0, 8'd23, 8'hFF);
        wr(0, 8'd4, 8'h09);                 // IER: RI, DOI
        wr(0, 8'd0, 8'h08);                 // operating
        wr(1, 8'd0, 8'h01);
        wr(1, 8'd0, 8'h00);                 // node 1 re-integrates
        wait_bits(14);
        // accepted: ID 0x123, 2 bytes 55 01
        send1(8'h02, 8'h24, 8'h60, 8'h00, 8'h00, 64'h5501_0000_0000_0000, 2);
        // rejected: data byte 1 differs
        send1(8'h01, 8'h24, 8'h60, 8'h00, 8'h00, 64'h5600_0000_0000_0000, 1);
        // rejected: extended frame with another ID.28..21
        send1(8'h88, 8'h55, 8'h9A, 8'hBC, 8'hD8, 64'h0102_0304_0506_0708, 8);
        expect_reg(0, 8'd29, 8'd1, "RMC: one frame passed the filter");
        expect_reg(0, 8'd16, 8'h02, "filtered frame info");
        expect_reg(0, 8'd19, 8'h55, "filtered data 1");
        expect_reg(0, 8'd20, 8'h01, "filtered data 2");
        rd(0, 8'd30, rbsa0);
        wr(0, 8'd1, 8'h04);                 // RRB
        expect_reg(0, 8'd30, (rbsa0 + 8'd5) & 8'h3F, "RBSA after RRB (5-byte message)");
        rbsa0 = (rbsa0 + 8'd5) & 8'h3F;
        wr(0, 8'd0, 8'h09);
        for (q = 20; q < 24; q = q + 1) wr(0, q, 8'hFF);   // accept all
        wr(0, 8'd0, 8'h08);
        wait_bits(14);
        for (k = 0; k < 5; k = k + 1)
            send1(8'h88, 8'h55, 8'h9A, 8'hBC, 8'hD8, 64'h0102_0304_0506_0708 + k, 8);
        expect_reg(0, 8'd29, 8'd4, "RMC: 4 x 13 bytes fit, the 5th overruns");
        rd(0, 8'd2, q);
        if (q[1] !== 1'b1 || q[0] !== 1'b1) fail("SR: DOS and RBS expected");
        expect_reg(0, 8'd3, 8'h09, "IR: DOI, RI");
        expect_reg(0, 8'd16, 8'h88, "ext frame info");
        expect_reg(0, 8'd17, 8'h55, "ext ID1");
        expect_reg(0, 8'd18, 8'h9A, "ext ID2");
        expect_reg(0, 8'd19, 8'hBC, "ext ID3");
        expect_reg(0, 8'd20, 8'hD8, "ext ID4");
        expect_reg(0, 8'd21, 8'h01, "ext data 1");
        expect_reg(0, 8'd28, 8'h08, "ext data 8");
        wr(0, 8'd1, 8'h0C);                 // RRB + CDO
        expect_reg(0, 8'd28, 8'h09, "second message data 8");
        expect_reg(0, 8'd30, (rbsa0 + 8'd13) & 8'h3F, "RBSA: + 13");
        rd(0, 8'd2, q);
        if (q[1] !== 1'b0) fail("DOS not cleared by CDO");

        $display("  Wishbone access length (cyc&stb high, ack cycle included): %0d..%0d wb_clk_i cycles", lat_min, lat_max);
        if (lat_max > 20) fail("ack latency above the documented bound");
        // ================= 8. glitch: bit error / receiver error; overload =================
        $display("8. dominant glitch in the data field; overload frame");
        while (q != 0) begin rd(0, 8'd29, q); if (q != 0) wr(0, 8'd1, 8'h04); end
        wr(0, 8'd1, 8'h08);                 // CDO
        wr(1, 8'd0, 8'h01); wr(1, 8'd15, 8'd0); wr(1, 8'd14, 8'd0); wr(1, 8'd0, 8'h00);
        wr(0, 8'd0, 8'h09); wr(0, 8'd15, 8'd0); wr(0, 8'd14, 8'd0); wr(0, 8'd0, 8'h08);
        wait_bits(14);
        rd(0, 8'd12, q); rd(1, 8'd12, q);   // arm ECC capture
        glitch_at = 1;                      // data bit 2 of 0xAA (recessive)
        send1(8'h01, 8'h24, 8'h60, 8'h00, 8'h00, 64'hAA00_0000_0000_0000, 1);
        rd(1, 8'd12, q);
        if (q[7:6] !== 2'b00 || q[5] !== 1'b0) fail("node 1 ECC: bit error, direction TX expected");
        rd(0, 8'd12, q);
        if (q[5] !== 1'b1) fail("node 0 ECC: direction RX expected");
        expect_reg(1, 8'd15, 8'd7, "node 1 TXERR: +8, then -1 after the retransmission");
        expect_reg(0, 8'd29, 8'd1, "node 0 received the retransmission once");
        rd(0, 8'd14, rec0);
        glitch_at = 2;                      // first intermission bit
        send1(8'h01, 8'h24, 8'h60, 8'h00, 8'h00, 64'hAA00_0000_0000_0000, 1);
        if (ovl_seen == 0) fail("no overload flag seen");
        expect_reg(1, 8'd15, 8'd6, "node 1 TXERR after the overload frame");
        rd(0, 8'd14, q);
        if (q != rec0 - 8'd1 && !(rec0 == 0 && q == 0)) fail("node 0 RXERR: only the reception decrement expected");
        expect_reg(0, 8'd29, 8'd2, "node 0 received the second frame");

        // ================= 9. listen only + single shot =================
        $display("9. listen-only node, single-shot transmission");
        while (q != 0) begin rd(0, 8'd29, q); if (q != 0) wr(0, 8'd1, 8'h04); end
        wr(0, 8'd0, 8'h01); wr(0, 8'd14, 8'd5); wr(0, 8'd0, 8'h02);   // LOM, RXERR = 5
        wr(1, 8'd0, 8'h01); wr(1, 8'd15, 8'd0); wr(1, 8'd0, 8'h00);
        wait_bits(14);
        tx0_dom = 0; watch_tx0 = 1;
        wr(1, 8'd16, 8'h01); wr(1, 8'd17, 8'h24); wr(1, 8'd18, 8'h60); wr(1, 8'd19, 8'h11);
        wr(1, 8'd1, 8'h03);                 // TR + AT: single shot
        wait_bits(120);
        watch_tx0 = 0;
        if (tx0_dom) fail("listen-only node drove a dominant bit");
        rd(1, 8'd2, q);
        if (q[2] !== 1'b1 || q[3] !== 1'b0) fail("single shot: TBS = 1, TCS = 0 expected");
        expect_reg(1, 8'd15, 8'd8, "node 1 TXERR: one attempt only");
        expect_reg(0, 8'd14, 8'd5, "listen-only RXERR frozen");
        expect_reg(0, 8'd29, 8'd0, "nothing received (the frame failed)");

        // ================= 10. dual filter =================
        $display("10. dual acceptance filter, standard frames");
        wr(0, 8'd0, 8'h01);                 // reset mode, dual filter, no LOM
        wr(0, 8'd16, 8'h24); wr(0, 8'd17, 8'h65); wr(0, 8'd18, 8'h55); wr(0, 8'd19, 8'h65);
        for (q = 20; q < 24; q = q + 1) wr(0, q, 8'h00);
        wr(0, 8'd0, 8'h00);
        wait_bits(14);
        send1(8'h01, 8'h24, 8'h60, 8'h00, 8'h00, 64'h5500_0000_0000_0000, 1);  // 0x123, 55: filter 1
        send1(8'h01, 8'h24, 8'h60, 8'h00, 8'h00, 64'h5600_0000_0000_0000, 1);  // 0x123, 56: no
        send1(8'h00, 8'h55, 8'h60, 8'h00, 8'h00, 64'h0, 0);                    // 0x2AB: filter 2
        send1(8'h00, 8'h55, 8'h40, 8'h00, 8'h00, 64'h0, 0);                    // 0x2AA: no
        expect_reg(0, 8'd29, 8'd2, "dual filter: RMC");
        expect_reg(0, 8'd19, 8'h55, "dual filter: first message data 1");
        wr(0, 8'd1, 8'h04);
        expect_reg(0, 8'd17, 8'h55, "dual filter: second message ID1");
        expect_reg(0, 8'd18, 8'h60, "dual filter: second message ID2");
        wr(0, 8'd1, 8'h04);

        // ================= 11. BasicCAN filter =================
        $display("11. BasicCAN acceptance filter, extended frame in BasicCAN");
        wr(0, 8'd0, 8'h01);
        wr(0, 8'd31, 8'h07);                // BasicCAN (CDR.7 written in reset mode)
        wr(0, 8'd4, 8'h24); wr(0, 8'd5, 8'h00);
        wr(0, 8'd0, 8'h00);
        wait_bits(14);
        send1(8'h00, 8'h55, 8'h60, 8'h00, 8'h00, 64'h0, 0);                    // 0x2AB: rejected
        rd(0, 8'd2, q);
        if (q[0] !== 1'b0) fail("BasicCAN filter let 0x2AB through");
        send1(8'h81, 8'h24, 8'hE0, 8'h00, 8'h08, 64'h7700_0000_0000_0000, 1); // ext, base 0x127
        rd(0, 8'd2, q);
        if (q[0] !== 1'b0) fail("BasicCAN: extended frame stored (the SJA1000 is extended frame passive in BasicCAN)");
        send1(8'h01, 8'h24, 8'hE0, 8'h00, 8'h00, 64'h7700_0000_0000_0000, 1); // std 0x127
        rd(0, 8'd2, q);
        if (q[0] !== 1'b1) fail("BasicCAN: standard frame 0x127 not stored");
        expect_reg(0, 8'd20, 8'h24, "BasicCAN RX ID.10..3 of 0x127");
        expect_reg(0, 8'd21, 8'hE1, "BasicCAN RX ID.2..0, RTR, DLC");
        expect_reg(0, 8'd22, 8'h77, "BasicCAN RX data 1");
        wr(0, 8'd1, 8'h04);
        rd(0, 8'd2, q);
        if (q[0] !== 1'b0) fail("RBS after RRB");

        // ================= 12. triple sampling =================
        $display("12. triple sampling (SAM = 1)");
        for (k = 0; k < 2; k = k + 1) begin
            wr(k, 8'd0, 8'h01);
            wr(k, 8'd31, 8'h07);                            // both in BasicCAN
            wr(k, 8'd6, 8'h01); wr(k, 8'd7, 8'hA5);         // SJW 1, SAM, TSEG1 6, TSEG2 3
            wr(k, 8'd4, 8'h00); wr(k, 8'd5, 8'hFF);
            wr(k, 8'd0, 8'h00);
        end
        wait_bits(14);
        wr(0, 8'd10, 8'h12); wr(0, 8'd11, 8'h22); wr(0, 8'd12, 8'hC3); wr(0, 8'd13, 8'h3C);
        wr(0, 8'd1, 8'h01);
        wait_bits(70);
        expect_reg(1, 8'd20, 8'h12, "SAM: node 1 RX ID");
        expect_reg(1, 8'd21, 8'h22, "SAM: node 1 RX ID/RTR/DLC");
        expect_reg(1, 8'd23, 8'h3C, "SAM: node 1 RX data 2");
        expect_reg(0, 8'd2, 8'h0C, "SAM: node 0 SR (TBS, TCS)");

        $display("PASS (Wishbone accesses %0d..%0d wb_clk_i cycles)", lat_min, lat_max);
        $finish;
    end

    initial begin
        #50_000_000;
        fail("global timeout");
    end
endmodule
