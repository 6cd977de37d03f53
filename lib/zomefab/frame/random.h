// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The frame stage's random numbers: xoshiro256** seeded by splitmix64, with bounded
/// integers and doubles defined here (not by the standard library's distributions, whose
/// results differ between implementations), so a seed gives the same frame everywhere.
#pragma once

#include <cstdint>

namespace zomefab::frame {

/// splitmix64 step: a well-mixed 64-bit value from @p x (Steele, Lea, Flood 2014).
inline uint64_t splitMix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/// The seed of stream @p index (a chain, a τ run) derived from the user's --seed and a salt that
/// keeps the families of streams apart.
inline uint64_t deriveSeed(uint64_t seed, uint64_t salt, uint64_t index) {
    return splitMix64(splitMix64(seed ^ splitMix64(salt)) + index);
}

/// xoshiro256** 1.0 (Blackman, Vigna): fast, 256-bit state, plenty for annealing.
class Rng {
public:
    explicit Rng(uint64_t seed) {
        for (uint64_t& s : mState) s = seed = splitMix64(seed);
    }
    uint64_t next() {
        const uint64_t result = rotl(mState[1] * 5, 7) * 9;
        const uint64_t t = mState[1] << 17;
        mState[2] ^= mState[0];
        mState[3] ^= mState[1];
        mState[1] ^= mState[2];
        mState[0] ^= mState[3];
        mState[2] ^= t;
        mState[3] = rotl(mState[3], 45);
        return result;
    }
    /// Uniform integer in [0, n), n ≥ 1: Lemire's multiply-shift on the high 32 bits (the bias of
    /// skipping the rejection step, < n/2³², is irrelevant here and keeps one draw per call).
    uint32_t below(uint32_t n) { return uint32_t((next() >> 32) * uint64_t(n) >> 32); }
    /// Uniform double in [0, 1) with 53 random bits.
    double uniform() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }

private:
    static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
    uint64_t mState[4];
};

}  // namespace zomefab::frame
