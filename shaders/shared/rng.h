// Random numbers shared by GLSL and C++: integer hashing, a PCG32 stream, and padded, Owen-scrambled Sobol points.
//
// Sample values depend only on (seed, pixel, sample index, dimension), never on which thread asks for them, so images
// are identical for any number of threads.
#ifndef TY_SHARED_RNG_H
#define TY_SHARED_RNG_H

#include "compat.h"
#include "constants.h"

TY_BEGIN

// A 32-bit integer hash with low bias (the "lowbias32" constants found by Chris Wellons' hash prospector).
TY_FUNC uint hashUint(uint x) {
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

TY_FUNC uint hashCombine(uint seed, uint value) { return hashUint(seed ^ (value + 0x9e3779b9u + (seed << 6u) + (seed >> 2u))); }

// The top 24 bits of x as a float in [0, 1).
TY_FUNC float uintToUnitFloat(uint x) { return float(x >> 8u) * (1.0f / 16777216.0f); }

// PCG32 (O'Neill): 64-bit state in two uints so that GLSL without int64 can run it.
struct Pcg32 {
    uint stateLo;
    uint stateHi;
};

// 64-bit multiply-add on (hi, lo) pairs: state = state * 6364136223846793005 + 1442695040888963407.
TY_FUNC void pcg32Step(TY_INOUT(Pcg32) rng) {
    const uint mulLo = 0x4c957f2du, mulHi = 0x5851f42du;
    const uint incLo = 0xf767814fu, incHi = 0x14057b7eu;
    uint lo = rng.stateLo, hi = rng.stateHi;
    // (hi * 2^32 + lo) * (mulHi * 2^32 + mulLo) mod 2^64
    uint loLo = (lo & 0xffffu) * (mulLo & 0xffffu);
    uint loHiA = (lo >> 16u) * (mulLo & 0xffffu);
    uint loHiB = (lo & 0xffffu) * (mulLo >> 16u);
    uint hiHi = (lo >> 16u) * (mulLo >> 16u);
    uint mid = (loLo >> 16u) + (loHiA & 0xffffu) + (loHiB & 0xffffu);
    uint productLo = (loLo & 0xffffu) | (mid << 16u);
    uint productHi = hiHi + (loHiA >> 16u) + (loHiB >> 16u) + (mid >> 16u);
    productHi += lo * mulHi + hi * mulLo;
    uint newLo = productLo + incLo;
    uint carry = newLo < productLo ? 1u : 0u;
    rng.stateLo = newLo;
    rng.stateHi = productHi + incHi + carry;
}

TY_FUNC uint pcg32Next(TY_INOUT(Pcg32) rng) {
    uint oldLo = rng.stateLo, oldHi = rng.stateHi;
    pcg32Step(rng);
    // xorshift-high, then a random rotation: output = rotr32(((old ^ (old >> 18)) >> 27), old >> 59)
    uint xLo = oldLo ^ ((oldLo >> 18u) | (oldHi << 14u));
    uint xHi = oldHi ^ (oldHi >> 18u);
    uint xorshifted = (xLo >> 27u) | (xHi << 5u);
    uint rot = oldHi >> 27u;
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

TY_FUNC Pcg32 pcg32Seed(uint seed, uint stream) {
    Pcg32 rng;
    rng.stateLo = hashUint(seed);
    rng.stateHi = hashUint(stream ^ 0x2545f491u);
    pcg32Step(rng);
    return rng;
}

TY_FUNC float pcg32NextFloat(TY_INOUT(Pcg32) rng) { return uintToUnitFloat(pcg32Next(rng)); }

// ---------------------------------------------------------------------------------------------------------------------
// Owen-scrambled Sobol (0,2)-sequence, padded (Burley 2020, "Practical Hash-based Owen Scrambling"): every pair of
// dimensions is the first two Sobol dimensions with its own index shuffle and scramble, so any number of dimensions is
// available without direction-number tables, and each 2-D projection keeps its (0,2) stratification.

// The first two Sobol dimensions as 32-bit fixed point. Dimension 0 is the van der Corput sequence; dimension 1 uses
// the direction numbers v_0 = 2^31, v_k = v_{k-1} ^ (v_{k-1} >> 1), i.e. v_k = (I + S)^k v_0 with S the right shift.
// By Lucas' theorem (I + S)^k = sum of S^j over the j whose bits are a subset of k's, so dimension 1 is the bit
// reversal of w with w_j = XOR of index bit i over every i that is a superset of j: a subset-sum transform, one masked
// shift per bit of the bit position (5 steps, instead of a loop over 32 index bits). Derivation: docs/reference.md.
TY_FUNC uint sobolDimension1Reversed(uint index) {
    uint w = index;
    w ^= (w >> 1u) & 0x55555555u;
    w ^= (w >> 2u) & 0x33333333u;
    w ^= (w >> 4u) & 0x0f0f0f0fu;
    w ^= (w >> 8u) & 0x00ff00ffu;
    w ^= (w >> 16u) & 0x0000ffffu;
    return w;
}

TY_FUNC uvec2 sobol2(uint index) { return uvec2(bitfieldReverse(index), bitfieldReverse(sobolDimension1Reversed(index))); }

// A hash-based nested uniform scramble of a bit-reversed value: one random permutation per binary subtree.
TY_FUNC uint laineKarrasPermutation(uint x, uint seed) {
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16u) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

TY_FUNC uint nestedUniformScramble(uint x, uint seed) {
    x = bitfieldReverse(x);
    x = laineKarrasPermutation(x, seed);
    return bitfieldReverse(x);
}

// A 2-D point in [0,1)^2 for sample `index` of dimension pair `pair`, for one pixel identified by `pixelSeed`. It is
// nestedUniformScramble() of each coordinate of sobol2(shuffled index) with the bit reversals that cancel left out.
TY_FUNC vec2 sobolSample2D(uint pixelSeed, uint index, uint pair) {
    uint seed = hashCombine(pixelSeed, pair);
    uint shuffled = nestedUniformScramble(index, hashCombine(seed, 0x6c8e9cf5u));
    uint sx = bitfieldReverse(laineKarrasPermutation(shuffled, hashCombine(seed, 0xa511e9b3u)));
    uint sy = bitfieldReverse(laineKarrasPermutation(sobolDimension1Reversed(shuffled), hashCombine(seed, 0x63d83595u)));
    return vec2(min(uintToUnitFloat(sx), kOneMinusEpsilon), min(uintToUnitFloat(sy), kOneMinusEpsilon));
}

TY_END

#endif  // TY_SHARED_RNG_H
