// Acceptance filter (SJA1000 datasheet 6.3.9 and 6.4.15). Combinational.
// Mask bit 1 = "don't care". BasicCAN: ACR/AMR against ID.10..ID.3 of
// standard frames. An extended frame is never accepted in BasicCAN mode: the
// SJA1000 is "extended frame passive in PCA82C200 compatible mode" (datasheet
// features list): it checks and acknowledges the frame but does not store it.
// PeliCAN single filter (AFM = 1) and dual filter (AFM = 0), for standard and
// extended frames; data-byte bits are compared only for bytes the frame
// actually carries (remote frames and short frames pass those bits).
module can_acf (
    input  wire        peli,
    input  wire        afm,
    input  wire [31:0] acr,      // ACR0 in [31:24] ... ACR3 in [7:0]
    input  wire [31:0] amr,
    input  wire [28:0] id,       // standard ID in [28:18]
    input  wire        ide,
    input  wire        rtr,
    input  wire [3:0]  dlc,
    input  wire [15:0] data12,   // data bytes 1 and 2
    output wire        accept
);
    wire [7:0] acr0 = acr[31:24], acr1 = acr[23:16], acr2 = acr[15:8], acr3 = acr[7:0];
    wire [7:0] amr0 = amr[31:24], amr1 = amr[23:16], amr2 = amr[15:8], amr3 = amr[7:0];
    wire [3:0] nd   = (rtr || dlc == 4'd0) ? 4'd0 : dlc;   // only 0 / 1 / >=2 matter
    wire       has1 = (nd != 4'd0);
    wire       has2 = (nd > 4'd1);

    // match: every bit equal or masked
    function m8(input [7:0] v, input [7:0] c, input [7:0] k);
        m8 = (((v ^ c) & ~k) == 8'h00);
    endfunction

    // BasicCAN
    wire basic_ok = !ide && m8(id[28:21], acr0, amr0);

    // PeliCAN single filter
    wire s_std = m8(id[28:21], acr0, amr0) &&
                 m8({id[20:18], rtr, 4'b0000}, acr1, amr1 | 8'h0F) &&
                 (!has1 || m8(data12[15:8], acr2, amr2)) &&
                 (!has2 || m8(data12[7:0], acr3, amr3));
    wire s_ext = m8(id[28:21], acr0, amr0) && m8(id[20:13], acr1, amr1) &&
                 m8(id[12:5], acr2, amr2) &&
                 m8({id[4:0], rtr, 2'b00}, acr3, amr3 | 8'h03);

    // PeliCAN dual filter
    wire d_std1 = m8(id[28:21], acr0, amr0) &&
                  m8({id[20:18], rtr, 4'b0000}, acr1, amr1 | 8'h0F) &&
                  (!has1 || (m8({data12[15:12], 4'b0000}, {acr1[3:0], 4'b0000}, {amr1[3:0], 4'hF}) &&
                             m8({4'b0000, data12[11:8]}, {4'b0000, acr3[3:0]}, {4'hF, amr3[3:0]})));
    wire d_std2 = m8(id[28:21], acr2, amr2) &&
                  m8({id[20:18], rtr, 4'b0000}, acr3, amr3 | 8'h0F);
    wire d_ext1 = m8(id[28:21], acr0, amr0) && m8(id[20:13], acr1, amr1);
    wire d_ext2 = m8(id[28:21], acr2, amr2) && m8(id[20:13], acr3, amr3);

    wire peli_ok = afm ? (ide ? s_ext : s_std)
                       : (ide ? (d_ext1 || d_ext2) : (d_std1 || d_std2));

    assign accept = peli ? peli_ok : basic_ok;
endmodule
