// Example: our rtl/can_top on a plain SystemVerilog Wishbone bench, with
// the golden model as its scoreboard (sja1000_model_pkg). Every Wishbone
// access goes to the model at the edge the DUT samples it, every read is
// compared at its ack, tx_o/irq_on/bus_off_on at every CAN clock.
//
//   default:   PeliCAN self-test frame (rx_i = tx_o), received and read back
//   +tied_rx:  the DE2 thesis set-up (BasicCAN, rx_i tied recessive): the
//              frame never completes and finish() explains why
//
// Prints "SCOREBOARD PASS ..." or "SCOREBOARD FAIL" and the diagnosis
// (exit status 1).
`timescale 1ps/1ps
module tb_can_top;
  import sja1000_model_pkg::*;

  localparam real CAN_HZ = 24.0e6;
  localparam int CAN_HALF_PS = 20833;  // 24 MHz
  localparam int WB_HALF_PS = 10000;   // 50 MHz

  logic wb_clk_i = 0, wb_rst_i = 1, clk_i = 0;
  logic [7:0] wb_dat_i = 0, wb_adr_i = 0;
  logic wb_cyc_i = 0, wb_stb_i = 0, wb_we_i = 0;
  wire [7:0] wb_dat_o;
  wire wb_ack_o, tx_o, bus_off_on, irq_on, clkout_o;
  bit tied_rx;
  wire rx_i = tied_rx ? 1'b1 : tx_o;

  can_top dut (.*);

  always #(WB_HALF_PS) wb_clk_i = ~wb_clk_i;
  // An odd offset: no CAN edge ever falls on a host edge.
  initial begin #3001; forever #(CAN_HALF_PS) clk_i = ~clk_i; end

  sja1000_scoreboard sb;

  task automatic fail_now();
    $display("SCOREBOARD FAIL");
    $display("%s", sb.diagnosis());
    $fatal(1, "the DUT diverged from the golden model");
  endtask

  // Scoreboard feed, host side: the launch edge of each access (the first
  // host edge at which the DUT samples cyc & stb), the data of each read at
  // its ack. The master below drives on falling edges, so every value here
  // is the one the DUT samples at this rising edge.
  bit in_access = 0, req_we;
  logic [7:0] req_adr;
  always @(posedge wb_clk_i) if (sb != null && !wb_rst_i) begin
    if (wb_cyc_i && wb_stb_i && !in_access) begin
      sb.request(wb_we_i, wb_adr_i, wb_dat_i);
      in_access <= 1; req_we <= wb_we_i; req_adr <= wb_adr_i;
    end
    if (wb_ack_o && in_access) begin
      if (!req_we) void'(sb.compare_read(req_adr, wb_dat_o));
      in_access <= 0;
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
    if (sb != null && !wb_rst_i) begin
      void'(sb.clock(rx, tx_o, irq_on, bus_off_on));
      if (sb.failed()) fail_now();
    end
  end

  // Wishbone master: drives on falling edges, sees the ack there.
  task automatic wb_write(input logic [7:0] a, input logic [7:0] d);
    @(negedge wb_clk_i);
    wb_cyc_i = 1; wb_stb_i = 1; wb_we_i = 1; wb_adr_i = a; wb_dat_i = d;
    do @(negedge wb_clk_i); while (!wb_ack_o);
    wb_cyc_i = 0; wb_stb_i = 0;
  endtask

  task automatic wb_read(input logic [7:0] a, output logic [7:0] d);
    @(negedge wb_clk_i);
    wb_cyc_i = 1; wb_stb_i = 1; wb_we_i = 0; wb_adr_i = a;
    do @(negedge wb_clk_i); while (!wb_ack_o);
    d = wb_dat_o;
    wb_cyc_i = 0; wb_stb_i = 0;
  endtask

  task automatic can_clocks(int n);
    repeat (n) @(posedge clk_i);
  endtask

  logic [7:0] v;
  initial begin
    tied_rx = $test$plusargs("tied_rx");
    sb = new("rtl", CAN_HZ);
    sb.set_name(tied_rx ? "tb_can_top +tied_rx" : "tb_can_top self-test");
    repeat (4) @(posedge wb_clk_i);
    wb_rst_i = 0;
    repeat (4) @(posedge wb_clk_i);
    if (!tied_rx) begin
      // PeliCAN self-test: STM, self reception request, rx = tx_o.
      wb_write(0, 8'h01);                 // MOD: reset mode
      wb_write(31, 8'h80);                // CDR: PeliCAN
      wb_write(0, 8'h05);                 // MOD: reset + self-test
      for (int a = 16; a < 20; a++) wb_write(a[7:0], 8'h00);  // ACR0..3
      for (int a = 20; a < 24; a++) wb_write(a[7:0], 8'hFF);  // AMR0..3
      wb_write(6, 8'h41);                 // BTR0: BRP 1, SJW 2
      wb_write(7, 8'h25);                 // BTR1: 10 tq, 600 kbit/s at 24 MHz
      wb_write(8, 8'h1A);                 // OCR
      wb_write(4, 8'hFF);                 // IER: every interrupt
      wb_write(0, 8'h04);                 // MOD: operating, self-test
      wb_read(0, v);
      wb_write(16, 8'h02);                // TX frame info: standard, DLC 2
      wb_write(17, 8'h24); wb_write(18, 8'h60);  // ID 0x123
      wb_write(19, 8'hA5); wb_write(20, 8'h5A);
      wb_write(1, 8'h10);                 // CMR: self reception request
      // Poll SR until the frame is received (RBS) and sent (TCS).
      for (int i = 0; i < 400; i++) begin
        wb_read(2, v);
        if ((v & 8'h09) == 8'h09) break;
        can_clocks(40);
      end
      wb_read(3, v);                      // IR (clears RI/TI)
      for (int a = 16; a < 21; a++) wb_read(a[7:0], v);  // the frame received
      wb_write(1, 8'h04);                 // CMR: release receive buffer
      wb_read(2, v);
      wb_read(29, v);                     // RMC
    end else begin
      // The DE2 thesis (tb/de2-thesis.toml): BasicCAN, rx tied recessive.
      wb_write(0, 8'h01);  wb_write(31, 8'h00);
      wb_write(4, 8'hFF);  wb_write(5, 8'hFF);
      wb_write(6, 8'h41);  wb_write(7, 8'h25);  wb_write(8, 8'hDB);
      wb_write(0, 8'h00);
      wb_write(10, 8'hA5); wb_write(11, 8'h21); wb_write(12, 8'h51);
      wb_read(12, v); wb_read(10, v); wb_read(11, v);
      wb_write(1, 8'h01);                 // CMR: transmission request
      can_clocks(200 * 40);
      wb_read(2, v);
    end
    // The last reads are judged, then the end-of-test check.
    can_clocks(sb.open_clocks() + 1);
    if (sb.finish()) fail_now();
    $display("SCOREBOARD PASS: %0d register reads and %0d tx sample points compared",
             sb.compared_reads(), sb.compared_bits());
    $finish;
  end
endmodule
