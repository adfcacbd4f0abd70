// AXI4-Lite slave wrapper around can_top: one 8-bit register per 32-bit
// word (register n at byte 4n, data in bits 7:0), as Zynq designs map it.
//
// One access at a time. A write starts when AWVALID and WVALID are both
// high (in either order: the slave waits for both before raising either
// READY, which AXI allows), a read when ARVALID is high, in each case only
// while no response of the same kind is still waiting. The choice is
// locked (cur_*) from the first cycle the access is on can_top's Wishbone
// port until its ack, so a request arriving on the other channel
// meanwhile waits. AWREADY and WREADY (or ARREADY) are can_top's one-cycle
// wb_ack_o; BVALID (or RVALID with the byte in RDATA[7:0]) is registered
// from it and held until BREADY (RREADY). Responses are OKAY. WSTRB,
// AWPROT and ARPROT are not used. irq_on is active low, as on can_top.
module can_axi4lite #(
    parameter RX_SYNC = 0      // see can_top: 2 on hardware, 0 in co-simulation
) (
    input  wire        s_axi_aclk,
    input  wire        s_axi_aresetn,
    input  wire [31:0] s_axi_awaddr,
    input  wire [2:0]  s_axi_awprot,
    input  wire        s_axi_awvalid,
    output wire        s_axi_awready,
    input  wire [31:0] s_axi_wdata,
    input  wire [3:0]  s_axi_wstrb,
    input  wire        s_axi_wvalid,
    output wire        s_axi_wready,
    output reg  [1:0]  s_axi_bresp,
    output reg         s_axi_bvalid,
    input  wire        s_axi_bready,
    input  wire [31:0] s_axi_araddr,
    input  wire [2:0]  s_axi_arprot,
    input  wire        s_axi_arvalid,
    output wire        s_axi_arready,
    output reg  [31:0] s_axi_rdata,
    output reg  [1:0]  s_axi_rresp,
    output reg         s_axi_rvalid,
    input  wire        s_axi_rready,
    input  wire        clk_i,
    input  wire        rx_i,
    output wire        tx_o,
    output wire        bus_off_on,
    output wire        irq_on,
    output wire        clkout_o
);
    reg        cur_wr, cur_rd;     // access on the Wishbone port, locked
    wire       wr_ok = s_axi_awvalid & s_axi_wvalid & ~s_axi_bvalid;
    wire       rd_ok = s_axi_arvalid & ~s_axi_rvalid;
    wire       idle  = ~cur_wr & ~cur_rd;
    wire       sel_wr = cur_wr | (idle & wr_ok);
    wire       sel_rd = cur_rd | (idle & ~wr_ok & rd_ok);
    wire       req = sel_wr | sel_rd;
    wire       ack;
    wire [7:0] rdat;

    can_top #(.RX_SYNC(RX_SYNC)) u_can (
        .wb_clk_i(s_axi_aclk), .wb_rst_i(~s_axi_aresetn),
        .wb_dat_i(s_axi_wdata[7:0]), .wb_dat_o(rdat),
        .wb_cyc_i(req), .wb_stb_i(req), .wb_we_i(sel_wr),
        .wb_adr_i(sel_wr ? s_axi_awaddr[9:2] : s_axi_araddr[9:2]),
        .wb_ack_o(ack),
        .clk_i(clk_i), .rx_i(rx_i), .tx_o(tx_o),
        .bus_off_on(bus_off_on), .irq_on(irq_on), .clkout_o(clkout_o)
    );

    assign s_axi_awready = ack & sel_wr;
    assign s_axi_wready  = ack & sel_wr;
    assign s_axi_arready = ack & sel_rd;

    always @(posedge s_axi_aclk) begin
        if (!s_axi_aresetn) begin
            cur_wr <= 1'b0; cur_rd <= 1'b0;
            s_axi_bvalid <= 1'b0; s_axi_bresp <= 2'b00;
            s_axi_rvalid <= 1'b0; s_axi_rresp <= 2'b00; s_axi_rdata <= 32'h0;
        end else begin
            if (s_axi_bvalid & s_axi_bready) s_axi_bvalid <= 1'b0;
            if (s_axi_rvalid & s_axi_rready) s_axi_rvalid <= 1'b0;
            if (ack) begin
                cur_wr <= 1'b0; cur_rd <= 1'b0;
                if (sel_wr) s_axi_bvalid <= 1'b1;
                if (sel_rd) begin
                    s_axi_rvalid <= 1'b1;
                    s_axi_rdata  <= {24'h000000, rdat};
                end
            end else begin
                cur_wr <= sel_wr;
                cur_rd <= sel_rd;
            end
        end
    end

    wire unused = &{1'b0, s_axi_awprot, s_axi_arprot, s_axi_wstrb, s_axi_awaddr[31:10],
                    s_axi_awaddr[1:0], s_axi_araddr[31:10], s_axi_araddr[1:0], s_axi_wdata[31:8]};
endmodule
