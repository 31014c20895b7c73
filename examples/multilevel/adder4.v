// 4-bit ripple-carry adder: S = A + B + CI, CO the carry out.
// Written as four full adders so the carry chain is the structure the author gave it; each
// carry is the majority of its three inputs, a form with no static hazard.
module adder4 (
    input  [3:0] A,
    input  [3:0] B,
    input        CI,
    output [3:0] S,
    output       CO
);
    wire [4:0] c;
    assign c[0] = CI;
    genvar i;
    generate
        for (i = 0; i < 4; i = i + 1) begin : bit_slice
            assign S[i]     = A[i] ^ B[i] ^ c[i];
            assign c[i + 1] = (A[i] & B[i]) | (A[i] & c[i]) | (B[i] & c[i]);
        end
    endgenerate
    assign CO = c[4];
endmodule
