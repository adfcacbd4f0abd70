// SJA1000 register addresses (CAN address space, 8-bit), as localparams.
// Source: SJA1000 datasheet (2000 Jan 04), sections 6.3.1 (BasicCAN layout)
// and 6.4.1 (PeliCAN layout). The one register map lives in crates/regmap;
// a test there checks these constants against it, so edit both together.
// Included inside module bodies (localparams are module-scoped).

// ---- BasicCAN view (CDR.7 = 0); addresses 32..127 mirror 0..31 ----
localparam [7:0] BC_CR     = 8'd0;   // control register
localparam [7:0] BC_CMR    = 8'd1;   // command register (write only, reads FFh)
localparam [7:0] BC_SR     = 8'd2;   // status register
localparam [7:0] BC_IR     = 8'd3;   // interrupt register (read clears)
localparam [7:0] BC_ACR    = 8'd4;   // acceptance code (reset mode)
localparam [7:0] BC_AMR    = 8'd5;   // acceptance mask (reset mode)
localparam [7:0] BC_BTR0   = 8'd6;   // bus timing 0 (reset mode)
localparam [7:0] BC_BTR1   = 8'd7;   // bus timing 1 (reset mode)
localparam [7:0] BC_OCR    = 8'd8;   // output control (reset mode)
localparam [7:0] BC_TEST   = 8'd9;   // test register (not implemented)
localparam [7:0] BC_TXB    = 8'd10;  // transmit buffer 10..19 (operating mode)
localparam [7:0] BC_TXB_LEN = 8'd10;
localparam [7:0] BC_RXB    = 8'd20;  // receive buffer window 20..29
localparam [7:0] BC_RXB_LEN = 8'd10;
localparam [7:0] BC_CDR    = 8'd31;  // clock divider (common)

// ---- PeliCAN view (CDR.7 = 1); addresses 128..255 mirror 0..127 ----
localparam [7:0] PC_MOD    = 8'd0;   // mode
localparam [7:0] PC_CMR    = 8'd1;   // command (write only, reads 00h)
localparam [7:0] PC_SR     = 8'd2;   // status
localparam [7:0] PC_IR     = 8'd3;   // interrupt (read clears all but RI)
localparam [7:0] PC_IER    = 8'd4;   // interrupt enable
localparam [7:0] PC_BTR0   = 8'd6;   // bus timing 0
localparam [7:0] PC_BTR1   = 8'd7;   // bus timing 1
localparam [7:0] PC_OCR    = 8'd8;   // output control
localparam [7:0] PC_TEST   = 8'd9;   // test (not implemented)
localparam [7:0] PC_ALC    = 8'd11;  // arbitration lost capture
localparam [7:0] PC_ECC    = 8'd12;  // error code capture
localparam [7:0] PC_EWLR   = 8'd13;  // error warning limit
localparam [7:0] PC_RXERR  = 8'd14;  // RX error counter
localparam [7:0] PC_TXERR  = 8'd15;  // TX error counter
localparam [7:0] PC_TXB    = 8'd16;  // TX buffer 16..28 (write, operating mode)
localparam [7:0] PC_RXB    = 8'd16;  // RX buffer window 16..28 (read, operating mode)
localparam [7:0] PC_BUF_LEN = 8'd13;
localparam [7:0] PC_ACR0   = 8'd16;  // acceptance code 0..3 (reset mode) 16..19
localparam [7:0] PC_AMR0   = 8'd20;  // acceptance mask 0..3 (reset mode) 20..23
localparam [7:0] PC_RMC    = 8'd29;  // RX message counter
localparam [7:0] PC_RBSA   = 8'd30;  // RX buffer start address
localparam [7:0] PC_CDR    = 8'd31;  // clock divider
localparam [7:0] PC_RXFIFO = 8'd32;  // internal RX FIFO RAM 32..95 (read)
localparam [7:0] PC_RXFIFO_LEN = 8'd64;
localparam [7:0] PC_TXRAM  = 8'd96;  // TX buffer readback 96..108
