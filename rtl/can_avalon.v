// Avalon-MM slave wrapper around can_top, for Platform Designer (one
// 8-bit register per word address, native addressing, variable wait).
//
// The Wishbone cycle is driven from chipselect & (read | write), which the
// Avalon master holds, with address and writedata, for the whole transfer
// while waitrequest is high; waitrequest stays high until can_top's
// wb_ack_o (one cycle), and readdata (can_top's registered wb_dat_o) is
// valid in that cycle. Unlike seed 000's wiring, wb_cyc_i is not taken from
// begintransfer (high for one cycle only) and the ack is not left on a
// conduit: it ends the Avalon transfer through waitrequest.
// irq is active high for the Nios II interrupt controller.
module can_avalon #(
    parameter RX_SYNC = 0      // see can_top: 2 on hardware, 0 in co-simulation
) (
    input  wire       clk,
    input  wire       reset,
    input  wire [7:0] address,
    input  wire       chipselect,
    input  wire       read,
    input  wire       write,
    input  wire [7:0] writedata,
    output wire [7:0] readdata,
    output wire       waitrequest,
    output wire       irq,
    input  wire       can_clk,
    input  wire       rx,
    output wire       tx,
    output wire       bus_off_on,
    output wire       clkout
);
    wire req = chipselect & (read | write);
    wire ack;
    wire irq_n;

    can_top #(.RX_SYNC(RX_SYNC)) u_can (
        .wb_clk_i(clk), .wb_rst_i(reset),
        .wb_dat_i(writedata), .wb_dat_o(readdata),
        .wb_cyc_i(req), .wb_stb_i(req), .wb_we_i(write), .wb_adr_i(address),
        .wb_ack_o(ack),
        .clk_i(can_clk), .rx_i(rx), .tx_o(tx),
        .bus_off_on(bus_off_on), .irq_on(irq_n), .clkout_o(clkout)
    );

    // high (stall) in every cycle except the one that completes the transfer
    assign waitrequest = ~ack;
    assign irq = ~irq_n;
endmodule
