// Arithmetic primitives of the datapath, one per function of model/evclust/fixed/arith.py.
// Every intermediate is a 64-bit two's-complement word: the model's int64. Synthesis trims
// the words to the bits the operands actually carry (Yosys wreduce). Included inside each
// module body, as functions are module-scoped.

// x + round(((u << guard) - x) * beta * 2^-beta_frac): an alpha filter step (arith.alpha_step).
// Floor, or round half up when `nearest`.
function automatic signed [63:0] alpha_step;
    input signed [63:0] x;
    input signed [63:0] u;
    input signed [63:0] beta;
    input integer beta_frac;
    input integer guard;
    input nearest;
    reg signed [63:0] product;
    begin
        product = ((u <<< guard) - x) * beta;
        if (nearest)
            product = product + (64'sd1 <<< (beta_frac - 1));
        alpha_step = x + (product >>> beta_frac);
    end
endfunction

// v clipped to [lo, hi] (arith.saturate).
function automatic signed [63:0] saturate;
    input signed [63:0] v;
    input signed [63:0] lo;
    input signed [63:0] hi;
    begin
        saturate = v < lo ? lo : (v > hi ? hi : v);
    end
endfunction

// A raw value moved from from_frac to to_frac fraction bits, floor when dropping.
function automatic signed [63:0] align;
    input signed [63:0] v;
    input integer from_frac;
    input integer to_frac;
    begin
        align = to_frac >= from_frac ? v <<< (to_frac - from_frac) : v >>> (from_frac - to_frac);
    end
endfunction

function automatic signed [63:0] abs64;
    input signed [63:0] v;
    begin
        abs64 = v < 0 ? -v : v;
    end
endfunction

function automatic signed [63:0] min64;
    input signed [63:0] a;
    input signed [63:0] b;
    begin
        min64 = a < b ? a : b;
    end
endfunction

// a * b as shifted additions over b's b_bits bits (two's complement: b's top bit is its sign;
// give an unsigned b one bit more). Synthesis builds it from logic cells, where a `*` would
// take a whole DSP block however narrow its operands: for the narrow multiplies that run per
// palette entry. Slice the result to the product's width, so synthesis trims the additions.
function automatic signed [63:0] mul_by_addition;
    input signed [63:0] a;
    input signed [63:0] b;
    input integer b_bits;
    integer i;
    begin
        mul_by_addition = 64'sd0;
        for (i = 0; i < b_bits - 1; i = i + 1)
            mul_by_addition = mul_by_addition + ((a <<< i) & {64{b[i]}});
        mul_by_addition = mul_by_addition - ((a <<< (b_bits - 1)) & {64{b[b_bits - 1]}});
    end
endfunction

// An unsigned field of up to 63 bits as a 64-bit word (give it zero-extended).
function automatic signed [63:0] u64;
    input [62:0] v;
    begin
        u64 = {1'b0, v};
    end
endfunction

// 1 if v lies outside [lo, hi]: a saturation, for the status counters (two bits, so that two
// axes' counts add).
function automatic [1:0] outside;
    input signed [63:0] v;
    input signed [63:0] lo;
    input signed [63:0] hi;
    begin
        outside = (v < lo || v > hi) ? 2'd1 : 2'd0;
    end
endfunction
