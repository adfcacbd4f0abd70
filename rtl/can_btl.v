// Bit timing logic (SJA1000 BTL; CAN 2.0B section 10).
//
// Time quantum tq = 2 * (BRP + 1) clk periods from a free-running prescaler
// (held at zero while the controller is not running). All bit timing work
// happens on tq boundaries: at the last clk of each quantum (tq_tick) the bus
// level rx is looked at; a recessive-to-dominant change since the previous
// tick means the edge fell in the quantum that just ended ("q").
// Bit = SYNC_SEG (1 tq) + TSEG1 (TSEG1+1 tq) + TSEG2 (TSEG2+1 tq); the
// sample point is the end of TSEG1 (q == t1).
//  - Hard sync (bus idle, SOF expected): the quantum holding the edge becomes
//    SYNC_SEG; counting goes on with TSEG1.
//  - Resync (CAN 2.0B 10.4.2): edge in TSEG1 (phase error e = q > 0):
//    TSEG1 lengthened by min(e, SJW+1); edge in TSEG2 (e = q - nq < 0):
//    TSEG2 shortened by min(|e|, SJW+1); an edge in SYNC_SEG (e = 0) moves
//    nothing. Only one sync between two sample points (an edge in SYNC_SEG
//    is one), only if the previous sampled bit was recessive, and a node
//    sending a dominant bit does not resync on a positive phase error.
//  - SAM = 1: the bit is the majority of the levels at the last three ticks.
// tx_o changes at the start of every bit (SYNC_SEG) to the value tx_next
// the bit stream processor computed at the previous sample point.
module can_btl (
    input  wire       clk,
    input  wire       rst,
    input  wire       run,        // operating mode and awake
    input  wire [5:0] brp,
    input  wire [1:0] sjw,
    input  wire [3:0] tseg1,
    input  wire [2:0] tseg2,
    input  wire       sam,
    input  wire       rx,
    input  wire       hard_en,    // BSP: a dominant edge now would be SOF
    input  wire       tx_next,    // BSP: level for the next bit
    output reg        sample,     // one clk pulse at the sample point
    output reg        rx_bit,     // sampled bus level (valid with sample)
    output reg        tx_o
);
    reg [6:0] pre;
    wire      tq_tick = (pre == {brp, 1'b1});

    reg [4:0] q;                  // quantum that ends at this tick
    reg       rx_tq;              // level at the previous tick
    reg       rx_tq2;             // level two ticks ago
    reg       last_bit;           // value at the previous sample point
    reg       synced;             // a sync happened since the last sample point

    wire [4:0] t1   = {1'b0, tseg1} + 5'd1;
    wire [4:0] nq   = t1 + {2'b00, tseg2} + 5'd2;      // 1 + t1 + t2
    wire [4:0] sjw1 = {3'b000, sjw} + 5'd1;
    wire       edge_det = rx_tq && !rx && last_bit && !synced;
    wire       in_tseg1 = (q != 5'd0) && (q <= t1);
    wire       in_tseg2 = (q > t1);
    wire [4:0] rem  = nq - q;                          // quanta left incl. q
    wire       maj  = (rx & rx_tq) | (rx & rx_tq2) | (rx_tq & rx_tq2);

    always @(posedge clk) begin
        if (rst || !run) begin
            pre      <= 7'd0;
            q        <= 5'd0;
            rx_tq    <= 1'b1;
            rx_tq2   <= 1'b1;
            last_bit <= 1'b1;
            synced   <= 1'b0;
            sample   <= 1'b0;
            rx_bit   <= 1'b1;
            tx_o     <= 1'b1;
        end else begin
            sample <= 1'b0;
            pre    <= tq_tick ? 7'd0 : pre + 7'd1;
            if (tq_tick) begin
                rx_tq  <= rx;
                rx_tq2 <= rx_tq;
                if (edge_det && hard_en) begin
                    // hard synchronisation
                    synced <= 1'b1;
                    q      <= 5'd1;
                    if (in_tseg2) tx_o <= tx_next;     // a new bit started
                end else if (edge_det && in_tseg1 && tx_o) begin
                    // late edge: lengthen TSEG1
                    synced <= 1'b1;
                    q      <= (q <= sjw1) ? 5'd1 : (q + 5'd1 - sjw1);
                end else if (edge_det && in_tseg2) begin
                    // early edge: shorten TSEG2
                    synced <= 1'b1;
                    if (rem <= sjw1) begin
                        q    <= 5'd1;
                        tx_o <= tx_next;
                    end else if (q + 5'd1 + sjw1 == nq) begin
                        q    <= 5'd0;
                        tx_o <= tx_next;
                    end else begin
                        q    <= q + 5'd1 + sjw1;
                    end
                end else begin
                    // An edge in SYNC_SEG (phase error 0) moves nothing but is
                    // this bit's one synchronisation: later edges wait for
                    // the sample point.
                    if (edge_det && q == 5'd0)
                        synced <= 1'b1;
                    if (q == t1) begin
                        sample   <= 1'b1;
                        rx_bit   <= sam ? maj : rx;
                        last_bit <= sam ? maj : rx;
                        synced   <= 1'b0;
                    end
                    if (q == nq - 5'd1) begin
                        q    <= 5'd0;
                        tx_o <= tx_next;
                    end else begin
                        q    <= q + 5'd1;
                    end
                end
            end
        end
    end
endmodule
