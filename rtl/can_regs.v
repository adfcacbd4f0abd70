// SJA1000 register file (clk_i domain): BasicCAN and PeliCAN views, reset
// vs operating mode access rules, commands, status, interrupts (IR/IER,
// read-to-clear), ALC/ECC capture, TX buffer, acceptance code/mask, sleep,
// and the CLKOUT divider (CDR). Addresses come from sja1000_addr.vh.
module can_regs (
    input  wire        clk,
    input  wire        rst,
    // register access (one clk pulse, from can_wb_cdc)
    input  wire        acc_stb,
    input  wire        acc_we,
    // BasicCAN decodes A4..A0 (32..255 mirror 0..31), PeliCAN A6..A0
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [7:0]  acc_adr,
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire [7:0]  acc_wdat,
    output wire [7:0]  acc_rdat,    // valid one clk after acc_stb
    // configuration
    output reg         rm,          // reset mode (MOD.RM / CR.RR)
    output wire        peli,        // CDR.7
    output reg         lom,
    output reg         stm,
    output reg         afm,
    output reg         sleep,
    output reg  [7:0]  btr0,
    output reg  [7:0]  btr1,
    output reg  [7:0]  ewlr,
    output wire [31:0] acr,
    output wire [31:0] amr,
    // TX buffer decoded for the BSP
    output wire        tx_ide,
    output wire        tx_rtr,
    output wire [3:0]  tx_dlc,
    output wire [28:0] tx_id,
    output wire [63:0] tx_data,
    output reg         tx_req,
    output reg         tx_single,
    output reg         tx_self,
    output reg         tx_abort,
    // RX FIFO
    output reg         rrb,
    output reg         cdo,
    output wire        rbsa_wr,
    output wire        fifo_wr,     // host write of the RX FIFO RAM (PeliCAN, reset mode)
    output wire        fifo_rd,     // this read targets the RX FIFO RAM
    output wire [5:0]  fifo_adr,
    input  wire [7:0]  fifo_q,      // RAM data, one clk after fifo_rd
    input  wire [6:0]  rmc,
    input  wire [5:0]  rbsa,
    input  wire        rbs,
    input  wire        dos,
    input  wire        dos_set,
    // from the protocol engine
    input  wire        tx_done,
    input  wire        tx_drop,
    input  wire        alc_evt,
    input  wire [4:0]  alc_val,
    input  wire        err_evt,
    input  wire [7:0]  ecc_val,
    input  wire        rs,
    input  wire        ts,
    input  wire        bus_idle,
    input  wire        integrating,
    input  wire [7:0]  tec,
    input  wire [7:0]  rec,
    input  wire        bus_off,
    input  wire        warn,
    input  wire        epi_evt,
    output wire        wr_tec,
    output wire        wr_rec,
    input  wire        rx_i,        // raw bus level, for wake-up
    output wire        irq,
    output reg         clkout,
    output wire        clkout_fosc  // CDR selects fosc: can_top outputs clk_i itself
);
    // the include lists the whole register map; not every address is used here
    /* verilator lint_off UNUSEDPARAM */
