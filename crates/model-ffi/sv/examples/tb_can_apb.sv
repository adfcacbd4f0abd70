// Example: our rtl/can_apb (can_top behind an APB completer, register n at
// byte address 4n, data in bits 7:0) on a plain SystemVerilog APB bench,
// with the golden model as its scoreboard (sja1000_model_pkg) fed from the
// APB pins: each access goes to the model at the first edge of its access
// phase (PSEL & PENABLE), with the profile's [access.apb] timing
// (set_host_bus("apb")), every read is compared at PREADY, and
// tx_o/irq_on/bus_off_on at every CAN clock.
//
//   PeliCAN self-test frame (rx_i = tx_o), received and read back.
//
// Prints "SCOREBOARD PASS ..." or "SCOREBOARD FAIL" and the diagnosis
// (exit status 1).
`timescale 1ps/1ps
module tb_can_apb;
  import sja1000_model_pkg::*;

  localparam real CAN_HZ = 24.0e6;
  localparam int CAN_HALF_PS = 20833;  // 24 MHz
  localparam int APB_HALF_PS = 10000;  // 50 MHz
  localparam int STRIDE = 4;           // bytes between registers

  logic pclk = 0, presetn = 0, clk_i = 0;
  logic psel = 0, penable = 0, pwrite = 0;
  logic [31:0] paddr = 0, pwdata = 0;
  logic [3:0] pstrb = 0;
  logic [2:0] pprot = 0;
  wire [31:0] prdata;
  wire pready, pslverr, tx_o, bus_off_on, irq_on, clkout_o;
  wire rx_i = tx_o;

  can_apb dut (.*);

  always #(APB_HALF_PS) pclk = ~pclk;
  // An odd offset: no CAN edge ever falls on a host edge.
  initial begin #3001; forever #(CAN_HALF_PS) clk_i = ~clk_i; end

  sja1000_scoreboard sb;

  task automatic fail_now();
    $display("SCOREBOARD FAIL");
    $display("%s", sb.diagnosis());
    $fatal(1, "the DUT diverged from the golden model");
  endtask

  // Scoreboard feed, host side, from the APB pins as this rising edge
  // samples them (the master below drives on falling edges): the launch
  // at the first edge of the access phase, the read data at PREADY. The
  // byte address becomes a register number by the stride; the register's
  // byte is lane 0.
  bit in_access = 0, req_we;
  logic [7:0] req_reg;
  always @(posedge pclk) if (sb != null && presetn) begin
    if (psel && penable && !in_access) begin
      req_we = pwrite;
      req_reg = 8'(paddr / STRIDE);
      sb.request(req_we, req_reg, pwdata[7:0]);
      in_access = 1;
    end
    if (in_access && pready) begin
      if (!req_we) void'(sb.compare_read(req_reg, prdata[7:0]));
      in_access = 0;
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
    if (sb != null && presetn) begin
      void'(sb.clock(rx, tx_o, irq_on, bus_off_on));
      if (sb.failed()) fail_now();
    end
  end

  // APB master: a setup phase, then the access phase until PREADY; drives
  // on falling edges.
  task automatic apb(input bit we, input logic [7:0] r, input logic [7:0] d, output logic [7:0] q);
    @(negedge pclk);
    psel = 1; penable = 0; pwrite = we; paddr = 32'(r) * STRIDE;
    pwdata = we ? {24'h0, d} : 32'h0; pstrb = we ? 4'b0001 : 4'b0000;
    @(negedge pclk);
    penable = 1;
    do @(negedge pclk); while (!pready);
    q = prdata[7:0];
    psel = 0; penable = 0;
  endtask

  task automatic apb_write(input logic [7:0] r, input logic [7:0] d);
    logic [7:0] unused;
    apb(1, r, d, unused);
  endtask

  task automatic apb_read(input logic [7:0] r, output logic [7:0] q);
    apb(0, r, 8'h00, q);
  endtask

  task automatic can_clocks(int n);
    repeat (n) @(posedge clk_i);
  endtask

  logic [7:0] v;
  initial begin
    sb = new("rtl", CAN_HZ);
    sb.set_name("tb_can_apb self-test");
    sb.set_host_bus("apb");
    repeat (4) @(posedge pclk);
    presetn = 1;
    repeat (4) @(posedge pclk);
    // PeliCAN self-test: STM, self reception request, rx = tx_o.
    apb_write(0, 8'h01);                 // MOD: reset mode
    apb_write(31, 8'h80);                // CDR: PeliCAN
    apb_write(0, 8'h05);                 // MOD: reset + self-test
    for (int a = 16; a < 20; a++) apb_write(a[7:0], 8'h00);  // ACR0..3
    for (int a = 20; a < 24; a++) apb_write(a[7:0], 8'hFF);  // AMR0..3
    apb_write(6, 8'h41);                 // BTR0: BRP 1, SJW 2
    apb_write(7, 8'h25);                 // BTR1: 10 tq, 600 kbit/s at 24 MHz
    apb_write(8, 8'h1A);                 // OCR
    apb_write(4, 8'hFF);                 // IER: every interrupt
    apb_write(0, 8'h04);                 // MOD: operating, self-test
    apb_read(0, v);
    apb_write(16, 8'h02);                // TX frame info: standard, DLC 2
    apb_write(17, 8'h24); apb_write(18, 8'h60);  // ID 0x123
    apb_write(19, 8'hA5); apb_write(20, 8'h5A);
    apb_write(1, 8'h10);                 // CMR: self reception request
    // Poll SR until the frame is received (RBS) and sent (TCS).
    for (int i = 0; i < 400; i++) begin
      apb_read(2, v);
      if ((v & 8'h09) == 8'h09) break;
      can_clocks(40);
    end
    apb_read(3, v);                      // IR (clears RI/TI)
    for (int a = 16; a < 21; a++) apb_read(a[7:0], v);  // the frame received
    if (v != 8'h5A) $fatal(1, "received data byte 2 is 0x%02X, not 0x5A", v);
    apb_write(1, 8'h04);                 // CMR: release receive buffer
    apb_read(2, v);
    // The last reads are judged, then the end-of-test check.
    can_clocks(sb.open_clocks() + 1);
    if (sb.finish()) fail_now();
    $display("SCOREBOARD PASS: %0d register reads and %0d tx sample points compared",
             sb.compared_reads(), sb.compared_bits());
    $finish;
  end
endmodule
