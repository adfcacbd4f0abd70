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

    // Datasheet TXERR: a write of 255 in reset mode only arms a CPU-driven
    // bus-off; it happens when reset mode is left, as a bus-off by errors.
    reg  boff_armed;
    wire boff_forced = boff_armed && !hold;
    wire boff_by_err = !freeze && !bus_off && tec_add8 && tec_up[8];
    // Until the armed bus-off has taken effect the status stays held, so the
    // one clk between leaving reset mode and bus-off shows no ES/EPI change.
    wire held = hold || boff_armed;

    // SR.ES: held set while bus-off (cleared with the counters at the end of
    // the recovery, datasheet SR note 1). A change caused by a TXERR/RXERR
    // write in reset mode shows (ES, EI, EPI, BS) only when reset mode is
    // left (datasheet RXERR/TXERR: "will not occur until the reset mode is
    // cancelled again").
    wire warn_live = bus_off || (tec >= ewl) || (rec >= ewl);
    reg  warn_held;
    assign warn    = (held && !bus_off) ? warn_held : warn_live;

    reg passive_q;
    assign epi_evt = (passive != passive_q) && !bus_off && !held;

    always @(posedge clk) begin
        if (rst) begin
            tec       <= 8'd0;
            rec       <= 8'd0;
            bus_off   <= 1'b0;
            passive_q <= 1'b0;
            warn_held <= 1'b0;
            boff_armed <= 1'b0;
        end else begin
            if (!held) passive_q <= passive;
            warn_held <= warn;
            if (wr_rec && !bus_off) rec <= wdat;   // ignored while bus-off
            if (wr_tec) begin
                // 255 (not bus-off yet) arms the bus-off for leaving reset
                // mode; any other value disarms it, and ends a bus-off
                if (!(wdat == 8'd255 && bus_off)) begin
                    tec <= wdat; bus_off <= 1'b0;
                end
                boff_armed <= wdat == 8'd255 && !bus_off;
            end else if (boff_forced || boff_by_err) begin
                // bus-off, by errors (rule 10: TEC above 255) or armed by a
                // TXERR write of 255: TXERR is set to 127 to count the
                // recovery, RXERR is cleared
                boff_armed <= 1'b0;
                bus_off <= 1'b1; tec <= 8'd127; rec <= 8'd0;
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
                if (tec_add8) tec <= tec_up[7:0];
                else if (tec_sub1 && tec != 8'd0) tec <= tec - 8'd1;
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
endmodule
