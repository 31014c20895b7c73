// 16-bit ripple-carry adder: S = A + B + CI, CO the carry out.
// Written as sixteen full adders so the carry chain is the structure the author gave it; each
// carry is the majority of its three inputs, a form with no static hazard.
module adder16 (
    input  [15:0] A,
    input  [15:0] B,
    input        CI,
    output [15:0] S,
    output       CO
);
    wire [16:0] c;
    assign c[0] = CI;
    genvar i;
    generate
        for (i = 0; i < 16; i = i + 1) begin : bit_slice
            assign S[i]     = A[i] ^ B[i] ^ c[i];
            assign c[i + 1] = (A[i] & B[i]) | (A[i] & c[i]) | (B[i] & c[i]);
        end
    endgenerate
    assign CO = c[16];
endmodule
