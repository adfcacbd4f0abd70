// 64-byte receive FIFO (SJA1000 RXFIFO): messages are stored in the format
// of the active mode (PeliCAN: frame info, 2 or 4 ID bytes, data; BasicCAN:
// 2 descriptor bytes, data). RBSA points at the message shown in the
// receive buffer window, RMC counts stored messages, a message that does
// not fit is dropped and sets DOS (data overrun).
// A stored message is copied into the RAM one byte per clk (at most 13 clk,
// well inside the 5 bit times before the next frame's identifier).
// The RAM has one synchronous write port and one synchronous read port
// (block-RAM friendly): the read port serves host reads (data one clk after
// the access strobe) and otherwise looks at the header of the message at
// RBSA, which a release (RRB) needs one clk later to know its length.
module can_rxfifo (
    input  wire        clk,
    input  wire        rst,
    input  wire        clr,        // reset mode: FIFO empty, writes start at RBSA
    input  wire        peli,
    input  wire        store,      // pulse: store the frame below
    input  wire [28:0] id,
    input  wire        ide,
    input  wire        rtr,
    input  wire [3:0]  dlc,
    input  wire [63:0] data,
    input  wire        rrb,        // release receive buffer
    input  wire        cdo,        // clear data overrun
    input  wire        rbsa_wr,    // host write of RBSA (reset mode)
    input  wire [7:0]  wdat,
    input  wire        host_wr,    // host writes the RAM (reset mode)
    input  wire        host_rd,    // host reads the RAM (window or CAN address 32..95)
    input  wire [5:0]  host_adr,   // absolute RAM address
    output reg  [7:0]  rd_q,       // RAM data, one clk after host_rd
    output reg  [6:0]  rmc,
    output reg  [5:0]  rbsa,
    output wire        rbs,
    output reg         dos,
    output reg         dos_set,    // pulse: DOS 0 -> 1
    output wire        wbusy_o,    // a stored message is being copied into the RAM
    output wire        commit_o    // its last byte is written now (RMC counts it at this edge)
);
    reg [7:0] ram [0:63];
    reg [5:0] wr_ptr;
    reg [6:0] fill;               // bytes in use
    reg       wbusy;
    reg [3:0] wk, wlen;

    assign rbs     = (rmc != 7'd0);

    wire [3:0] nd  = (rtr || dlc == 4'd0) ? 4'd0 : (dlc[3] ? 4'd8 : dlc);
    wire [3:0] len = nd + (peli ? (ide ? 4'd5 : 4'd3) : 4'd2);

    // length of the message at RBSA
    // header byte with the length: PeliCAN frame info (FF, RTR, DLC) at
    // RBSA, BasicCAN descriptor byte 1 (RTR, DLC) at RBSA + 1
    reg        rrb_q;              // release pending, header in rd_q
    wire [5:0] hdr_adr = peli ? rbsa : rbsa + 6'd1;
    /* verilator lint_off UNUSEDSIGNAL */
    wire [7:0] h = rd_q;           // bit 5 carries no length information in either format
    /* verilator lint_on UNUSEDSIGNAL */
    wire [3:0] hnd_p = (h[6] || h[3:0] == 4'd0) ? 4'd0 : (h[3] ? 4'd8 : h[3:0]);
    wire [3:0] hnd_b = (h[4] || h[3:0] == 4'd0) ? 4'd0 : (h[3] ? 4'd8 : h[3:0]);
    wire [3:0] hlen  = peli ? (hnd_p + (h[7] ? 4'd5 : 4'd3)) : (hnd_b + 4'd2);

    // byte wk of the message being written
    reg [7:0] wbyte;
    reg [3:0] dj;            // data byte index; always < 8 where used
    /* verilator lint_off UNUSEDSIGNAL */
    wire      dj_msb = dj[3];
    /* verilator lint_on UNUSEDSIGNAL */
    always @* begin
        dj = 4'd0;
        if (peli) begin
            if (wk == 4'd0) wbyte = {ide, rtr, 2'b00, dlc};
            else if (!ide && wk == 4'd1) wbyte = id[28:21];
            else if (!ide && wk == 4'd2) wbyte = {id[20:18], rtr, 4'b0000};
            else if (ide && wk == 4'd1) wbyte = id[28:21];
            else if (ide && wk == 4'd2) wbyte = id[20:13];
            else if (ide && wk == 4'd3) wbyte = id[12:5];
            else if (ide && wk == 4'd4) wbyte = {id[4:0], rtr, 2'b00};
            else begin
                dj = wk - (ide ? 4'd5 : 4'd3);
                wbyte = data[6'd63 - {dj[2:0], 3'b000} -: 8];
            end
        end else begin
            if (wk == 4'd0) wbyte = id[28:21];
            else if (wk == 4'd1) wbyte = {id[20:18], rtr, dlc};
            else begin
                dj = wk - 4'd2;
                wbyte = data[6'd63 - {dj[2:0], 3'b000} -: 8];
            end
        end
    end

    wire do_rrb    = rrb_q && rmc != 7'd0 && !clr;
    wire fits      = ({3'b000, len} + fill) <= 7'd64;
    wire start     = store && !wbusy && !clr;
    wire commit    = wbusy && (wk == wlen - 4'd1);
    assign wbusy_o  = wbusy;
    assign commit_o = commit;

    wire [5:0] wr_adr = wr_ptr + {2'b00, wk};       // wraps at 64
    always @(posedge clk) begin
        if (wbusy && !clr) ram[wr_adr] <= wbyte;
        else if (host_wr && clr) ram[host_adr] <= wdat;
        rd_q <= ram[host_rd ? host_adr : hdr_adr];
    end

    always @(posedge clk) begin
        dos_set <= 1'b0;
        rrb_q   <= rrb && !host_rd;
        if (rst) begin
            rmc <= 7'd0; rbsa <= 6'd0; dos <= 1'b0; wr_ptr <= 6'd0; fill <= 7'd0;
            wbusy <= 1'b0; wk <= 4'd0; wlen <= 4'd0;
        end else if (clr) begin
            rmc <= 7'd0; fill <= 7'd0; dos <= 1'b0; wbusy <= 1'b0; wk <= 4'd0;
            if (rbsa_wr) begin rbsa <= wdat[5:0]; wr_ptr <= wdat[5:0]; end
            else wr_ptr <= rbsa;
        end else begin
            if (cdo) dos <= 1'b0;
            if (start) begin
                if (fits) begin
                    wbusy <= 1'b1; wk <= 4'd0; wlen <= len;
                end else begin
                    if (!dos) dos_set <= 1'b1;
                    dos <= 1'b1;
                end
            end else if (wbusy) begin
                wk <= wk + 4'd1;
                if (commit) wbusy <= 1'b0;
            end
            if (commit) wr_ptr <= wr_ptr + {2'b00, wlen};
            fill <= fill + (commit ? {3'b000, wlen} : 7'd0) - (do_rrb ? {3'b000, hlen} : 7'd0);
            rmc  <= rmc + (commit ? 7'd1 : 7'd0) - (do_rrb ? 7'd1 : 7'd0);
            if (do_rrb) rbsa <= rbsa + {2'b00, hlen};
        end
    end
endmodule
