// Wishbone slave (wb_clk_i) to register-access strobe (clk_i) bridge.
//
// The register file lives in the clk_i domain. One access at a time crosses
// with a request/acknowledge toggle handshake: the address, write data and
// direction are held in wb_clk_i flops (stable for the whole access) while
// the request toggle crosses through a 2-flop synchroniser; the read data
// is captured in a clk_i flop and held stable while the acknowledge toggle
// crosses back through another 2-flop synchroniser. No multi-bit value is
// ever sampled while it changes.
//
// Ack latency, counted from the first wb_clk_i edge that sees cyc&stb to the
// edge that presents wb_ack_o (Twb = wb_clk_i period, Tclk = clk_i period):
//   1 Twb (launch) + 4..5 Tclk (2 sync flops, strobe, read data capture)
//   + 3..4 Twb (2 sync flops, registered ack), i.e. 4..5 + (4..5)*Tclk/Twb
//   wb_clk_i cycles: 13..16 cycles at 50 MHz wb_clk_i / 24 MHz clk_i
//   (measured by tb/rtl/tb_can.v, see rtl/README.md).
// wb_ack_o is a one-cycle pulse, raised only if cyc&stb are still held;
// the next access is launched only after the previous one completed.
//
// Reset: wb_rst_i (synchronous to wb_clk_i) sets rst_req, which crosses to
// clk_i through a 2-flop synchroniser; rst_req stays set until the clk_i
// domain is seen in reset (fed back through 2 more flops), so even a
// one-cycle wb_rst_i pulse resets the clk_i domain. No access is launched
// until the clk_i domain has left reset again.
//
// ACK_LEVEL = 1 (not the default) is for masters that poll wb_ack_o through
// a GPIO (the thesis's PIO wiring): the access happens once per cyc&stb
// assertion and wb_ack_o then stays high until cyc&stb fall (four-phase
// handshake), so a slow poll cannot miss it and a held strobe never repeats
// the access. The default (0) is the classic one-cycle pulse.
module can_wb_cdc #(
    parameter ACK_LEVEL = 0
) (
    input  wire       wb_clk_i,
    input  wire       wb_rst_i,
    input  wire [7:0] wb_dat_i,
    output reg  [7:0] wb_dat_o,
    input  wire       wb_cyc_i,
    input  wire       wb_stb_i,
    input  wire       wb_we_i,
    input  wire [7:0] wb_adr_i,
    output wire       wb_ack_o,

    input  wire       clk_i,
    output reg        rst_o,      // clk_i-domain synchronous reset
    output reg        acc_stb,    // one clk_i pulse per access
    output wire       acc_we,
    output wire [7:0] acc_adr,
    output wire [7:0] acc_wdat,
    input  wire [7:0] acc_rdat    // read data, valid the clk after acc_stb
);
    // ---------------- wb_clk_i domain ----------------
    reg       rst_req;
    reg       rst_fb_m, rst_fb_s;
    reg       busy;
    reg       ack_q;              // one-cycle ack (pulse mode)
    reg       served;             // level mode: this strobe has been served
    reg       req_tgl;
    reg [7:0] adr_q, dat_q;
    reg       we_q;
    reg       ack_m, ack_s, ack_d;
    reg       ack_tgl;            // clk_i domain
    reg [7:0] rdat_x;             // clk_i domain, stable while ack crosses

    wire ack_edge = ack_s ^ ack_d;
    wire req_on   = wb_cyc_i & wb_stb_i;
    assign wb_ack_o = ack_q | (served & req_on);
    wire ready    = !wb_rst_i && !rst_req && !rst_fb_s;

    always @(posedge wb_clk_i) begin
        rst_fb_m <= rst_o;
        rst_fb_s <= rst_fb_m;
        ack_m    <= ack_tgl;
        ack_s    <= ack_m;
        if (wb_rst_i) begin
            rst_req  <= 1'b1;
            busy     <= 1'b0;
            req_tgl  <= 1'b0;
            ack_d    <= 1'b0;
            ack_m    <= 1'b0;
            ack_s    <= 1'b0;
            ack_q    <= 1'b0;
            served   <= 1'b0;
            wb_dat_o <= 8'h00;
            adr_q    <= 8'h00;
            dat_q    <= 8'h00;
            we_q     <= 1'b0;
        end else begin
            if (rst_fb_s) rst_req <= 1'b0;
            ack_d    <= ack_s;
            ack_q    <= 1'b0;
            if (!req_on) served <= 1'b0;
            if (busy && ack_edge) begin
                busy     <= 1'b0;
                if (ACK_LEVEL != 0) served <= req_on;
                else ack_q <= req_on;
                wb_dat_o <= rdat_x;
            end else if (!busy && !ack_q && !served && ready && req_on) begin
                busy    <= 1'b1;
                req_tgl <= ~req_tgl;
                adr_q   <= wb_adr_i;
                dat_q   <= wb_dat_i;
                we_q    <= wb_we_i;
            end
        end
    end

    // ---------------- clk_i domain ----------------
    reg rst_m;
    reg req_m, req_s, req_d;
    reg acc_stb_d;

    assign acc_we   = we_q;
    assign acc_adr  = adr_q;
    assign acc_wdat = dat_q;

    always @(posedge clk_i) begin
        rst_m <= rst_req;
        rst_o <= rst_m;
    end

    always @(posedge clk_i) begin
        if (rst_o) begin
            req_m   <= 1'b0;
            req_s   <= 1'b0;
            req_d   <= 1'b0;
            acc_stb <= 1'b0;
            acc_stb_d <= 1'b0;
            ack_tgl <= 1'b0;
            rdat_x  <= 8'h00;
        end else begin
            req_m   <= req_tgl;
            req_s   <= req_m;
            req_d   <= req_s;
            acc_stb <= req_s ^ req_d;
            acc_stb_d <= acc_stb;
            if (acc_stb_d) begin
                rdat_x  <= acc_rdat;
                ack_tgl <= ~ack_tgl;
            end
        end
    end
endmodule
