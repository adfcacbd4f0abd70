// Icarus self-check for rtl/can_top_8051: an 8051-style host on the
// multiplexed bus, its pins changing at times unrelated to clk_i (24 MHz):
// ALE 120 ns with the address, address hold 40 ns, then RD (800 ns) or
// WR (400 ns, data driven 160 ns before it and held 40 ns after), 260 ns
// recovery. Checks: reset values through the bus, registers written and
// read back (every bit pattern of TEST), the port driven only inside RD
// with CS (and floating within one simulation step after RD falls), a
// read with CS low is ignored, a PeliCAN self-test frame with self
// reception read back from the RX buffer.
`timescale 1ns/1ps
module tb_8051;
    reg cclk = 0, rst = 1;
    always #20.833 cclk = ~cclk;           // 24 MHz CAN clock

    reg        ale = 0, cs = 0, rd = 0, wr = 0;
    reg  [7:0] ad_host = 8'h00;
    reg        ad_host_oe = 0;
    wire [7:0] ad_dut;
    wire       ad_dut_oe, tx, bo, irq_n, ck;

    can_top_8051 dut (.rst_i(rst), .clk_i(cclk), .ale_i(ale), .cs_can_i(cs), .rd_i(rd),
        .wr_i(wr), .port_0_i(ad_host_oe ? ad_host : 8'hFF), .port_0_o(ad_dut),
        .port_0_oe(ad_dut_oe), .rx_i(tx), .tx_o(tx), .bus_off_on(bo), .irq_on(irq_n),
        .clkout_o(ck));

    task fail(input [8*64-1:0] msg);
        begin $display("FAIL: %0s (t=%0t)", msg, $time); $fatal(1); end
    endtask

    // the DUT may drive the port only while RD and CS are high
    always @(ad_dut_oe) if (ad_dut_oe && !(rd && cs)) fail("port driven outside RD");
    always @(*) if (ad_dut_oe && ad_host_oe) fail("port contention");

    task automatic addr_phase(input [7:0] a, input sel);
        begin
            cs = sel; ad_host = a; ad_host_oe = 1; ale = 1; #120;
            ale = 0; #40;
        end
    endtask
    task automatic wr8051(input [7:0] a, input [7:0] d);
        begin
            addr_phase(a, 1);
            ad_host = d; #160;
            wr = 1; #400;
            wr = 0; #40;
            ad_host_oe = 0; cs = 0; #260;
        end
    endtask
    task automatic rd8051(input [7:0] a, input sel, output [7:0] q);
        begin
            addr_phase(a, sel);
            ad_host_oe = 0; #160;
            rd = 1; #800;
            q = ad_dut_oe ? ad_dut : 8'hFF;  // pull-ups if nobody drives
            rd = 0; #1;
            if (ad_dut_oe) fail("port still driven after RD fell");
            cs = 0; #259;
        end
    endtask
    task automatic expect_reg(input [7:0] a, input [7:0] v);
        reg [7:0] q;
        begin
            rd8051(a, 1, q);
            if (q !== v) begin
                $display("FAIL: addr %0d read %02h, expected %02h (t=%0t)", a, q, v, $time);
                $fatal(1);
            end
        end
    endtask

    integer i;
    reg [7:0] q;
    initial begin
        #3 rst = 1; #500 rst = 0; #2000;
        expect_reg(0, 8'h21);                 // BasicCAN CR after reset
        rd8051(0, 0, q);                      // CS low: nobody answers
        if (q !== 8'hFF) fail("a read without CS was answered");
        for (i = 0; i < 256; i = i + 37) begin
            wr8051(9, i); expect_reg(9, i);   // TEST: plain register
        end
        wr8051(31, 8'h88);                    // CDR: PeliCAN, clock off
        wr8051(0, 8'h05);                     // MOD: reset mode, self test
        wr8051(16, 8'h00); wr8051(20, 8'hFF); // ACR0, AMR0: accept all
        wr8051(21, 8'hFF); wr8051(22, 8'hFF); wr8051(23, 8'hFF);
        wr8051(6, 8'h41); wr8051(7, 8'h25); wr8051(8, 8'h1A);
        expect_reg(6, 8'h41); expect_reg(7, 8'h25);
        wr8051(0, 8'h04);                     // operating mode, self test
        wr8051(16, 8'h02);                    // SFF, DLC 2
        wr8051(17, 8'hA5); wr8051(18, 8'h20); wr8051(19, 8'h51); wr8051(20, 8'h3C);
        wr8051(1, 8'h10);                     // SRR: self reception request
        for (i = 0; i < 200; i = i + 1) begin
            rd8051(2, 1, q);                  // SR
            if (q[0]) i = 1000;               // RBS
        end
        if (i < 1000) fail("no self-received frame");
        expect_reg(16, 8'h02); expect_reg(17, 8'hA5); expect_reg(18, 8'h20);
        expect_reg(19, 8'h51); expect_reg(20, 8'h3C);
        $display("PASS tb_8051");
        $finish;
    end
    initial begin #20000000 fail("timeout"); end
endmodule
