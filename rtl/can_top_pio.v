// can_top for hosts that bit-bang the Wishbone pins through GPIO (the DE2
// thesis wiring: a Nios II writes cyc/stb/we through a PIO and polls ack
// through another). Such a host samples ack every few cycles and would miss
// a one-cycle pulse, so this variant holds wb_ack_o until cyc&stb fall
// (four-phase handshake, ACK_LEVEL = 1) and runs one access per strobe.
// Same port list as can_top; use can_top itself on a real Wishbone bus.
module can_top_pio (
    input  wire       wb_clk_i,
    input  wire       wb_rst_i,
    input  wire [7:0] wb_dat_i,
    output wire [7:0] wb_dat_o,
    input  wire       wb_cyc_i,
    input  wire       wb_stb_i,
    input  wire       wb_we_i,
    input  wire [7:0] wb_adr_i,
    output wire       wb_ack_o,
    input  wire       clk_i,
    input  wire       rx_i,
    output wire       tx_o,
    output wire       bus_off_on,
    output wire       irq_on,
    output wire       clkout_o
);
    can_top #(.ACK_LEVEL(1)) u_can (
        .wb_clk_i(wb_clk_i), .wb_rst_i(wb_rst_i), .wb_dat_i(wb_dat_i),
        .wb_dat_o(wb_dat_o), .wb_cyc_i(wb_cyc_i), .wb_stb_i(wb_stb_i),
        .wb_we_i(wb_we_i), .wb_adr_i(wb_adr_i), .wb_ack_o(wb_ack_o),
        .clk_i(clk_i), .rx_i(rx_i), .tx_o(tx_o), .bus_off_on(bus_off_on),
        .irq_on(irq_on), .clkout_o(clkout_o)
    );
endmodule
