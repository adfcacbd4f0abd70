// Icarus self-check for rtl/can_avalon: two wrappers on one CAN bus, driven
// by an Avalon-MM master that holds chipselect/read/write/address/writedata
// while waitrequest is high and takes readdata in the cycle it drops.
// Checks: waitrequest high until the access completes (never a zero-wait
// access, never a dropped one), the thesis frame goes from node 0 to node 1,
// irq is active high and is released when the message is released (RRB).
// Node 1 uses RX_SYNC = 2 (the hardware setting: a 2-flop rx synchroniser).
`timescale 1ns/1ps
module tb_avalon;
    reg clk = 0, cclk = 0, reset = 1;
    always #10 clk = ~clk;                 // 50 MHz Avalon clock
    always #20.833 cclk = ~cclk;           // 24 MHz CAN clock

    reg  [7:0] address [0:1];
    reg  [7:0] wdata   [0:1];
    reg        cs [0:1], rd_s [0:1], wr_s [0:1];
    wire [7:0] rdata0, rdata1;
    wire       wait0, wait1, irq0, irq1, tx0, tx1, bo0, bo1, ck0, ck1;
    wire       bus = tx0 & tx1;

    can_avalon a0 (.clk(clk), .reset(reset), .address(address[0]), .chipselect(cs[0]),
        .read(rd_s[0]), .write(wr_s[0]), .writedata(wdata[0]), .readdata(rdata0),
        .waitrequest(wait0), .irq(irq0), .can_clk(cclk), .rx(bus), .tx(tx0),
        .bus_off_on(bo0), .clkout(ck0));
    can_avalon #(.RX_SYNC(2)) a1 (.clk(clk), .reset(reset), .address(address[1]), .chipselect(cs[1]),
        .read(rd_s[1]), .write(wr_s[1]), .writedata(wdata[1]), .readdata(rdata1),
        .waitrequest(wait1), .irq(irq1), .can_clk(cclk), .rx(bus), .tx(tx1),
        .bus_off_on(bo1), .clkout(ck1));

    task fail(input [8*64-1:0] msg);
        begin $display("FAIL: %0s (t=%0t)", msg, $time); $fatal(1); end
    endtask

    integer waits_min = 1000;
    task automatic av(input integer n, input w, input [7:0] a, input [7:0] d, output [7:0] q);
        integer t;
        begin
            @(posedge clk); #1;
            address[n] = a; wdata[n] = d; cs[n] = 1; rd_s[n] = !w; wr_s[n] = w;
            t = 0;
            #1;
            while ((n == 0 ? wait0 : wait1)) begin
                @(posedge clk); #1; t = t + 1;
                if (t > 200) fail("waitrequest never dropped");
            end
            if (t < waits_min) waits_min = t;
            q = (n == 0) ? rdata0 : rdata1;
            @(posedge clk); #1;                // transfer ends on this edge
            cs[n] = 0; rd_s[n] = 0; wr_s[n] = 0;
        end
    endtask
    task automatic wr(input integer n, input [7:0] a, input [7:0] d); reg [7:0] t; av(n, 1, a, d, t); endtask
    task automatic expect_reg(input integer n, input [7:0] a, input [7:0] v);
        reg [7:0] q;
        begin
            av(n, 0, a, 8'h00, q);
            if (q !== v) begin
                $display("FAIL: node %0d addr %0d read %02h, expected %02h", n, a, q, v);
                $fatal(1);
            end
        end
    endtask

    integer k;
    initial begin
        for (k = 0; k < 2; k = k + 1) begin
            cs[k] = 0; rd_s[k] = 0; wr_s[k] = 0; address[k] = 0; wdata[k] = 0;
        end
        repeat (3) @(posedge clk);
        #1 reset = 0;
        // back-to-back accesses (a new one starts the cycle after the last ended)
        for (k = 0; k < 2; k = k + 1) begin
            expect_reg(k, 8'd0, 8'h21);
            wr(k, 8'd0, 8'h01); wr(k, 8'd4, 8'hFF); wr(k, 8'd5, 8'hFF);
            wr(k, 8'd6, 8'h41); wr(k, 8'd7, 8'h25); wr(k, 8'd31, 8'h00);
            expect_reg(k, 8'd7, 8'h25);
            wr(k, 8'd0, 8'h02);            // operating, RIE
        end
        if (irq0 !== 1'b0 || irq1 !== 1'b0) fail("irq must be low (inactive) after set-up");
        repeat (600) @(posedge cclk);       // bus integration
        wr(0, 8'd10, 8'hA5); wr(0, 8'd11, 8'h21); wr(0, 8'd12, 8'h51);
        wr(0, 8'd1, 8'h01);
        k = 0;
        while (irq1 !== 1'b1) begin
            @(posedge clk); k = k + 1;
            if (k > 200000) fail("node 1 never raised irq");
        end
        expect_reg(1, 8'd20, 8'hA5);
        expect_reg(1, 8'd21, 8'h21);
        expect_reg(1, 8'd22, 8'h51);
        expect_reg(1, 8'd3, 8'hE1);          // IR: RI (follows RBS, not cleared by the read)
        wr(1, 8'd1, 8'h04);                  // RRB
        @(posedge clk); #1;
        if (irq1 !== 1'b0) fail("irq not released by RRB");
        repeat (400) @(posedge cclk);       // node 0 finishes EOF (its success is at the last EOF bit)
        expect_reg(0, 8'd2, 8'h0C);          // node 0: TBS, TCS
        if (waits_min < 2) fail("an access completed without wait states");
        $display("PASS (Avalon: at least %0d wait states per access)", waits_min);
        $finish;
    end
    initial begin #20_000_000; fail("global timeout"); end
endmodule
