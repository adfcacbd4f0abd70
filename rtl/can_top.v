// SJA1000-compatible CAN 2.0A/B controller, Wishbone slave.
// Same top-level name and port list as the opencores can_top Wishbone
// variant. Two clock domains: wb_clk_i (host) and clk_i (CAN, the SJA1000
// oscillator); see can_wb_cdc for the crossing and its ack latency.
//   irq_on     active low: low while an enabled interrupt is pending
//   bus_off_on high while on the bus, low while bus-off
//   tx_o/rx_i  1 = recessive
module can_top #(
    // 1: wb_ack_o stays high until cyc&stb fall (for GPIO-polled masters),
    // see can_wb_cdc; 0 (default): classic one-cycle ack pulse
    parameter ACK_LEVEL = 0,
    // clk_i flops in front of rx_i: 0 (default) for co-simulation, where
    // rx_i changes on clk_i edges; 2 on hardware with an asynchronous
    // transceiver input (adds 2 clk_i of loop delay)
    parameter RX_SYNC = 0
) (
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
    wire        rst;
    wire        acc_stb, acc_we;
    wire [7:0]  acc_adr, acc_wdat, acc_rdat;

    can_wb_cdc #(.ACK_LEVEL(ACK_LEVEL)) u_cdc (
        .wb_clk_i(wb_clk_i), .wb_rst_i(wb_rst_i), .wb_dat_i(wb_dat_i), .wb_dat_o(wb_dat_o),
        .wb_cyc_i(wb_cyc_i), .wb_stb_i(wb_stb_i), .wb_we_i(wb_we_i), .wb_adr_i(wb_adr_i),
        .wb_ack_o(wb_ack_o), .clk_i(clk_i), .rst_o(rst), .acc_stb(acc_stb), .acc_we(acc_we),
        .acc_adr(acc_adr), .acc_wdat(acc_wdat), .acc_rdat(acc_rdat)
    );

    // configuration and status
    wire        rm, peli, lom, stm, afm, sleep;
    wire [7:0]  btr0, btr1, ewlr;
    wire [31:0] acr, amr;
    wire        tx_ide, tx_rtr;
    wire [3:0]  tx_dlc;
    wire [28:0] tx_id;
    wire [63:0] tx_data;
    wire        tx_req, tx_single, tx_self, tx_abort;
    wire        rrb, cdo, rbsa_wr;
    wire        fifo_rd;
    wire [7:0]  fifo_q;
    wire [5:0]  fifo_adr, rbsa;
    wire [6:0]  rmc;
    wire        rbs, dos, dos_set, fifo_wr;
    wire        tx_done, tx_drop, alc_evt, err_evt;
    wire        tx_done_st, fifo_busy, fifo_commit;
    wire [4:0]  alc_val;
    wire [7:0]  ecc_val;
    wire        rs, ts, bus_idle, integrating;
    wire [7:0]  tec, rec;
    wire        bus_off, passive, warn, epi_evt, wr_tec, wr_rec;
    wire        irq;
    wire        clkout_div, clkout_fosc;
    wire        tec_add8, tec_sub1, rec_add1, rec_add8, rec_sub1, recov_tick;
    wire        sample, rx_bit, tx_next, hard_en;
    wire [28:0] rx_id;
    wire        rx_ide, rx_rtr, rx_valid;
    wire [3:0]  rx_dlc;
    wire [63:0] rx_data;
    wire        accept;
    wire        run = !rm && !sleep;

    // optional synchroniser for rx_i
    wire        rx;
    generate
        if (RX_SYNC == 1) begin : g_rx_sync1
            reg rx_q = 1'b1;
            always @(posedge clk_i) rx_q <= rx_i;
            assign rx = rx_q;
        end else if (RX_SYNC > 1) begin : g_rx_sync
            reg [RX_SYNC-1:0] rx_q = {RX_SYNC{1'b1}};
            always @(posedge clk_i) rx_q <= {rx_q[RX_SYNC-2:0], rx_i};
            assign rx = rx_q[RX_SYNC-1];
        end else begin : g_rx_direct
            assign rx = rx_i;
        end
    endgenerate

    can_regs u_regs (
        .clk(clk_i), .rst(rst),
        .acc_stb(acc_stb), .acc_we(acc_we), .acc_adr(acc_adr), .acc_wdat(acc_wdat), .acc_rdat(acc_rdat),
        .rm(rm), .peli(peli), .lom(lom), .stm(stm), .afm(afm), .sleep(sleep),
        .btr0(btr0), .btr1(btr1), .ewlr(ewlr), .acr(acr), .amr(amr),
        .tx_ide(tx_ide), .tx_rtr(tx_rtr), .tx_dlc(tx_dlc), .tx_id(tx_id), .tx_data(tx_data),
        .tx_req(tx_req), .tx_single(tx_single), .tx_self(tx_self), .tx_abort(tx_abort),
        .rrb(rrb), .cdo(cdo), .rbsa_wr(rbsa_wr), .fifo_rd(fifo_rd), .fifo_adr(fifo_adr),
        .fifo_q(fifo_q), .rmc(rmc), .rbsa(rbsa), .rbs(rbs), .dos(dos),
        .dos_set(dos_set), .fifo_wr(fifo_wr),
        .tx_done(tx_done_st), .tx_drop(tx_drop), .alc_evt(alc_evt), .alc_val(alc_val),
        .err_evt(err_evt), .ecc_val(ecc_val), .rs(rs), .ts(ts), .bus_idle(bus_idle),
        .integrating(integrating),
        .tec(tec), .rec(rec), .bus_off(bus_off), .warn(warn), .epi_evt(epi_evt),
        .wr_tec(wr_tec), .wr_rec(wr_rec), .rx_i(rx), .irq(irq), .clkout(clkout_div),
        .clkout_fosc(clkout_fosc)
    );

    can_btl u_btl (
        .clk(clk_i), .rst(rst), .run(run),
        .brp(btr0[5:0]), .sjw(btr0[7:6]), .tseg1(btr1[3:0]), .tseg2(btr1[6:4]), .sam(btr1[7]),
        .rx(rx), .hard_en(hard_en), .tx_next(tx_next),
        .sample(sample), .rx_bit(rx_bit), .tx_o(tx_o)
    );

    can_bsp u_bsp (
        .clk(clk_i), .rst(rst), .rm(rm), .run(run), .sample(sample), .rx(rx_bit), .tx_cur(tx_o),
        .lom(lom), .stm(stm), .passive(passive), .bus_off(bus_off),
        .tx_ide(tx_ide), .tx_rtr(tx_rtr), .tx_dlc(tx_dlc), .tx_id(tx_id), .tx_data(tx_data),
        .tx_req(tx_req), .tx_single(tx_single), .tx_self(tx_self), .tx_abort(tx_abort),
        .tx_next(tx_next), .hard_en(hard_en),
        .rx_id(rx_id), .rx_ide(rx_ide), .rx_rtr(rx_rtr), .rx_dlc(rx_dlc), .rx_data(rx_data),
        .rx_valid(rx_valid), .tx_done(tx_done), .tx_drop(tx_drop),
        .alc_evt(alc_evt), .alc_val(alc_val), .err_evt(err_evt), .ecc_val(ecc_val),
        .tec_add8(tec_add8), .tec_sub1(tec_sub1), .rec_add1(rec_add1), .rec_add8(rec_add8),
        .rec_sub1(rec_sub1), .recov_tick(recov_tick),
        .rs(rs), .ts(ts), .bus_idle(bus_idle), .integrating(integrating)
    );

    can_fce u_fce (
        .clk(clk_i), .rst(rst), .freeze(lom), .hold(rm),
        .tec_add8(tec_add8), .tec_sub1(tec_sub1), .rec_add1(rec_add1), .rec_add8(rec_add8),
        .rec_sub1(rec_sub1), .recov_tick(recov_tick),
        .wr_tec(wr_tec), .wr_rec(wr_rec), .wdat(acc_wdat), .ewl(ewlr),
        .tec(tec), .rec(rec), .bus_off(bus_off), .passive(passive), .warn(warn), .epi_evt(epi_evt)
    );

    can_acf u_acf (
        .peli(peli), .afm(afm), .acr(acr), .amr(amr), .id(rx_id), .ide(rx_ide), .rtr(rx_rtr),
        .dlc(rx_dlc), .data12(rx_data[63:48]), .accept(accept)
    );

    can_rxfifo u_fifo (
        .clk(clk_i), .rst(rst), .clr(rm), .peli(peli),
        .store(rx_valid && accept),
        .id(rx_id), .ide(rx_ide), .rtr(rx_rtr), .dlc(rx_dlc), .data(rx_data),
        .rrb(rrb), .cdo(cdo), .rbsa_wr(rbsa_wr), .wdat(acc_wdat),
        .host_wr(fifo_wr), .host_rd(fifo_rd), .host_adr(fifo_adr), .rd_q(fifo_q),
        .rmc(rmc), .rbsa(rbsa), .rbs(rbs), .dos(dos), .dos_set(dos_set),
        .wbusy_o(fifo_busy), .commit_o(fifo_commit)
    );

    // Self reception: the transmission succeeds and the own frame is stored
    // at the same bit (end of EOF), so TBS/TCS/TI change together with RBS
    // (SR is one snapshot of one event: a host never sees the transmission
    // complete while its self-received copy is still missing). The FIFO
    // copies the message one byte per clk, so tx_done waits for its commit.
    reg tx_done_wait;
    wire self_store = tx_done && rx_valid && accept;
    assign tx_done_st = (tx_done && !self_store) || (tx_done_wait && (fifo_commit || !fifo_busy));
    always @(posedge clk_i) begin
        if (rst) tx_done_wait <= 1'b0;
        else if (self_store) tx_done_wait <= 1'b1;
        else if (fifo_commit || !fifo_busy) tx_done_wait <= 1'b0;
    end

    // CLKOUT: the divided clock, or clk_i itself when CDR selects fosc
    // (a clock multiplexer; the switch may glitch, as on the SJA1000 when
    // CDR is rewritten)
    assign clkout_o   = clkout_fosc ? clk_i : clkout_div;
    assign bus_off_on = !bus_off;
    assign irq_on     = !irq;
endmodule
