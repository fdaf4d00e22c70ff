// Deterministic random numbers for the synthetic-drive simulator. The engine is
// std::mt19937_64 (its output sequence is fixed by the C++ standard); uniform and normal
// variates are derived here by hand because std::*_distribution are implementation-defined,
// so the same seed gives the same drive with any standard library.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace ipm_road_mapper {
namespace sim {

// SplitMix64 finalizer: a well-mixed 64-bit hash, used to derive independent stream seeds.
inline std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

// Independent random streams of one drive. Each purpose draws from its own stream so that
// changing one noise knob does not reshuffle the others.
enum class RandomStream : std::uint64_t {
  kOdometry = 1,
  kBodyMotion = 2,
  kSegmentation = 3,  // indexed by frame
  kImage = 4,
  kSplit = 5,  // split instances, indexed by frame
};

// A seeded generator with platform-independent uniform and normal variates.
class SimRandom {
 public:
  explicit SimRandom(std::uint64_t seed) : engine_(seed) {}

  // Generator of `stream` (and sub-index, e.g. the frame number) for a drive seed.
  static SimRandom ForStream(std::uint64_t seed, RandomStream stream, std::uint64_t index = 0) {
    const std::uint64_t s =
        SplitMix64(seed ^ SplitMix64(static_cast<std::uint64_t>(stream) * 0x100000001B3ULL +
                                     SplitMix64(index)));
    return SimRandom(s);
  }

  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  // Uniform in [a, b).
  double Uniform(double a, double b) { return a + (b - a) * Uniform(); }

  // Uniform integer in [lo, hi] (inclusive); the bias of the modulo is negligible here.
  int UniformInt(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }

  // True with probability p.
  bool Bernoulli(double p) { return Uniform() < p; }

  // Standard normal variate (Box-Muller; the second value of each pair is kept).
  double Normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

  // Poisson variate with the given mean (Knuth's method; fine for small means).
  int Poisson(double mean) {
    if (mean <= 0.0) return 0;
    const double limit = std::exp(-mean);
    int k = 0;
    double p = Uniform();
    while (p > limit && k < 1000) {
      ++k;
      p *= Uniform();
    }
    return k;
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace sim
}  // namespace ipm_road_mapper
