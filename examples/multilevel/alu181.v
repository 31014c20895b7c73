// A 74181-style 4-bit ALU, active-high data.
//   M = 1: sixteen logic functions of A and B chosen by S (no carries);
//   M = 0: sixteen arithmetic functions, F = X plus Y plus carry-in, where
//          X = A | (B & S0) | (~B & S1) and Y = A & ((~B & S2) | (B & S3)).
// The carry input CN and output CN4 are active low (CN = 1: no carry in), as on the part.
// AEQB is 1 when F = 1111; P and G are the group propagate and generate, active low.
module alu181 (
    input        M,
    input  [3:0] S,
    input        CN,
    input  [3:0] A,
    input  [3:0] B,
    output [3:0] F,
    output       CN4,
    output       AEQB,
    output       P,
    output       G
);
    wire [3:0] x = A | (B & {4{S[0]}}) | (~B & {4{S[1]}});   // per-bit propagate
    wire [3:0] y = A & ((~B & {4{S[2]}}) | (B & {4{S[3]}}));  // per-bit generate
    wire [4:0] c;                                             // internal carries, active high
    assign c[0] = ~CN;
    assign c[1] = y[0] | (x[0] & c[0]);
    assign c[2] = y[1] | (x[1] & c[1]);
    assign c[3] = y[2] | (x[2] & c[2]);
    assign c[4] = y[3] | (x[3] & c[3]);
    wire [3:0] h = x ^ y;                                     // half sum
    assign F    = M ? ~h : (h ^ c[3:0]);
    assign CN4  = ~c[4];
    assign AEQB = &F;
    assign P    = ~&x;
    assign G    = ~(y[3] | (x[3] & y[2]) | (x[3] & x[2] & y[1]) | (x[3] & x[2] & x[1] & y[0]));
endmodule
