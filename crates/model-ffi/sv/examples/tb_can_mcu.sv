// Example: our rtl/can_top_mcu in Motorola mode (mode_i low: AS, E, R/W,
// CS and the multiplexed AD port, split into port_0_i / port_0_o /
// port_0_oe) on a plain SystemVerilog bench, with the golden model as its
// scoreboard (sja1000_model_pkg) fed from the bus pins: the address
// latched when AS falls, a read to the model when E rises, a write when E
// falls (where can_top_mcu takes them; set_host_bus("motorola"): the
// profile's [access.motorola], else [access.i8051] timing), every read
// compared when E falls with the byte the core drove in E, and
// tx_o/irq_on/bus_off_on at every CAN clock.
//
//   PeliCAN self-test frame (rx_i = tx_o), received and read back.
//
// Prints "SCOREBOARD PASS ..." or "SCOREBOARD FAIL" and the diagnosis
// (exit status 1).
`timescale 1ps/1ps
module tb_can_mcu;
  import sja1000_model_pkg::*;

  localparam real CAN_HZ = 24.0e6;
  localparam int CAN_HALF_PS = 20833;  // 24 MHz
  // Phases (ps): the kit's Rust Motorola BFM defaults
  // (bfm::MotorolaAcTiming, crates/bfm/src/motorola.rs).
  localparam int AS_PS = 120_000, ADDR_HOLD_PS = 40_000, READ_FLOAT_PS = 160_000;
  localparam int DATA_SETUP_PS = 160_000, E_READ_PS = 760_000, E_WRITE_PS = 400_000;
  localparam int DATA_HOLD_PS = 40_000, RECOVERY_PS = 260_000;

  logic rst_i = 1, clk_i = 0, mode_i = 0;
  logic ale_as_i = 0, cs_can_i = 0, rd_e_i = 0, wr_rw_i = 1;
  logic [7:0] port_0_i = 8'hFF;
  wire [7:0] port_0_o;
  wire port_0_oe, tx_o, bus_off_on, irq_on, clkout_o;
  wire rx_i = tx_o;

  can_top_mcu dut (.*);

  initial begin #3001; forever #(CAN_HALF_PS) clk_i = ~clk_i; end

  sja1000_scoreboard sb;

  task automatic fail_now();
    $display("SCOREBOARD FAIL");
    $display("%s", sb.diagnosis());
    $fatal(1, "the DUT diverged from the golden model");
  endtask

  // Scoreboard feed, host side, from the bus pins: the address latched as
  // AS falls, the access at the E edge the core counts from, the read data
  // as the core drove it while E was high (its enable falls with E).
  logic [7:0] adr, rdata;
  bit in_e, read_e, driven;
  always @(negedge ale_as_i) adr = port_0_i;
  always @(posedge rd_e_i) if (sb != null && !rst_i && cs_can_i) begin
    in_e = 1;
    read_e = wr_rw_i;
    driven = 0;
    if (read_e) sb.request(0, adr, 8'h00);
  end
  always @(port_0_oe or port_0_o) if (port_0_oe && rd_e_i) begin
    rdata = port_0_o;
    driven = 1;
  end
  // in_e, not cs_can_i: a read's CS falls with E, before this block runs.
  always @(negedge rd_e_i) if (in_e) begin
    in_e = 0;
    if (!read_e) sb.request(1, adr, port_0_i);
    else void'(sb.compare_read(adr, driven ? rdata : 8'hFF));
    if (sb.failed()) fail_now();
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

  // Motorola master: AS with the address (R/W low from here for a write),
  // address hold, write data set-up or port released, E, data hold,
  // recovery with CS low.
  task automatic mot(input bit we, input logic [7:0] r, input logic [7:0] d, output logic [7:0] q);
    ale_as_i = 1; cs_can_i = 1; wr_rw_i = !we; port_0_i = r;
    #(AS_PS) ale_as_i = 0;
    #(ADDR_HOLD_PS) port_0_i = we ? d : 8'hFF;
    #(we ? DATA_SETUP_PS : READ_FLOAT_PS) rd_e_i = 1;
    #(we ? E_WRITE_PS : E_READ_PS) q = port_0_oe ? port_0_o : 8'hFF;
    rd_e_i = 0;
    if (we) #(DATA_HOLD_PS);
    cs_can_i = 0; wr_rw_i = 1; port_0_i = 8'hFF;
    #(RECOVERY_PS);
  endtask

  task automatic mot_write(input logic [7:0] r, input logic [7:0] d);
    logic [7:0] unused;
    mot(1, r, d, unused);
  endtask

  task automatic mot_read(input logic [7:0] r, output logic [7:0] q);
    mot(0, r, 8'h00, q);
  endtask

  task automatic can_clocks(int n);
    repeat (n) @(posedge clk_i);
  endtask

  logic [7:0] v;
  initial begin
    sb = new("rtl", CAN_HZ);
    sb.set_name("tb_can_mcu self-test");
    sb.set_host_bus("motorola");
    repeat (4) @(posedge clk_i);
    rst_i = 0;
    repeat (4) @(posedge clk_i);
    // PeliCAN self-test: STM, self reception request, rx = tx_o.
    mot_write(0, 8'h01);                 // MOD: reset mode
    mot_write(31, 8'h80);                // CDR: PeliCAN
    mot_write(0, 8'h05);                 // MOD: reset + self-test
    for (int a = 16; a < 20; a++) mot_write(a[7:0], 8'h00);  // ACR0..3
    for (int a = 20; a < 24; a++) mot_write(a[7:0], 8'hFF);  // AMR0..3
    mot_write(6, 8'h41);                 // BTR0: BRP 1, SJW 2
    mot_write(7, 8'h25);                 // BTR1: 10 tq, 600 kbit/s at 24 MHz
    mot_write(8, 8'h1A);                 // OCR
    mot_write(4, 8'hFF);                 // IER: every interrupt
    mot_write(0, 8'h04);                 // MOD: operating, self-test
    mot_read(0, v);
    mot_write(16, 8'h02);                // TX frame info: standard, DLC 2
    mot_write(17, 8'h24); mot_write(18, 8'h60);  // ID 0x123
    mot_write(19, 8'hA5); mot_write(20, 8'h5A);
    mot_write(1, 8'h10);                 // CMR: self reception request
    // Poll SR until the frame is received (RBS) and sent (TCS).
    for (int i = 0; i < 400; i++) begin
      mot_read(2, v);
      if ((v & 8'h09) == 8'h09) break;
      can_clocks(40);
    end
    mot_read(3, v);                      // IR (clears RI/TI)
    for (int a = 16; a < 21; a++) mot_read(a[7:0], v);  // the frame received
    if (v != 8'h5A) $fatal(1, "received data byte 2 is 0x%02X, not 0x5A", v);
    mot_write(1, 8'h04);                 // CMR: release receive buffer
    mot_read(2, v);
    // The last reads are judged, then the end-of-test check.
    can_clocks(sb.open_clocks() + 1);
    if (sb.finish()) fail_now();
    $display("SCOREBOARD PASS: %0d register reads and %0d tx sample points compared",
             sb.compared_reads(), sb.compared_bits());
    $finish;
  end
endmodule
