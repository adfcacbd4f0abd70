// Icarus Verilog test bench for the bench's self-test loopback workload
// (crates/bench): the same RTL, clocking and register sequence as
// tb/bench/harness.cpp and the co-simulation. One 24 MHz clock drives
// wb_clk_i and clk_i, rx_i is tied to tx_o, and Wishbone tasks play the
// sequence; frames come from the shared xorshift32 generator.
//
// Plusargs: +frames=<n> +seed=<s>
// Prints: BENCH frames=<n> cycles=<clock cycles> errors=<mismatches>
`timescale 1ns/1ps
module bench_tb;
    reg        clk = 1'b0;
    reg        rst = 1'b1;
    reg        cyc = 1'b0, stb = 1'b0, we = 1'b0;
    reg  [7:0] adr = 8'h00, dwr = 8'h00;
    wire [7:0] drd;
    wire       ack, tx, bus_on, irq_n, clkout;

    can_top dut (
        .wb_clk_i(clk), .wb_rst_i(rst), .wb_dat_i(dwr), .wb_dat_o(drd),
        .wb_cyc_i(cyc), .wb_stb_i(stb), .wb_we_i(we), .wb_adr_i(adr), .wb_ack_o(ack),
        .clk_i(clk), .rx_i(tx), .tx_o(tx), .bus_off_on(bus_on), .irq_on(irq_n), .clkout_o(clkout)
    );

    always #20.833 clk = ~clk;   // 24 MHz
    reg [63:0] cycles = 0;
    always @(posedge clk) cycles <= cycles + 1;

    // Wishbone classic access: pins set after a falling edge, held until
    // the rising edge that shows ack, released before the next rising edge.
    task wb(input w, input [7:0] a, input [7:0] d, output [7:0] q);
        integer t;
        begin
            cyc = 1'b1; stb = 1'b1; we = w; adr = a; dwr = d;
            t = 0;
            @(posedge clk); #1;
            while (!ack) begin
                t = t + 1;
                if (t > 200) begin $display("FAIL: no wb_ack_o at 0x%02h", a); $finish; end
                @(posedge clk); #1;
            end
            q = drd;
            @(negedge clk);
            cyc = 1'b0; stb = 1'b0; we = 1'b0;
            @(posedge clk);
            @(negedge clk);
        end
    endtask
    reg [7:0] scratch;
    task wr(input [7:0] a, input [7:0] d); wb(1'b1, a, d, scratch); endtask
    task rd(input [7:0] a, output [7:0] q); wb(1'b0, a, 8'h00, q); endtask

    task idle(input integer n);
        integer i;
        for (i = 0; i < n; i = i + 1) @(negedge clk);
    endtask

    task wait_irq;
        integer t;
        begin
            t = 0;
            while (irq_n) begin
                @(negedge clk);
                t = t + 1;
                if (t > 200 * 40) begin $display("FAIL: irq_on never went low"); $finish; end
            end
        end
    endtask

    // The shared frame generator (see crates/bench/src/workload.rs).
    reg [31:0] rng;
    task next_u32(output [31:0] r);
        reg [31:0] x;
        begin
            x = rng;
            x = x ^ (x << 13);
            x = x ^ (x >> 17);
            x = x ^ (x << 5);
            rng = x;
            r = x;
        end
    endtask

    integer frames, k, i, errors;
    reg [63:0] seed;
    reg [31:0] r;
    reg [7:0] txb [0:10];
    reg [7:0] q, ir, mask;
    initial begin
        if (!$value$plusargs("frames=%d", frames)) frames = 10;
        if (!$value$plusargs("seed=%d", seed)) seed = 1;
        rng = seed[31:0];
        if (rng == 0) rng = 1;
        errors = 0;
        idle(8);
        rst = 1'b0;
        idle(8);

        wr(0, 8'h01);                      // reset mode
        wr(31, 8'h80);                     // CDR: PeliCAN
        wr(0, 8'h01);                      // MOD: RM
        wr(6, 8'h41);                      // BTR0
        wr(7, 8'h25);                      // BTR1: 40 clocks per bit
        for (i = 16; i < 20; i = i + 1) wr(i, 8'h00);   // ACR
        for (i = 20; i < 24; i = i + 1) wr(i, 8'hFF);   // AMR: accept all
        wr(4, 8'h03);                      // IER: RIE, TIE
        wr(0, 8'h04);                      // MOD: operating, self test
        idle(12 * 40);

        for (k = 0; k < frames; k = k + 1) begin
            next_u32(r);
            txb[0] = 8'h08;
            txb[1] = r[10:3];
            txb[2] = {r[2:0], 5'b0};
            for (i = 0; i < 8; i = i + 1) begin
                next_u32(r);
                txb[3 + i] = r[7:0];
            end
            for (i = 0; i < 11; i = i + 1) wr(16 + i, txb[i]);
            wr(1, 8'h10);                  // CMR: self reception request
            ir = 8'h00;
            wait_irq;
            idle(2 * 40);                  // SETTLE_BITS
            rd(3, q);
            ir = ir | q;
            while ((ir & 8'h03) != 8'h03) begin
                idle(40);
                wait_irq;
                rd(3, q);
                ir = ir | q;
            end
            rd(2, q);
            if ((q & 8'h09) != 8'h09) errors = errors + 1;   // TCS and RBS
            for (i = 0; i < 11; i = i + 1) begin
                mask = (i == 2) ? 8'hF0 : 8'hFF;
                rd(16 + i, q);
                if ((q & mask) != (txb[i] & mask)) errors = errors + 1;
            end
            wr(1, 8'h04);                  // CMR: release receive buffer
        end
        $display("BENCH frames=%0d cycles=%0d errors=%0d", frames, cycles, errors);
        $finish;
    end
endmodule