`include "sja1000_addr.vh"
    /* verilator lint_on UNUSEDPARAM */

    reg  [7:0] cdr;
    reg  [7:0] ocr;
    reg  [7:0] ier;            // PeliCAN IER; BasicCAN CR.1-4 map to bits 0-3
    reg        cr6;            // BasicCAN CR.6 (former SYNC bit), value reflected
    reg  [7:0] ir;             // bit 0 used in BasicCAN only (PeliCAN RI is live)
    reg  [7:0] alc, ecc;
    reg        alc_arm, ecc_arm;
    reg        tbs, tcs;
    reg  [7:0] acr_r [0:3];
    reg  [7:0] amr_r [0:3];
    reg  [7:0] txb [0:12];
    reg        bus_off_q, warn_q;
    reg        rm_q;
    reg  [7:0] test;           // test register: read/write, no function
    reg  [7:0] ramfree [0:2];  // PeliCAN 109..111: free internal RAM

    assign peli = cdr[7];
    assign acr  = {acr_r[0], acr_r[1], acr_r[2], acr_r[3]};
    assign amr  = {amr_r[0], amr_r[1], amr_r[2], amr_r[3]};

    // ---- TX buffer decode ----
    // BasicCAN: txb[0] = ID.10..3, txb[1] = ID.2..0 RTR DLC, txb[2..9] data.
    // PeliCAN:  txb[0] = frame info (FF RTR x x DLC), ID bytes, data.
    assign tx_ide  = peli & txb[0][7];
    assign tx_rtr  = peli ? txb[0][6] : txb[1][4];
    assign tx_dlc  = peli ? txb[0][3:0] : txb[1][3:0];
    assign tx_id   = !peli ? {txb[0], txb[1][7:5], 18'd0} :
                     tx_ide ? {txb[1], txb[2], txb[3], txb[4][7:3]} :
                              {txb[1], txb[2][7:5], 18'd0};
    assign tx_data = !peli ? {txb[2], txb[3], txb[4], txb[5], txb[6], txb[7], txb[8], txb[9]} :
                     tx_ide ? {txb[5], txb[6], txb[7], txb[8], txb[9], txb[10], txb[11], txb[12]} :
                              {txb[3], txb[4], txb[5], txb[6], txb[7], txb[8], txb[9], txb[10]};

    // ---- address decode ----
    // addresses outside the view (BasicCAN 32..255, PeliCAN 128..255) read
    // 00h and ignore writes, as in the register map
    wire [7:0] a  = acc_adr;
    wire       in_view = peli ? !acc_adr[7] : (acc_adr[7:5] == 3'b000);
    wire       wr = acc_stb &  acc_we & in_view;
    wire       rd = acc_stb & ~acc_we & in_view;
    wire       in_win_p = (a >= PC_RXB) && (a < PC_RXB + PC_BUF_LEN);
    wire       in_win_b = (a >= BC_RXB) && (a < BC_RXB + BC_RXB_LEN);
    wire [3:0] tx_ofs_b = a[3:0] - BC_TXB[3:0];   // BasicCAN TX buffer byte 0..9 (mod 16)
    wire [3:0] win_idx = peli ? (a[3:0] - PC_RXB[3:0]) : (a[3:0] - BC_RXB[3:0]);
    wire       in_ram  = (a >= PC_RXFIFO) && (a < PC_RXFIFO + PC_RXFIFO_LEN);
    wire       rd_win  = peli ? (in_win_p && !rm) : in_win_b;
    assign fifo_rd  = rd && (rd_win || (peli && in_ram));
    assign fifo_wr  = wr && peli && rm && in_ram;
    assign fifo_adr = rd_win ? (rbsa + {2'b00, win_idx}) : (a[5:0] - PC_RXFIFO[5:0]);

    // read data: registers are captured at the access strobe (the same clk
    // as read side effects such as the IR clear), RAM data comes one clk later
    reg  [7:0] rdat;
    reg  [7:0] rdat_q;
    reg        fifo_sel_q;
    always @(posedge clk) begin
        if (acc_stb) begin
            rdat_q     <= rdat;
            fifo_sel_q <= fifo_rd;
        end
    end
    assign acc_rdat = fifo_sel_q ? fifo_q : rdat_q;
    assign rbsa_wr = wr && peli && rm && a == PC_RBSA;
    assign wr_tec  = wr && peli && rm && a == PC_TXERR;
    assign wr_rec  = wr && peli && rm && a == PC_RXERR;

    // RI follows RBS (while RIE is set) in both views; a read never clears it
    wire ri_live = rbs & ier[0];
    wire [7:0] ir_view = peli ? {ir[7:1], ri_live} : {3'b111, ir[4:1], ri_live};
    assign irq = peli ? ((|ir[7:1]) | ri_live) : ((|ir[4:1]) | ri_live);

    // reset mode: PeliCAN shows RS = TS = 1 (waiting for bus-free), BasicCAN 0
    // TS/RS keep their reset-mode value (PeliCAN 1, BasicCAN 0) until bus-free
    // is seen after reset mode or sleep ("wait idle")
    // While bus-off (in reset mode or counting the recovery) the node is
    // also waiting to become idle: datasheet SR note 3, after bus-off idle
    // takes 128 x 11 recessive bits. This covers the clk in which BS rises
    // before MOD.RM follows (one SR snapshot: BS = 1 with TS = 1, RS = 0
    // never shows).
    wire       wait_idle = rm || integrating || bus_off;
    // bus-off releases the TX buffer at the same instant BS rises (one SR
    // snapshot: BS = 1 with TBS = 0 never shows)
    wire       tbs_sr = tbs | (bus_off & ~bus_off_q);
    wire [7:0] sr = {bus_off, warn, wait_idle ? peli : ts, wait_idle ? peli : rs, tcs, tbs_sr, dos, rbs};

    // ---- read mux ----
    always @* begin
        rdat = 8'h00;
        if (peli) begin
            case (a)
                PC_MOD:   rdat = {3'b000, sleep, afm, stm, lom, rm};
                PC_CMR:   rdat = 8'h00;
                PC_SR:    rdat = sr;
                PC_IR:    rdat = ir_view;
                PC_IER:   rdat = ier;
                PC_BTR0:  rdat = btr0;
                PC_BTR1:  rdat = btr1;
                PC_OCR:   rdat = ocr;
                PC_ALC:   rdat = alc;
                PC_ECC:   rdat = ecc;
                PC_EWLR:  rdat = ewlr;
                PC_RXERR: rdat = rec;
                PC_TXERR: rdat = tec;
                PC_RMC:   rdat = {1'b0, rmc};
                PC_RBSA:  rdat = {2'b00, rbsa};
                PC_CDR:   rdat = cdr;             // CDR.4 is always written 0
                PC_TEST:  rdat = test;
                default: begin
                    // RX window (operating mode) and RAM: data from the FIFO RAM
                    if (in_win_p && rm) begin
                        if (a < PC_AMR0) rdat = acr_r[a[1:0]];
                        else if (a < PC_AMR0 + 8'd4) rdat = amr_r[a[1:0]];
                    end else if (a >= PC_TXRAM && a < PC_TXRAM + PC_BUF_LEN) begin
                        rdat = txb[a[3:0]];
                    end else if (a >= PC_TXRAM + PC_BUF_LEN && a < PC_TXRAM + PC_BUF_LEN + 8'd3) begin
                        rdat = ramfree[a[1:0] - 2'd1];   // 109..111
                    end
                end
            endcase
        end else begin
            case (a)
                BC_CR:   rdat = {1'b0, cr6, 1'b1, ier[3:0], rm};
                BC_CMR:  rdat = 8'hFF;
                BC_SR:   rdat = sr;
                BC_IR:   rdat = ir_view;
                BC_ACR:  rdat = rm ? acr_r[0] : 8'hFF;
                BC_AMR:  rdat = rm ? amr_r[0] : 8'hFF;
                BC_BTR0: rdat = rm ? btr0 : 8'hFF;
                BC_BTR1: rdat = rm ? btr1 : 8'hFF;
                BC_OCR:  rdat = rm ? ocr : 8'hFF;
                BC_TEST: rdat = test;
                BC_CDR:  rdat = cdr;             // CDR.4 is always written 0
                default: begin
                    if (a >= BC_TXB && a < BC_TXB + BC_TXB_LEN)
                        rdat = rm ? 8'hFF : txb[tx_ofs_b];
                    // 20..29: window (FIFO RAM data); 30 reads 00h
                end
            endcase
        end
    end

    // ---- sleep request (MOD.SM / CMR.GTS) ----
    wire sleep_wr = wr && !rm && (peli ? (a == PC_MOD) : (a == BC_CMR));
    wire sleep_d  = acc_wdat[4];
    // a requested transmission (TBS = 0) is bus activity about to start:
    // sleeping on it would freeze a frame the host is waiting for
    wire can_sleep = bus_idle && !irq && tbs;
    wire wake_bus  = sleep && !rx_i;

    // ---- clock divider (CDR.2..0: fosc/2,4,...,14, 7 = fosc; CDR.3 = off) ----
    assign clkout_fosc = (cdr[2:0] == 3'd7) && !cdr[3] && !sleep;
    reg [2:0] cdiv;
    always @(posedge clk) begin
        if (rst) begin
            cdiv <= 3'd0; clkout <= 1'b0;
        end else if (cdr[3] || sleep) begin
            cdiv <= 3'd0; clkout <= 1'b0;
        end else if (cdr[2:0] == 3'd7) begin
            cdiv <= 3'd0; clkout <= 1'b0;              // fosc: see clkout_fosc
        end else if (cdiv == cdr[2:0]) begin
            cdiv <= 3'd0; clkout <= ~clkout;
        end else begin
            cdiv <= cdiv + 3'd1;
        end
    end

    // ---- interrupt sources (IR bits are set only when enabled) ----
    wire rd_ir   = rd && a == PC_IR;     // same address in both views
    // WUI: sleep mode left, or go-to-sleep refused (bus activity / interrupt pending)
    wire wui_evt = wake_bus || (sleep_wr && sleep && !sleep_d) ||
                   (sleep_wr && !sleep && sleep_d && !can_sleep);
    wire [7:0] ir_set = {
        peli & err_evt & ecc_arm & ier[7],                       // BEI
        peli & alc_evt & alc_arm & ier[6],                       // ALI
        peli & epi_evt & ier[5],                                 // EPI
        wui_evt & (~peli | ier[4]),                              // WUI (always on in BasicCAN)
        dos_set & ier[3],                                        // DOI
        ((bus_off != bus_off_q) | (warn != warn_q)) & ier[2],   // EI
        (tx_done | tx_drop) & ier[1],                            // TI: TBS 0 -> 1
        1'b0                                                     // RI: live, see ri_live
    };

    integer i;
    always @(posedge clk) begin
        tx_req <= 1'b0; tx_single <= 1'b0; tx_self <= 1'b0; tx_abort <= 1'b0;
        rrb <= 1'b0; cdo <= 1'b0;
        if (rst) begin
            rm <= 1'b1; lom <= 1'b0; stm <= 1'b0; afm <= 1'b0; sleep <= 1'b0;
            btr0 <= 8'h00; btr1 <= 8'h00; ewlr <= 8'd96; cdr <= 8'h00; ocr <= 8'h00;
            ier <= 8'h00; cr6 <= 1'b0; ir <= 8'h00; alc <= 8'h00; ecc <= 8'h00;
            alc_arm <= 1'b1; ecc_arm <= 1'b1; tbs <= 1'b1; tcs <= 1'b1;
            bus_off_q <= 1'b0; warn_q <= 1'b0; rm_q <= 1'b1; test <= 8'h00;
            for (i = 0; i < 3; i = i + 1) ramfree[i] <= 8'h00;
            for (i = 0; i < 4; i = i + 1) begin acr_r[i] <= 8'h00; amr_r[i] <= 8'h00; end
            for (i = 0; i < 13; i = i + 1) txb[i] <= 8'h00;
        end else begin
            bus_off_q <= bus_off;
            warn_q    <= warn;
            rm_q      <= rm;

            // ---- interrupt sources ----
            // a read of IR clears the bits it returned; events of the same
            // clk are kept for the next read
            ir <= (rd_ir ? 8'h00 : ir) | ir_set;
            if (alc_evt && alc_arm) begin
                alc <= {3'b000, alc_val}; alc_arm <= 1'b0;
            end
            if (err_evt && ecc_arm) begin
                ecc <= ecc_val; ecc_arm <= 1'b0;
            end
            if (tx_done) begin tbs <= 1'b1; tcs <= 1'b1; end
            if (tx_drop) tbs <= 1'b1;

            // ---- sleep / wake-up ----
            if (wake_bus || (sleep_wr && sleep && !sleep_d)) begin
                sleep <= 1'b0;
            end else if (sleep_wr && !sleep && sleep_d && can_sleep) begin
                sleep <= 1'b1;
            end

            // ---- bus-off sets reset mode ----
            if (bus_off && !bus_off_q) begin rm <= 1'b1; tbs <= 1'b1; end

            // ---- reads with side effects ----
            if (rd && peli && a == PC_ALC) alc_arm <= 1'b1;
            if (rd && peli && a == PC_ECC) ecc_arm <= 1'b1;

            // ---- writes ----
            if (wr) begin
                if (peli) begin
                    case (a)
                        PC_MOD: begin
                            if (rm) begin
                                lom <= acc_wdat[1]; stm <= acc_wdat[2]; afm <= acc_wdat[3];
                            end
                            rm <= acc_wdat[0] | (bus_off && !bus_off_q);
                        end
                        PC_CMR: if (!rm) begin
                            if (acc_wdat[4] && tbs) begin                  // SRR
                                tx_req <= 1'b1; tx_self <= 1'b1; tx_single <= acc_wdat[1];
                                tbs <= 1'b0; tcs <= 1'b0;
                            end else if (acc_wdat[0] && tbs) begin         // TR
                                tx_req <= 1'b1; tx_single <= acc_wdat[1];
                                tbs <= 1'b0; tcs <= 1'b0;
                            end else if (acc_wdat[1]) begin
                                tx_abort <= 1'b1;                          // AT
                            end
                            rrb <= acc_wdat[2]; cdo <= acc_wdat[3];
                        end else begin
                            rrb <= acc_wdat[2]; cdo <= acc_wdat[3];
                        end
                        PC_IER:  ier <= acc_wdat;
                        PC_TEST: test <= acc_wdat;
                        PC_BTR0: if (rm) btr0 <= acc_wdat;
                        PC_BTR1: if (rm) btr1 <= acc_wdat;
                        PC_OCR:  if (rm) ocr <= acc_wdat;
                        PC_EWLR: if (rm) ewlr <= acc_wdat;
                        PC_CDR:  cdr <= rm ? (acc_wdat & 8'hEF) : {cdr[7:3], acc_wdat[2:0]};
                        default: begin
                            if (rm && a >= PC_TXRAM && a < PC_TXRAM + PC_BUF_LEN)
                                txb[a[3:0]] <= acc_wdat;
                            if (rm && a >= PC_TXRAM + PC_BUF_LEN && a < PC_TXRAM + PC_BUF_LEN + 8'd3)
                                ramfree[a[1:0] - 2'd1] <= acc_wdat;
                            if (in_win_p) begin
                                if (!rm) begin
                                    if (tbs) txb[a[3:0]] <= acc_wdat;
                                end else if (a < PC_AMR0) acr_r[a[1:0]] <= acc_wdat;
                                else if (a < PC_AMR0 + 8'd4) amr_r[a[1:0]] <= acc_wdat;
                            end
                        end
                    endcase
                end else begin
                    case (a)
                        BC_CR: begin
                            rm <= acc_wdat[0] | (bus_off && !bus_off_q);
                            ier[3:0] <= acc_wdat[4:1];
                            cr6 <= acc_wdat[6];
                        end
                        BC_CMR: begin
                            if (!rm) begin
                                if (acc_wdat[0] && tbs) begin
                                    tx_req <= 1'b1; tx_single <= acc_wdat[1];
                                    tbs <= 1'b0; tcs <= 1'b0;
                                end else if (acc_wdat[1]) tx_abort <= 1'b1;
                            end
                            rrb <= acc_wdat[2]; cdo <= acc_wdat[3];
                        end
                        BC_ACR:  if (rm) acr_r[0] <= acc_wdat;
                        BC_AMR:  if (rm) amr_r[0] <= acc_wdat;
                        BC_BTR0: if (rm) btr0 <= acc_wdat;
                        BC_BTR1: if (rm) btr1 <= acc_wdat;
                        BC_OCR:  if (rm) ocr <= acc_wdat;
                        BC_CDR:  cdr <= rm ? (acc_wdat & 8'hEF) : {cdr[7:3], acc_wdat[2:0]};
                        BC_TEST: test <= acc_wdat;
                        default: begin
                            if (a >= BC_TXB && a < BC_TXB + BC_TXB_LEN && !rm && tbs)
                                txb[tx_ofs_b] <= acc_wdat;
                        end
                    endcase
                end
            end

            // ---- reset mode: the pending transmission is released (no TI);
            // entering it clears WUI, DOI and TI (map reset values) ----
            if (rm) begin
                tbs <= 1'b1;
                sleep <= 1'b0;
            end
            if (rm && !rm_q) ir <= ir & 8'hE4;
        end
    end
endmodule
