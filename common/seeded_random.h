#pragma once
// Deterministic pseudo-random numbers for study designs. Trial order and sides must be reproducible from the
// stored seed on any machine and standard library, so nothing here uses std::uniform_int_distribution or
// std::shuffle (their algorithms are implementation-defined); std::mt19937_64's output sequence is fixed by the
// C++ standard.
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

namespace skinlab {

// SplitMix64 finaliser (Steele, Lea & Flood 2014): mixes a 64-bit value into a well-distributed one. Used to
// derive independent seeds (per participant, per pair) from the design seed.
inline std::uint64_t mixSeed(std::uint64_t value) {
    value += 0x9E3779B97F4A7C15ull;
    value = (value ^ (value >> 30)) * 0xBF58476D1CE4E5B9ull;
    value = (value ^ (value >> 27)) * 0x94D049BB133111EBull;
    return value ^ (value >> 31);
}

inline std::uint64_t combineSeed(std::uint64_t seed, std::uint64_t salt) { return mixSeed(seed ^ mixSeed(salt)); }

class SeededRandom {
public:
    explicit SeededRandom(std::uint64_t seed) : engine_(seed) {}

    // Uniform integer in [0, bound) by rejection (no modulo bias). bound must be > 0.
    std::uint64_t below(std::uint64_t bound) {
        const std::uint64_t limit = UINT64_MAX - (UINT64_MAX % bound);
        std::uint64_t value = engine_();
        while (value >= limit) value = engine_();
        return value % bound;
    }
    bool coin() { return (engine_() >> 63) != 0; }
    // Uniform double in [0, 1) from the top 53 bits.
    double unit() { return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0); }

    // Fisher–Yates shuffle.
    template <class T>
    void shuffle(std::vector<T>& items) {
        for (std::size_t i = items.size(); i > 1; --i) {
            std::size_t j = static_cast<std::size_t>(below(i));
            std::swap(items[i - 1], items[j]);
        }
    }

private:
    std::mt19937_64 engine_;
};

} // namespace skinlab
