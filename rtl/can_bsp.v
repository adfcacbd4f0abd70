// Bit stream processor (SJA1000 BSP; CAN 2.0B sections 3-7).
//
// Works once per bit, at the sample point given by the bit timing logic:
// destuffing/stuff check, CRC-15 (0x4599), arbitration with ALC capture,
// ACK, the five errors (bit, stuff, CRC, form, ACK) with the SJA1000 ECC
// segment codes, active/passive error flags, error delimiter, overload
// frames, intermission, suspend transmission, bus integration and bus-off
// recovery counting. tx_next (combinational from the registered state) is
// the level of the next bit; the BTL drives it at the next SYNC_SEG.
// Fault confinement counting rules are reported to can_fce as pulses.
module can_bsp (
    input  wire        clk,
    input  wire        rst,
    input  wire        rm,          // reset mode: cancel everything
    input  wire        run,         // not reset mode, not sleeping
    input  wire        sample,
    input  wire        rx,          // sampled bit
    input  wire        tx_cur,      // level we drive during this bit
    input  wire        lom,         // listen only
    input  wire        stm,         // self test: no ACK needed
    input  wire        passive,
    input  wire        bus_off,
    // frame to send
    input  wire        tx_ide,
    input  wire        tx_rtr,
    input  wire [3:0]  tx_dlc,
    input  wire [28:0] tx_id,       // standard ID in [28:18]
    input  wire [63:0] tx_data,     // byte 1 in [63:56]
    input  wire        tx_req,      // pulse: TR or SRR
    input  wire        tx_single,   // with tx_req: no retransmission
    input  wire        tx_self,     // with tx_req: self reception
    input  wire        tx_abort,    // pulse: AT
    // outputs to the BTL
    output reg         tx_next,
    output wire        hard_en,
    // received frame
    output wire [28:0] rx_id,       // standard ID in [28:18]
    output reg         rx_ide,
    output reg         rx_rtr,
    output reg  [3:0]  rx_dlc,
    output reg  [63:0] rx_data,     // byte 1 in [63:56] (aligned during the CRC field)
    output reg         rx_valid,    // pulse: frame valid for the receiver (EOF bit 6)
    // events
    output reg         tx_done,     // pulse: transmission successful
    output reg         tx_drop,     // pulse: request dropped (abort, single shot)
    output reg         alc_evt,
    output reg  [4:0]  alc_val,
    output reg         err_evt,
    output reg  [7:0]  ecc_val,
    output reg         tec_add8,
    output reg         tec_sub1,
    output reg         rec_add1,
    output reg         rec_add8,
    output reg         rec_sub1,
    output reg         recov_tick,
    output wire        rs,          // SR.RS
    output wire        ts,          // SR.TS
    output wire        bus_idle,
    output wire        integrating  // waiting for bus-free (11 recessive bits)
);
    localparam [4:0] S_OFF = 5'd0, S_INTEG = 5'd1, S_IDLE = 5'd2, S_SOF = 5'd3,
                     S_IDA = 5'd4, S_SRTR = 5'd5, S_IDE = 5'd6, S_IDB = 5'd7,
                     S_RTR = 5'd8, S_R1 = 5'd9, S_R0 = 5'd10, S_DLC = 5'd11,
                     S_DATA = 5'd12, S_CRC = 5'd13, S_CRCD = 5'd14, S_ACK = 5'd15,
                     S_ACKD = 5'd16, S_EOF = 5'd17, S_INTER = 5'd18, S_SUSP = 5'd19,
                     S_EFLAG = 5'd20, S_EWAIT = 5'd21, S_EDELIM = 5'd22,
                     S_OFLAG = 5'd23, S_BUSOFF = 5'd24;

    // ECC error codes (bits 7:6)
    localparam [1:0] E_BIT = 2'b00, E_FORM = 2'b01, E_STUFF = 2'b10, E_OTHER = 2'b11;

    reg [4:0]  st;
    reg [5:0]  cnt;
    reg [2:0]  scnt;         // equal bits in a row (stuffing)
    reg        slast;        // last bus bit (stuffing)
    reg [14:0] crc;
    reg        srtr;         // received SRR/RTR bit
    reg        txr;          // we are the transmitter of this frame
    reg        req, req_single, req_self;
    reg        abort_hold;   // an abort met a clock that may start a frame: decide next clock
    reg        crc_err;      // CRC error to signal after the ACK delimiter
    reg        ack_pend;     // error-passive ACK error: +8 only if dominant seen in flag
    reg [2:0]  eq_cnt;       // passive error flag: equal bits in a row
    reg        eq_last;
    reg        first;        // first bit after an error flag
    reg [28:0] id_sr;        // identifier bits shifted in (11 or 29)
    reg [2:0]  align;        // byte shifts left to align the data field
    reg        flag_act;     // the error flag being sent is active (dominant)
    reg [2:0]  dom_cnt;      // dominant bits after a flag (tolerate 7)
    reg [3:0]  rcnt;         // recessive bits in a row (bus free)

    // CAN 2.0B 8, rule 9 note: the flag type is the fault state *before*
    // the increment of the error that starts it (an error making the node
    // error passive is still signalled with an active error flag).
    wire flag_passive = !flag_act;
    wire busy      = !(st == S_OFF || st == S_INTEG || st == S_BUSOFF || st == S_IDLE ||
                       st == S_INTER || st == S_SUSP);
    wire stuffed   = (st >= S_IDA) && (st <= S_CRC);
    wire is_stuff  = ((st >= S_IDA) && (st <= S_CRCD)) && (scnt == 3'd5);
    // arbitration field up to RTR; IDE belongs to it only in an extended
    // frame (a stuff bit seen in S_IDE of a standard frame follows RTR:
    // no rule 3 exception 2 there, a plain bit error)
    wire in_arb    = (st == S_IDA) || (st == S_SRTR) || (st == S_IDE && tx_ide) ||
                     (st == S_IDB) || (st == S_RTR);
    // data bytes mod 8 (8 bytes -> 0, so that 8 * ndata - 1 wraps to 63)
    wire [2:0] ndata = rx_dlc[3] ? 3'd0 : rx_dlc[2:0];
    assign rx_id = rx_ide ? id_sr : {id_sr[10:0], 18'd0};
    wire can_tx    = req && !lom;

    // Hard sync only while the bus is idle for us (CAN 2.0B 9.2.4 rule 3).
    // S_SOF: a request decided at the last sample point; until our SOF is
    // on the wire another node's SOF edge hard-synchronises us (and starts
    // our SOF with it). Once we drive the SOF, its edge (in SYNC_SEG) was
    // the one synchronisation of the bit (rule 1): a later edge before the
    // sample point is a positive phase error of a dominant sender, ignored.
    assign hard_en  = (st == S_IDLE) || (st == S_SUSP) || ((st == S_SOF) && tx_cur) ||
                      (st == S_INTEG) || (st == S_BUSOFF) ||
                      ((st == S_INTER) && (cnt == 6'd2));
    assign bus_idle = (st == S_IDLE);
    assign integrating = (st == S_INTEG);
    // SR.TS: the transmitter, from SOF until bus idle (also between automatic
    // retransmissions and during suspend); SR.RS: a receiver inside a frame
    // or error/overload signalling, and through the intermission after it
    // (the datasheet reads RS = TS = 0 as bus idle, which starts after it)
    assign ts = txr;
    assign rs = !txr && (busy || st == S_INTER);

    // ---- the level of the bit being sent (tx_cur) for the current state ----
    reg frame_bit;
    always @* begin
        case (st)
            S_IDA:  frame_bit = tx_id[5'd28 - cnt[4:0]];
            S_SRTR: frame_bit = tx_ide ? 1'b1 : tx_rtr;
            S_IDE:  frame_bit = tx_ide;
            S_IDB:  frame_bit = tx_id[5'd17 - cnt[4:0]];
            S_RTR:  frame_bit = tx_rtr;
            S_DLC:  frame_bit = tx_dlc[2'd3 - cnt[1:0]];
            S_DATA: frame_bit = tx_data[6'd63 - cnt];
            S_CRC:  frame_bit = crc[14];
            default: frame_bit = 1'b0;                 // SOF, r1, r0
        endcase
    end

    always @* begin
        tx_next = 1'b1;
        case (st)
            S_SOF: tx_next = 1'b0;
            S_CRCD: tx_next = (txr && is_stuff) ? ~slast : 1'b1;
            S_ACK: tx_next = !(!txr && !crc_err && crc == 15'd0);
            S_EFLAG: tx_next = flag_passive;
            S_OFLAG: tx_next = 1'b0;
            default:
                if (stuffed && txr) tx_next = is_stuff ? ~slast : frame_bit;
        endcase
        if (lom || bus_off || !run) tx_next = 1'b1;
    end

    // ---- ECC segment of the current bit ----
    reg [4:0] seg;
    always @* begin
        case (st)
            S_SOF:    seg = 5'b00011;
            S_IDA:    seg = (cnt < 6'd8) ? 5'b00010 : 5'b00110;
            S_SRTR:   seg = 5'b00100;
            S_IDE:    seg = 5'b00101;
            S_IDB:    seg = (cnt < 6'd5) ? 5'b00111 : ((cnt < 6'd13) ? 5'b01111 : 5'b01110);
            S_RTR:    seg = 5'b01100;
            S_R1:     seg = 5'b01101;
            S_R0:     seg = 5'b01001;
            S_DLC:    seg = 5'b01011;
            S_DATA:   seg = 5'b01010;
            S_CRC:    seg = 5'b01000;
            S_CRCD:   seg = is_stuff ? 5'b01000 : 5'b11000;
            S_ACK:    seg = 5'b11001;
            S_ACKD:   seg = 5'b11011;
            S_EOF:    seg = 5'b11010;
            S_INTER:  seg = 5'b10010;
            S_EFLAG:  seg = flag_passive ? 5'b10110 : 5'b10001;
            S_EWAIT:  seg = 5'b10011;
            S_EDELIM: seg = 5'b10111;
            S_OFLAG:  seg = 5'b11100;
            default:  seg = 5'b00000;
        endcase
    end

    // ALC bit number of the current arbitration bit
    reg [4:0] alc_pos;
    always @* begin
        case (st)
            S_IDA:  alc_pos = cnt[4:0];
            S_SRTR: alc_pos = 5'd11;
            S_IDE:  alc_pos = 5'd12;
            S_IDB:  alc_pos = 5'd13 + cnt[4:0];
            default: alc_pos = 5'd31;                  // S_RTR
        endcase
    end

    wire [14:0] crc_step = {crc[13:0], 1'b0} ^ ((rx ^ crc[14]) ? 15'h4599 : 15'h0000);

    // ---- per-bit decision (combinational), applied at the sample point ----
    reg       err;           // an error is detected in this bit
    reg [1:0] ekind;
    reg       e_tec_none;    // transmitter error that does not count (rule 3 exceptions)
    reg       e_flagbit;     // bit error in own active error flag / overload flag
    reg       e_ackpass;     // ACK error while error passive (rule 3 exception 1)
    reg       arb_lost;
    always @* begin
        err = 1'b0; ekind = E_BIT; e_tec_none = 1'b0; e_flagbit = 1'b0;
        e_ackpass = 1'b0; arb_lost = 1'b0;
        if (is_stuff) begin
            if (txr && tx_cur != rx) begin
                err = 1'b1;
                if (tx_cur && in_arb) begin
                    ekind = E_STUFF; e_tec_none = 1'b1;   // rule 3 exception 2
                end else begin
                    ekind = E_BIT;
                end
            end else if (rx == slast) begin
                err = 1'b1; ekind = E_STUFF;
            end
        end else begin
            case (st)
                S_SOF: if (rx) begin err = 1'b1; ekind = E_BIT; end
                S_IDA, S_SRTR, S_IDE, S_IDB, S_RTR, S_R1, S_R0, S_DLC, S_DATA, S_CRC:
                    if (txr && tx_cur != rx) begin
                        if (tx_cur && in_arb) arb_lost = 1'b1;
                        else begin err = 1'b1; ekind = E_BIT; end
                    end
                S_CRCD: if (!rx) begin err = 1'b1; ekind = E_FORM; end
                S_ACK:
                    if (txr) begin
                        if (rx && !stm) begin
                            err = 1'b1; ekind = E_OTHER; e_ackpass = passive;
                        end
                    end else if (!tx_cur && rx) begin
                        err = 1'b1; ekind = E_BIT;
                    end
                S_ACKD:
                    if (!rx) begin err = 1'b1; ekind = E_FORM; end
                    else if (crc_err) begin err = 1'b1; ekind = E_OTHER; end
                S_EOF:
                    if (!rx && !(cnt == 6'd6 && !txr)) begin err = 1'b1; ekind = E_FORM; end
                S_EFLAG:
                    if (!flag_passive && rx) begin err = 1'b1; ekind = E_BIT; e_flagbit = 1'b1; end
                S_OFLAG:
                    if (!lom && rx) begin err = 1'b1; ekind = E_BIT; e_flagbit = 1'b1; end
                S_EDELIM:
                    if (!rx && cnt != 6'd7) begin err = 1'b1; ekind = E_FORM; end
                default: ;
            endcase
        end
    end

    always @(posedge clk) begin
        // single-cycle pulses
        rx_valid <= 1'b0; tx_done <= 1'b0; tx_drop <= 1'b0;
        alc_evt <= 1'b0; err_evt <= 1'b0;
        tec_add8 <= 1'b0; tec_sub1 <= 1'b0; rec_add1 <= 1'b0; rec_add8 <= 1'b0;
        rec_sub1 <= 1'b0; recov_tick <= 1'b0;
        if (rst) begin
            st <= S_OFF; cnt <= 6'd0; scnt <= 3'd0; slast <= 1'b1; crc <= 15'd0;
            srtr <= 1'b0; txr <= 1'b0; req <= 1'b0; req_single <= 1'b0; req_self <= 1'b0;
            abort_hold <= 1'b0;
            crc_err <= 1'b0; ack_pend <= 1'b0; eq_cnt <= 3'd0; eq_last <= 1'b1; flag_act <= 1'b1;
            first <= 1'b0; dom_cnt <= 3'd0; rcnt <= 4'd0;
            id_sr <= 29'd0; rx_ide <= 1'b0; rx_rtr <= 1'b0; rx_dlc <= 4'd0; rx_data <= 64'd0;
            align <= 3'd0;
            alc_val <= 5'd0; ecc_val <= 8'd0;
        end else begin
            // ---- transmission requests ----
            // CMR.AT (datasheet 6.4.4): a pending request is cancelled (TBS,
            // TI), one in progress is not retried. A frame starts at a sample
            // point (or when bus-off recovery ends) from the old `req`, so an
            // abort meeting that clock is decided one clock later, when txr
            // says whether the frame started: else TBS would free the buffer
            // of a frame on the wire.
            abort_hold <= 1'b0;
            if (rm) begin
                req <= 1'b0;
            end else if (tx_req && !req) begin
                req <= 1'b1; req_single <= tx_single; req_self <= tx_self;
            end else if ((tx_abort || abort_hold) && req) begin
                if (txr && busy) req_single <= 1'b1;
                else if (!abort_hold && (sample || st == S_BUSOFF)) abort_hold <= 1'b1;
                else begin req <= 1'b0; tx_drop <= 1'b1; end
            end

            if (!run) begin
                st <= S_OFF; txr <= 1'b0; rcnt <= 4'd0;
            end else if (st == S_OFF) begin
                st <= bus_off ? S_BUSOFF : S_INTEG; rcnt <= 4'd0;
            end else if (st == S_BUSOFF && !bus_off) begin
                // recovered: bus idle; a request written meanwhile starts now
                if (can_tx) begin st <= S_SOF; txr <= 1'b1; end
                else st <= S_IDLE;
            end else if (sample && (!bus_off || st == S_BUSOFF)) begin
                if (err) begin
                    // ---- error detected: error flag from the next bit ----
                    err_evt <= 1'b1;
                    ecc_val <= {ekind, !txr, seg};
                    st <= S_EFLAG; cnt <= 6'd0; crc_err <= 1'b0;
                    flag_act <= !passive && !lom;
                    if (txr) begin
                        if (e_ackpass) ack_pend <= 1'b1;
                        else if (!e_tec_none) tec_add8 <= 1'b1;
                        if (req_single && req) begin
                            req <= 1'b0; tx_drop <= 1'b1;
                        end
                    end else begin
                        if (e_flagbit) rec_add8 <= 1'b1;
                        else rec_add1 <= 1'b1;
                    end
                end else if (is_stuff) begin
                    slast <= rx; scnt <= 3'd1;
                end else begin
                    if (arb_lost) begin
                        txr <= 1'b0;
                        alc_evt <= 1'b1; alc_val <= alc_pos;
                        if (req_single) begin req <= 1'b0; tx_drop <= 1'b1; end
                    end
                    if (stuffed) begin
                        if (rx == slast) scnt <= scnt + 3'd1;
                        else scnt <= 3'd1;
                        slast <= rx;
                        crc <= crc_step;
                    end
                    case (st)
                        S_INTEG: begin
                            if (!rx) rcnt <= 4'd0;
                            else if (rcnt == 4'd10) begin
                                // bus idle reached: a pending request starts with the next bit
                                rcnt <= 4'd0;
                                if (can_tx) begin st <= S_SOF; txr <= 1'b1; end
                                else st <= S_IDLE;
                            end else rcnt <= rcnt + 4'd1;
                        end
                        S_BUSOFF: begin
                            if (!rx) rcnt <= 4'd0;
                            else if (rcnt == 4'd10) begin rcnt <= 4'd0; recov_tick <= 1'b1; end
                            else rcnt <= rcnt + 4'd1;
                        end
                        S_IDLE, S_SUSP, S_INTER: begin
                            if (!rx && (st != S_INTER || cnt == 6'd2)) begin
                                // start of frame from another node
                                st <= S_IDA; cnt <= 6'd0; scnt <= 3'd1; slast <= 1'b0;
                                crc <= 15'd0;
                                // at intermission bit 3 a pending request takes this as its
                                // own SOF and goes on with the identifier (unless it must
                                // suspend transmission); in bus idle the node is a receiver
                                txr <= (st == S_INTER) && can_tx && !(txr && passive);
                            end else if (!rx) begin
                                // dominant in intermission bit 1 or 2: overload frame
                                st <= S_OFLAG; cnt <= 6'd0;
                            end else if (st == S_INTER && cnt != 6'd2) begin
                                cnt <= cnt + 6'd1;
                            end else if (st == S_SUSP && cnt != 6'd7) begin
                                cnt <= cnt + 6'd1;
                            end else if (st == S_INTER && txr && passive) begin
                                st <= S_SUSP; cnt <= 6'd0;     // still the transmitter (SR.TS)
                            end else if (can_tx) begin
                                st <= S_SOF; txr <= 1'b1;
                            end else begin
                                st <= S_IDLE; txr <= 1'b0;
                            end
                        end
                        S_SOF: begin
                            st <= S_IDA; cnt <= 6'd0; scnt <= 3'd1; slast <= 1'b0;
                            crc <= 15'd0;
                        end
                        S_IDA: begin
                            id_sr <= {id_sr[27:0], rx};
                            if (cnt == 6'd10) st <= S_SRTR; else cnt <= cnt + 6'd1;
                        end
                        S_SRTR: begin srtr <= rx; st <= S_IDE; end
                        S_IDE: begin
                            rx_ide <= rx;
                            if (rx) begin st <= S_IDB; cnt <= 6'd0; end
                            else begin rx_rtr <= srtr; st <= S_R0; end
                        end
                        S_IDB: begin
                            id_sr <= {id_sr[27:0], rx};
                            if (cnt == 6'd17) st <= S_RTR; else cnt <= cnt + 6'd1;
                        end
                        S_RTR: begin rx_rtr <= rx; st <= S_R1; end
                        S_R1:  st <= S_R0;
                        S_R0:  begin st <= S_DLC; cnt <= 6'd0; end
                        S_DLC: begin
                            rx_dlc <= {rx_dlc[2:0], rx};
                            if (cnt == 6'd3) begin
                                cnt <= 6'd0;
                                // data bytes 1..n end up in the low bytes of rx_data;
                                // 8 - n byte shifts during the CRC field align byte 1
                                align <= (rx_rtr || rx_dlc[2]) ? 3'd0 : 3'd0 - {rx_dlc[1:0], rx};
                                if (rx_rtr || {rx_dlc[2:0], rx} == 4'd0) st <= S_CRC;
                                else st <= S_DATA;
                            end else cnt <= cnt + 6'd1;
                        end
                        S_DATA: begin
                            rx_data <= {rx_data[62:0], rx};
                            // last data bit: 8 * ndata - 1 (ndata = 8 wraps to 63)
                            if (cnt == ({ndata, 3'b000} - 6'd1)) begin
                                st <= S_CRC; cnt <= 6'd0;
                            end else cnt <= cnt + 6'd1;
                        end
                        S_CRC: begin
                            if (align != 3'd0) begin
                                rx_data <= {rx_data[55:0], 8'h00}; align <= align - 3'd1;
                            end
                            if (cnt == 6'd14) st <= S_CRCD; else cnt <= cnt + 6'd1;
                        end
                        S_CRCD: begin
                            crc_err <= !txr && (crc != 15'd0);
                            st <= S_ACK;
                        end
                        S_ACK: begin
                            if (!txr && !tx_cur) rec_sub1 <= 1'b1;     // rule 8
                            st <= S_ACKD;
                        end
                        S_ACKD: begin st <= S_EOF; cnt <= 6'd0; end
                        S_EOF: begin
                            // valid for receivers at the last-but-one EOF bit; an own
                            // frame (self reception) when the transmission succeeds
                            if (cnt == 6'd5 && !txr) rx_valid <= 1'b1;
                            if (cnt == 6'd6) begin
                                if (txr) begin
                                    tx_done <= 1'b1; tec_sub1 <= 1'b1; req <= 1'b0;
                                    if (req_self) rx_valid <= 1'b1;
                                end
                                if (!rx) begin st <= S_OFLAG; cnt <= 6'd0; end
                                else begin st <= S_INTER; cnt <= 6'd0; end
                            end else cnt <= cnt + 6'd1;
                        end
                        S_EFLAG: begin
                            if (flag_passive) begin
                                if (!rx && ack_pend) begin tec_add8 <= 1'b1; ack_pend <= 1'b0; end
                                if (cnt == 6'd0 || rx != eq_last) begin
                                    eq_cnt <= 3'd1; eq_last <= rx; cnt <= 6'd1;
                                end else if (eq_cnt == 3'd5) begin
                                    st <= S_EWAIT; first <= 1'b1; dom_cnt <= 3'd0; ack_pend <= 1'b0;
                                end else eq_cnt <= eq_cnt + 3'd1;
                            end else begin
                                if (cnt == 6'd5) begin
                                    st <= S_EWAIT; first <= 1'b1; dom_cnt <= 3'd0; ack_pend <= 1'b0;
                                end else cnt <= cnt + 6'd1;
                            end
                        end
                        S_OFLAG: begin
                            if (cnt == 6'd5) begin
                                st <= S_EWAIT; first <= 1'b0; dom_cnt <= 3'd0;
                            end else cnt <= cnt + 6'd1;
                        end
                        S_EWAIT: begin
                            first <= 1'b0;
                            if (rx) begin st <= S_EDELIM; cnt <= 6'd1; end
                            else begin
                                if (first && !txr) rec_add8 <= 1'b1;        // rule 2
                                if (dom_cnt == 3'd7) begin                  // rule 6
                                    if (txr) tec_add8 <= 1'b1; else rec_add8 <= 1'b1;
                                end
                                dom_cnt <= dom_cnt + 3'd1;
                            end
                        end
                        S_EDELIM: begin
                            if (!rx) begin st <= S_OFLAG; cnt <= 6'd0; end  // last bit dominant
                            else if (cnt == 6'd7) begin st <= S_INTER; cnt <= 6'd0; end
                            else cnt <= cnt + 6'd1;
                        end
                        default: ;
                    endcase
                end
            end
        end
    end
endmodule
