// A tiny design for vbridge's own tests: an 8-bit counter with a
// synchronous reset and a step size set by a define.
`ifndef STEP
`define STEP 1
`endif
module counter (
    input  wire       clk,
    input  wire       rst,
    input  wire       en,
    output reg  [7:0] count,
    output wire       wrapped
);
    assign wrapped = (count == 8'd0);
    always @(posedge clk)
        if (rst) count <= 8'd0;
        else if (en) count <= count + 8'd`STEP;
endmodule
