// A plain single-clock register port around can_top, as forks of the core
// expose it: a write strobe with its address and data, a read strobe with
// its address (separate addresses; tie them for a one-address port), and
// the read data, with no acknowledge.
//
// Everything runs on clk_i, the CAN clock (can_top's host side is clocked
// by it too, so no clock-domain crossing is left to the host). The
// Wishbone request is combinational from a strobe and held by a register
// until can_top's ack, so a one-clock strobe is enough; rdat_o is
// registered from the ack and held until the next read: it is valid a
// fixed number of clocks after the read strobe (can_top's ack latency at
// one clock: 10, 14 for the first access after reset, measured in
// co-simulation), and the host must leave an access that long before its
// next strobe. A strobe while
// an access is still held is ignored. irq_on is active low, as on can_top.
module can_regport #(
    parameter RX_SYNC = 0      // see can_top: 2 on hardware, 0 in co-simulation
) (
    input  wire       rst_i,
    input  wire       clk_i,
    input  wire       wr_i,
    input  wire [7:0] wr_adr_i,
    input  wire [7:0] wdat_i,
    input  wire       rd_i,
    input  wire [7:0] rd_adr_i,
    output reg  [7:0] rdat_o,
    input  wire       rx_i,
    output wire       tx_o,
    output wire       bus_off_on,
    output wire       irq_on,
    output wire       clkout_o
);
    reg        busy, busy_we;
    reg  [7:0] busy_adr, busy_dat;
    wire       ack;
    wire [7:0] wb_rdat;

    wire       req = busy | wr_i | rd_i;
    wire       we  = busy ? busy_we  : wr_i;
    wire [7:0] adr = busy ? busy_adr : (wr_i ? wr_adr_i : rd_adr_i);
    wire [7:0] dat = busy ? busy_dat : wdat_i;

    always @(posedge clk_i) begin
        if (rst_i) begin
            busy <= 1'b0; busy_we <= 1'b0; busy_adr <= 8'h00; busy_dat <= 8'h00;
            rdat_o <= 8'h00;
        end else if (req) begin
            busy     <= ~ack;
            busy_we  <= we;
            busy_adr <= adr;
            busy_dat <= dat;
            if (ack && !we) rdat_o <= wb_rdat;
        end
    end

    can_top #(.RX_SYNC(RX_SYNC)) u_can (
        .wb_clk_i(clk_i), .wb_rst_i(rst_i),
        .wb_dat_i(dat), .wb_dat_o(wb_rdat),
        .wb_cyc_i(req), .wb_stb_i(req), .wb_we_i(we), .wb_adr_i(adr),
        .wb_ack_o(ack),
        .clk_i(clk_i), .rx_i(rx_i), .tx_o(tx_o),
        .bus_off_on(bus_off_on), .irq_on(irq_on), .clkout_o(clkout_o)
    );
endmodule
