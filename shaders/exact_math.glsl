// Division, square root and hashing with the same bits on every device. Valid GLSL and, through
// host/dacrt/secondary_rays.hpp, valid C++.
//
// Vulkan guarantees correct rounding for +, - and * only: OpFDiv may be 2.5 ulp off and sqrt
// more, so a ray direction divided or normalized on a GPU would differ from the host's. These
// functions compute the correctly rounded (nearest-even) IEEE results from integer operations,
// identical on the host, on lavapipe and on any GPU. Callers keep their operands normal
// (docs/correctness.md, "Secondary rays"): no subnormal, infinite or NaN input or result.
// DACRT_UNROLL is [[unroll]] in GLSL (llvmpipe's loop limiter counts loop iterations) and
// nothing in C++. The host's own division and square root are IEEE's, correctly rounded, so
// C++ (DACRT_HOST_IEEE_ARITHMETIC) takes them: the same bits, several times faster;
// tests/dacrt/test_secondary_rays.cpp compiles the integer versions too and checks them
// against the host's on millions of operands.
#ifndef DACRT_EXACT_MATH_GLSL
#define DACRT_EXACT_MATH_GLSL

const uint kSignBit = 0x80000000u;
const uint kMantissaBits = 0x7FFFFFu;
const uint kHiddenBit = 0x800000u;

// sign | 2^(exponent - 127) * q / 2^24, rounded to nearest even: q holds 25 bits of the
// magnitude (its top bit set), the last one below the float's precision; sticky tells whether
// anything nonzero was left below that.
float packRounded(uint sign, int exponent, uint q, bool sticky) {
    uint guard = q & 1u;
    q >>= 1u;
    if (guard == 1u && (sticky || (q & 1u) == 1u)) q += 1u;
    if (q == 0x1000000u) {
        q >>= 1u;
        exponent += 1;
    }
    return uintBitsToFloat(sign | (uint(exponent) << 23u) | (q & kMantissaBits));
}

// a / b, correctly rounded, for a zero or normal, b normal and a normal quotient (a
// subnormal a reads as zero). Restoring division of the 24-bit significands: 25 quotient bits,
// the remainder's being nonzero the sticky bit.
float divideRounded(float a, float b) {
#ifdef DACRT_HOST_IEEE_ARITHMETIC
    return a / b;
#else
    uint ua = floatBitsToUint(a);
    uint ub = floatBitsToUint(b);
    uint sign = (ua ^ ub) & kSignBit;
    uint ea = (ua >> 23u) & 0xFFu;
    uint eb = (ub >> 23u) & 0xFFu;
    if (ea == 0u) return uintBitsToFloat(sign);
    uint ma = (ua & kMantissaBits) | kHiddenBit;
    uint mb = (ub & kMantissaBits) | kHiddenBit;
    int exponent = int(ea) - int(eb) + 127;
    if (ma < mb) {  // so that the quotient lies in [1, 2)
        ma <<= 1u;
        exponent -= 1;
    }
    uint q = 0u;
    uint r = ma;
    DACRT_UNROLL for (int i = 0; i < 25; ++i) {  // without branches: their outcome is a coin toss
        uint take = r >= mb ? 1u : 0u;
        r -= mb & (0u - take);
        q = (q << 1u) | take;
        r <<= 1u;
    }
    return packRounded(sign, exponent, q, r != 0u);
#endif
}

// sqrt(x), correctly rounded, for x zero or normal and non-negative (anything else gives 0).
// Digit-by-digit integer square root of the significand shifted left by 25 (50 bits, taken
// two at a time from a high and a low word): 25 root bits, the remainder the sticky bit.
float sqrtRounded(float x) {
#ifdef DACRT_HOST_IEEE_ARITHMETIC
    return x > 0.0f ? sqrt(x) : 0.0f;
#else
    uint ux = floatBitsToUint(x);
    uint ex = (ux >> 23u) & 0xFFu;
    if (ex == 0u || (ux & kSignBit) != 0u) return 0.0f;
    uint m = (ux & kMantissaBits) | kHiddenBit;
    int exponent = int(ex) - 127;
    if ((exponent & 1) != 0) {  // an even exponent halves exactly
        m <<= 1u;
        exponent -= 1;
    }
    uint low = m << 25u;
    uint high = m >> 7u;
    uint q = 0u;
    uint r = 0u;
    DACRT_UNROLL for (int i = 24; i >= 0; --i) {
        uint pair = 2 * i >= 32 ? (high >> uint(2 * i - 32)) & 3u : (low >> uint(2 * i)) & 3u;
        r = (r << 2u) | pair;
        uint trial = (q << 2u) | 1u;
        uint take = r >= trial ? 1u : 0u;
        r -= trial & (0u - take);
        q = (q << 1u) | take;
    }
    return packRounded(0u, (exponent >> 1) + 127, q, r != 0u);
#endif
}

// Components below this are flushed to zero where a normal is made, so that no product of
// up to three of them is subnormal: devices may flush subnormals, the host does not.
const float kSmallestNormalComponent = 9.094947017729282e-13f;  // 2^-40

// v / |v| for a vector whose largest component is normal and at most 2^63: scaled by a power
// of two first (exact), so that the sum of squares neither overflows nor underflows; components
// below 2^-40 of the largest are flushed to zero.
vec3 normalizeRounded(vec3 v) {
    float largest = max(abs(v.x), max(abs(v.y), abs(v.z)));
    uint e = (floatBitsToUint(largest) >> 23u) & 0xFFu;
    float scale = uintBitsToFloat(uint(254 - int(e)) << 23u);  // 2^(127 - e): largest * scale in [1, 2)
    precise vec3 s = v * scale;
    if (abs(s.x) < kSmallestNormalComponent) s.x = 0.0f;
    if (abs(s.y) < kSmallestNormalComponent) s.y = 0.0f;
    if (abs(s.z) < kSmallestNormalComponent) s.z = 0.0f;
    precise float lengthSquared = s.x * s.x + s.y * s.y + s.z * s.z;
    float norm = sqrtRounded(lengthSquared);
    return vec3(divideRounded(s.x, norm), divideRounded(s.y, norm), divideRounded(s.z, norm));
}

// The PCG hash (O'Neill's PCG-RXS-M-XS step on a 32-bit state, as Jarzynski and Olano,
// "Hash Functions for GPU Rendering", JCGT 9(3), 2020, recommend): a counter-based random
// number generator that needs no state between rays.
uint pcgHash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The top 24 bits of a hash as a float in [0, 1), exactly.
float unitInterval(uint bits) {
    return float(bits >> 8u) * 5.9604644775390625e-08f;
}

#endif
