// Fault confinement (CAN 2.0B section 8): transmit and receive error
// counters, error warning (EWL), error passive and bus-off states.
// The bit stream processor tells which rule fired; the rule letters refer
// to the numbered rules of CAN 2.0B section 8.
module can_fce (
    input  wire       clk,
    input  wire       rst,
    input  wire       freeze,       // listen-only mode: counters stopped
    input  wire       hold,         // reset mode: ES/EPI changes wait until it is left
    input  wire       tec_add8,     // rules 3, 4, 6 (transmitter)
    input  wire       tec_sub1,     // rule 7 (successful transmission)
    input  wire       rec_add1,     // rule 1
    input  wire       rec_add8,     // rules 2, 5, 6 (receiver)
    input  wire       rec_sub1,     // rule 8 (successful reception)
    input  wire       recov_tick,   // one bus-free sequence (11 recessive bits) in recovery
    input  wire       wr_tec,       // host write of TXERR (reset mode)
    input  wire       wr_rec,       // host write of RXERR (reset mode)
    input  wire [7:0] wdat,
    input  wire [7:0] ewl,
    output reg  [7:0] tec,          // TXERR view: counts the recovery while bus-off
    output reg  [7:0] rec,
    output reg        bus_off,
    output wire       passive,      // error passive (not bus-off)
    output wire       warn,         // SR.ES: a counter at or above EWL
    output wire       epi_evt       // error active <-> error passive transition
);
    wire [8:0] tec_up = {1'b0, tec} + 9'd8;
    wire [8:0] rec_up = {1'b0, rec} + (rec_add8 ? 9'd8 : 9'd1);

    assign passive = !bus_off && (tec[7] || rec[7]);

    // SR.ES: held set while bus-off (cleared with the counters at the end of
    // the recovery, datasheet SR note 1). A change caused by a TXERR/RXERR
    // write in reset mode shows (ES, EI, EPI) only when reset mode is left
    // (datasheet RXERR/TXERR: "will not occur until the reset mode is
    // cancelled again"); bus-off itself shows at once.
    wire warn_live = bus_off || (tec >= ewl) || (rec >= ewl);
    reg  warn_held;
    assign warn    = (hold && !bus_off) ? warn_held : warn_live;

    reg passive_q;
    assign epi_evt = (passive != passive_q) && !bus_off && !hold;

    always @(posedge clk) begin
        if (rst) begin
            tec       <= 8'd0;
            rec       <= 8'd0;
            bus_off   <= 1'b0;
            passive_q <= 1'b0;
            warn_held <= 1'b0;
        end else begin
            if (!hold) passive_q <= passive;
            warn_held <= warn;
            if (wr_rec && !bus_off) rec <= wdat;   // ignored while bus-off
            if (wr_tec) begin
                if (wdat == 8'd255 && !bus_off) begin
                    // datasheet: writing 255 to TXERR forces a bus-off event
                    bus_off <= 1'b1; tec <= 8'd127; rec <= 8'd0;
                end else begin
                    tec <= wdat; bus_off <= 1'b0; // a TXERR write ends bus-off
                end
            end else if (bus_off) begin
                // 128 occurrences of 11 recessive bits: TXERR counts 127..0,
                // the 128th sequence brings the node back error active.
                if (recov_tick) begin
                    if (tec == 8'd0) begin
                        bus_off <= 1'b0;
                        rec     <= 8'd0;
                    end else begin
                        tec <= tec - 8'd1;
                    end
                end
            end else if (!freeze) begin
                if (tec_add8) begin
                    if (tec_up[8]) begin
                        // TEC > 255: bus-off; TXERR is set to 127 to count recovery
                        bus_off <= 1'b1;
                        tec     <= 8'd127;
                        rec     <= 8'd0;
                    end else begin
                        tec <= tec_up[7:0];
                    end
                end else if (tec_sub1 && tec != 8'd0) begin
                    tec <= tec - 8'd1;
                end
                if (!(tec_add8 && tec_up[8])) begin
                    if (rec_add1 || rec_add8) begin
                        rec <= rec_up[8] ? 8'd255 : rec_up[7:0];
                    end else if (rec_sub1) begin
                        // rule 8: 1..127 -> minus one; above 127 -> 127
                        if (rec[7]) rec <= 8'd127;
                        else if (rec != 8'd0) rec <= rec - 8'd1;
                    end
                end
            end
        end
    end
endmodule
