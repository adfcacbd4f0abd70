// can_top with the SJA1000 chip's Intel-mode (8051) host interface, for
// boards and firmware designed around the chip. Written from the
// datasheet's description of the multiplexed bus: the host puts the
// register address on AD7..AD0 while ALE is high, then moves one byte over
// the same lines with RD or WR while the chip is selected.
//
// Differences from the chip, on purpose:
//   - strobes are active high (cs_can_i, rd_i, wr_i), as in the opencores
//     core's 8051 build; put inverters in front for /CS /RD /WR;
//   - the bidirectional AD bus is split into port_0_i / port_0_o /
//     port_0_oe (an FPGA pad or the board's tristate buffer joins them);
//   - the bus is sampled with clk_i through two flops (no latch on ALE), so
//     the host must hold each phase for at least 3 clk_i: ALE with the
//     address, the write data before WR is released, RD until the data
//     is there;
//   - a read answers through can_top's clock-domain crossing (clocked
//     here by clk_i on both sides): the byte is on the port about 15 clk_i
//     after RD rises (measured in co-simulation: an RD strobe of 31 host
//     cycles at 50 MHz host / 24 MHz clk_i is enough, 30 is not; the chip
//     answers in tens of ns), and stays there until RD or CS falls (the
//     output enable follows the pins directly, so the port floats as soon
//     as the strobe ends);
//   - a write is taken when WR is released (the datasheet times the data
//     set-up and hold around the rising edge of /WR) and completes in the
//     background: the next access waits for it.
// Same CAN-side pins as can_top: irq_on active low, bus_off_on high while
// on the bus, tx_o/rx_i 1 = recessive. rst_i is active high, synchronous
// to clk_i.
module can_top_8051 #(
    parameter RX_SYNC = 0      // see can_top: 2 on hardware, 0 in co-simulation
) (
    input  wire       rst_i,
    input  wire       clk_i,
    input  wire       ale_i,
    input  wire       cs_can_i,
    input  wire       rd_i,
    input  wire       wr_i,
    input  wire [7:0] port_0_i,
    output wire [7:0] port_0_o,
    output wire       port_0_oe,
    input  wire       rx_i,
    output wire       tx_o,
    output wire       bus_off_on,
    output wire       irq_on,
    output wire       clkout_o
);
    // Two flops on every bus pin, all sampled together, so a control level
    // and the port value used with it are from the same instant.
    reg  [11:0] bus_m, bus_q;
    always @(posedge clk_i) begin
        bus_m <= {ale_i, cs_can_i, rd_i, wr_i, port_0_i};
        bus_q <= bus_m;
    end
    wire        ale_q = bus_q[11];
    wire        rd_q  = bus_q[10] & bus_q[9];   // RD with chip select
    wire        wr_q  = bus_q[10] & bus_q[8];   // WR with chip select
    wire [7:0]  ad_q  = bus_q[7:0];

    reg         rd_d, wr_d;     // strobes one clk ago
    reg  [7:0]  adr;            // latched address (last clk with ALE high)
    reg  [7:0]  wdat;           // write data (last clk with WR high)
    reg         rd_pend, wr_pend;
    reg  [7:0]  wr_adr;
    reg         busy, busy_we;
    reg  [7:0]  busy_adr, busy_dat;
    reg  [7:0]  rdata;
    reg         rvalid;
    wire        ack;
    wire [7:0]  wb_rdat;

    always @(posedge clk_i) begin
        if (rst_i) begin
            rd_d <= 1'b0; wr_d <= 1'b0; adr <= 8'h00; wdat <= 8'h00;
            rd_pend <= 1'b0; wr_pend <= 1'b0; wr_adr <= 8'h00;
            busy <= 1'b0; busy_we <= 1'b0; busy_adr <= 8'h00; busy_dat <= 8'h00;
            rdata <= 8'h00; rvalid <= 1'b0;
        end else begin
            rd_d <= rd_q;
            wr_d <= wr_q;
            if (ale_q) adr <= ad_q;
            if (wr_q) wdat <= ad_q;
            // a strobe starts a read, the end of WR a write
            if (rd_q && !rd_d) begin
                rd_pend <= 1'b1;
                rvalid  <= 1'b0;
            end
            if (!rd_q) rvalid <= 1'b0;
            if (!wr_q && wr_d) begin
                wr_pend <= 1'b1;
                wr_adr  <= adr;
            end
            // one Wishbone access at a time; writes first (they are older)
            if (busy) begin
                if (ack) begin
                    busy <= 1'b0;
                    if (!busy_we) begin
                        rdata  <= wb_rdat;
                        // a read whose strobe already ended is dropped
                        rvalid <= rd_q;
                    end
                end
            end else if (wr_pend) begin
                busy <= 1'b1; busy_we <= 1'b1; busy_adr <= wr_adr; busy_dat <= wdat;
                wr_pend <= 1'b0;
            end else if (rd_pend) begin
                busy <= 1'b1; busy_we <= 1'b0; busy_adr <= adr;
                rd_pend <= 1'b0;
            end
        end
    end

    // the port floats the moment RD or CS falls, as on the chip
    assign port_0_oe = cs_can_i & rd_i & rvalid;
    assign port_0_o  = rdata;

    can_top #(.RX_SYNC(RX_SYNC)) u_can (
        .wb_clk_i(clk_i), .wb_rst_i(rst_i),
        .wb_dat_i(busy_dat), .wb_dat_o(wb_rdat),
        .wb_cyc_i(busy), .wb_stb_i(busy), .wb_we_i(busy_we), .wb_adr_i(busy_adr),
        .wb_ack_o(ack),
        .clk_i(clk_i), .rx_i(rx_i), .tx_o(tx_o),
        .bus_off_on(bus_off_on), .irq_on(irq_on), .clkout_o(clkout_o)
    );
endmodule
