// Three 256-byte Avalon-MM slaves, one per transfer timing the Avalon
// agents know, for examples/test_avalon_agents.py.

// waitrequest: held high for 2 cycles of each transfer.
module av_slave_wait (
    input  wire       clk, reset,
    input  wire [7:0] address,
    input  wire       chipselect, read, write,
    input  wire [7:0] writedata,
    output wire [7:0] readdata,
    output wire       waitrequest
);
    reg [7:0] mem [0:255];
    reg [1:0] cnt;
    wire req = chipselect & (read | write);
    assign waitrequest = !(req && cnt == 2'd2);
    assign readdata = mem[address];
    always @(posedge clk) begin
        cnt <= (reset || !waitrequest || !req) ? 2'd0 : cnt + 2'd1;
        if (req && write && !waitrequest) mem[address] <= writedata;
    end
endmodule

// Pipelined reads: waitrequest for 1 cycle, the read data 2 cycles after
// the command with readdatavalid.
module av_slave_pipe (
    input  wire       clk, reset,
    input  wire [7:0] address,
    input  wire       chipselect, read, write,
    input  wire [7:0] writedata,
    output wire [7:0] readdata,
    output wire       waitrequest,
    output wire       readdatavalid
);
    reg [7:0] mem [0:255];
    reg cnt, v1, v2;
    reg [7:0] d1, d2;
    wire req = chipselect & (read | write);
    assign waitrequest = !(req && cnt);
    assign readdatavalid = v2;
    assign readdata = d2;
    always @(posedge clk) begin
        cnt <= (reset || !waitrequest || !req) ? 1'b0 : 1'b1;
        if (req && write && !waitrequest) mem[address] <= writedata;
        v1 <= !reset && req && read && !waitrequest;
        d1 <= mem[address];
        v2 <= v1;
        d2 <= d1;
    end
endmodule

// Fixed wait states (read 2, write 1), no waitrequest.
module av_slave_fixed (
    input  wire       clk, reset,
    input  wire [7:0] address,
    input  wire       chipselect, read, write,
    input  wire [7:0] writedata,
    output wire [7:0] readdata
);
    reg [7:0] mem [0:255];
    assign readdata = mem[address];
    always @(posedge clk) if (chipselect && write) mem[address] <= writedata;
endmodule
