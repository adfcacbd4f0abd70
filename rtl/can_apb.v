// APB completer (AMBA APB, APB3 and APB4) wrapper around can_top: one
// 8-bit register per 32-bit word (register n at byte 4n, data in bits
// 7:0), as Linux's sja1000 platform binding calls reg-io-width = 4.
//
// The Wishbone cycle is the access phase (psel & penable), which the APB
// requester holds, with paddr, pwrite and pwdata, until pready; pready is
// can_top's one-cycle wb_ack_o and prdata its registered wb_dat_o, valid
// in that cycle. pslverr is never raised (every address decodes to a
// register). pstrb and pprot (APB4) are accepted and not used: a register
// is one byte, written whole. irq_on is active low, as on can_top.
module can_apb #(
    parameter RX_SYNC = 0      // see can_top: 2 on hardware, 0 in co-simulation
) (
    input  wire        pclk,
    input  wire        presetn,
    input  wire        psel,
    input  wire        penable,
    input  wire        pwrite,
    input  wire [31:0] paddr,
    input  wire [31:0] pwdata,
    input  wire [3:0]  pstrb,
    input  wire [2:0]  pprot,
    output wire [31:0] prdata,
    output wire        pready,
    output wire        pslverr,
    input  wire        clk_i,
    input  wire        rx_i,
    output wire        tx_o,
    output wire        bus_off_on,
    output wire        irq_on,
    output wire        clkout_o
);
    wire       req = psel & penable;
    wire       ack;
    wire [7:0] rdat;

    can_top #(.RX_SYNC(RX_SYNC)) u_can (
        .wb_clk_i(pclk), .wb_rst_i(~presetn),
        .wb_dat_i(pwdata[7:0]), .wb_dat_o(rdat),
        .wb_cyc_i(req), .wb_stb_i(req), .wb_we_i(pwrite), .wb_adr_i(paddr[9:2]),
        .wb_ack_o(ack),
        .clk_i(clk_i), .rx_i(rx_i), .tx_o(tx_o),
        .bus_off_on(bus_off_on), .irq_on(irq_on), .clkout_o(clkout_o)
    );

    assign pready  = ack;
    assign prdata  = {24'h000000, rdat};
    assign pslverr = 1'b0;

    // pstrb, pprot, paddr[1:0] and paddr[31:10] are not decoded.
    wire unused = &{1'b0, pstrb, pprot, paddr[31:10], paddr[1:0], pwdata[31:8]};
endmodule
