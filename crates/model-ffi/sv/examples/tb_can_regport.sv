// Example: our rtl/can_regport (can_top behind a plain register port on
// clk_i: one-clock strobes, separate read and write addresses, read data
// 14 clocks after the read strobe, no acknowledge) on a plain
// SystemVerilog bench, with the golden model as its scoreboard
// (sja1000_model_pkg) fed from the register-port pins: each access goes to
// the model at the clock edge that presents its strobe, with the profile's
// [access.regport] timing (set_host_bus("regport")), every read is
// compared at its latency, and tx_o/irq_on/bus_off_on at every CAN clock.
//
//   PeliCAN self-test frame (rx_i = tx_o), received and read back.
//
// Prints "SCOREBOARD PASS ..." or "SCOREBOARD FAIL" and the diagnosis
// (exit status 1).
`timescale 1ps/1ps
module tb_can_regport;
  import sja1000_model_pkg::*;

  localparam real CAN_HZ = 24.0e6;
  localparam int CAN_HALF_PS = 20833;  // 24 MHz
  // [access.regport] defaults (our can_regport, measured): read data 14
  // clocks after the strobe, 14 idle clocks after each access.
  localparam int LATENCY = 14;
  localparam int GAP = 14;

  logic clk_i = 0, rst_i = 1;
  logic wr_i = 0, rd_i = 0;
  logic [7:0] wr_adr_i = 0, rd_adr_i = 0, wdat_i = 0;
  wire [7:0] rdat_o;
  wire tx_o, bus_off_on, irq_on, clkout_o;
  wire rx_i = tx_o;

  can_regport dut (.*);

  initial begin #3001; forever #(CAN_HALF_PS) clk_i = ~clk_i; end

  sja1000_scoreboard sb;

  task automatic fail_now();
    $display("SCOREBOARD FAIL");
    $display("%s", sb.diagnosis());
    $fatal(1, "the DUT diverged from the golden model");
  endtask

  // Scoreboard feed, host side, from the pins as this rising edge samples
  // them (the master below drives on falling edges): the launch at the
  // edge that presents a strobe, the read data LATENCY clocks after it (the
  // port has no acknowledge: the data is due then).
  int since_rd = -1;
  logic [7:0] req_reg;
  always @(posedge clk_i) if (sb != null && !rst_i) begin
    if (wr_i) begin
      sb.request(1, wr_adr_i, wdat_i);
      since_rd = -1;
    end else if (rd_i) begin
      sb.request(0, rd_adr_i, 8'h00);
      req_reg = rd_adr_i;
      since_rd = 0;
    end else if (since_rd >= 0) begin
      since_rd++;
    end
    if (since_rd == LATENCY) begin
      void'(sb.compare_read(req_reg, rdat_o));
      since_rd = -1;
      if (sb.failed()) fail_now();
    end
  end

  // Scoreboard feed, CAN side: rx as the DUT sampled it at the edge, its
  // pins just after.
  initial forever begin
    logic rx;
    @(posedge clk_i);
    rx = rx_i;
    #1;
    if (sb != null && !rst_i) begin
      void'(sb.clock(rx, tx_o, irq_on, bus_off_on));
      if (sb.failed()) fail_now();
    end
  end

  // Register-port master: a one-clock strobe on a falling edge, then the
  // read data LATENCY clocks after it, then GAP idle clocks.
  task automatic reg_write(input logic [7:0] r, input logic [7:0] d);
    @(negedge clk_i);
    wr_i = 1; wr_adr_i = r; wdat_i = d;
    @(negedge clk_i);
    wr_i = 0;
    repeat (GAP - 1) @(negedge clk_i);
  endtask

  task automatic reg_read(input logic [7:0] r, output logic [7:0] q);
    @(negedge clk_i);
    rd_i = 1; rd_adr_i = r;
    @(negedge clk_i);
    rd_i = 0;
    repeat (LATENCY - 1) @(negedge clk_i);
    q = rdat_o;  // the data of clock LATENCY after the strobe
    repeat (GAP) @(negedge clk_i);
  endtask

  task automatic can_clocks(int n);
    repeat (n) @(posedge clk_i);
  endtask

  logic [7:0] v;
  initial begin
    sb = new("rtl", CAN_HZ);
    sb.set_name("tb_can_regport self-test");
    sb.set_host_bus("regport");
    repeat (4) @(posedge clk_i);
    rst_i = 0;
    repeat (4) @(posedge clk_i);
    // PeliCAN self-test: STM, self reception request, rx = tx_o.
    reg_write(0, 8'h01);                 // MOD: reset mode
    reg_write(31, 8'h80);                // CDR: PeliCAN
    reg_write(0, 8'h05);                 // MOD: reset + self-test
    for (int a = 16; a < 20; a++) reg_write(a[7:0], 8'h00);  // ACR0..3
    for (int a = 20; a < 24; a++) reg_write(a[7:0], 8'hFF);  // AMR0..3
    reg_write(6, 8'h41);                 // BTR0: BRP 1, SJW 2
    reg_write(7, 8'h25);                 // BTR1: 10 tq, 600 kbit/s at 24 MHz
    reg_write(8, 8'h1A);                 // OCR
    reg_write(4, 8'hFF);                 // IER: every interrupt
    reg_write(0, 8'h04);                 // MOD: operating, self-test
    reg_read(0, v);
    reg_write(16, 8'h02);                // TX frame info: standard, DLC 2
    reg_write(17, 8'h24); reg_write(18, 8'h60);  // ID 0x123
    reg_write(19, 8'hA5); reg_write(20, 8'h5A);
    reg_write(1, 8'h10);                 // CMR: self reception request
    // Poll SR until the frame is received (RBS) and sent (TCS).
    for (int i = 0; i < 400; i++) begin
      reg_read(2, v);
      if ((v & 8'h09) == 8'h09) break;
      can_clocks(40);
    end
    reg_read(3, v);                      // IR (clears RI/TI)
    for (int a = 16; a < 21; a++) reg_read(a[7:0], v);  // the frame received
    if (v != 8'h5A) $fatal(1, "received data byte 2 is 0x%02X, not 0x5A", v);
    reg_write(1, 8'h04);                 // CMR: release receive buffer
    reg_read(2, v);
    // The last reads are judged, then the end-of-test check.
    can_clocks(sb.open_clocks() + 1);
    if (sb.finish()) fail_now();
    $display("SCOREBOARD PASS: %0d register reads and %0d tx sample points compared",
             sb.compared_reads(), sb.compared_bits());
    $finish;
  end
endmodule
