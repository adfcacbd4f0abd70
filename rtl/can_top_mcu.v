// can_top with the SJA1000 chip's two multiplexed host modes, chosen by the
// mode_i pin as the chip's MODE pin chooses them (written from the
// datasheet's description of the two modes):
//   - mode_i = 1, Intel: the address on AD7..AD0 while ALE is high, then
//     one RD or WR strobe with the chip selected moves the byte;
//   - mode_i = 0, Motorola: the address on AD7..AD0 while AS is high, then
//     one E strobe with the chip selected moves the byte, its direction
//     given by R/W (high = read), set before E rises and held until after
//     E falls.
// Both are decoded into the Intel strobes (Motorola: RD = E & R/W,
// WR = E & !R/W) and handled by can_top_8051, so they share its timing:
// every pin sampled with clk_i through two flops, each phase held at least
// 3 clk_i, a read answered about 15 clk_i after the strobe rises, a write
// taken when the strobe falls (see rtl/can_top_8051.v).
// Differences from the chip, on purpose: active-high strobes (cs_can_i,
// ale_as_i, rd_e_i; the chip's /CS, /RD, /WR are low), and the AD bus split
// into port_0_i / port_0_o / port_0_oe. mode_i is a static strap.
module can_top_mcu #(
    parameter RX_SYNC = 0      // see can_top: 2 on hardware, 0 in co-simulation
) (
    input  wire       rst_i,
    input  wire       clk_i,
    input  wire       mode_i,     // 1 = Intel (8051), 0 = Motorola
    input  wire       ale_as_i,   // ALE / AS
    input  wire       cs_can_i,
    input  wire       rd_e_i,     // RD / E
    input  wire       wr_rw_i,    // WR / R/W (high = read)
    input  wire [7:0] port_0_i,
    output wire [7:0] port_0_o,
    output wire       port_0_oe,
    input  wire       rx_i,
    output wire       tx_o,
    output wire       bus_off_on,
    output wire       irq_on,
    output wire       clkout_o
);
    wire rd = mode_i ? rd_e_i  : (rd_e_i &  wr_rw_i);
    wire wr = mode_i ? wr_rw_i : (rd_e_i & ~wr_rw_i);

    can_top_8051 #(.RX_SYNC(RX_SYNC)) u_mcu (
        .rst_i(rst_i), .clk_i(clk_i),
        .ale_i(ale_as_i), .cs_can_i(cs_can_i), .rd_i(rd), .wr_i(wr),
        .port_0_i(port_0_i), .port_0_o(port_0_o), .port_0_oe(port_0_oe),
        .rx_i(rx_i), .tx_o(tx_o),
        .bus_off_on(bus_off_on), .irq_on(irq_on), .clkout_o(clkout_o)
    );
endmodule
