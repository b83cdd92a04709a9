// A counter-based Gaussian generator: every (seed, pair, sample, stream) key starts its own SplitMix64 sequence
// (Steele, Lea, Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014), so a sample's noise depends
// on its key only, never on which thread or batch chunk draws it. That is what makes the smoothed derivatives
// bitwise identical for any thread count; a shared engine would hand out numbers in scheduling order.
#pragma once

#include <cmath>
#include <cstdint>

namespace batchcol::detail {

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

class CounterRng {
 public:
  // The key words are chained through the mixer (not XORed together), so keys differing in any word give
  // unrelated sequences.
  CounterRng(std::uint64_t seed, std::uint64_t pair, std::uint64_t sample, std::uint64_t stream)
      : state_(splitmix64(splitmix64(splitmix64(splitmix64(seed) ^ pair) ^ sample) ^ stream)) {}

  std::uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return splitmix64(state_);
  }
  /// Uniform in (0, 1]: 53 random bits, shifted by one so log() below never sees 0.
  double uniform() { return static_cast<double>((next() >> 11) + 1) * 0x1.0p-53; }
  /// Two independent standard normals (Box-Muller).
  void gaussian_pair(double& g0, double& g1) {
    const double radius = std::sqrt(-2.0 * std::log(uniform()));
    const double angle = 6.283185307179586 * uniform();
    g0 = radius * std::cos(angle);
    g1 = radius * std::sin(angle);
  }

 private:
  std::uint64_t state_;
};

/// z in R^N, standard normal, for (seed, pair, sample, stream); N even.
template <int N> void gaussian_vector(std::uint64_t seed, std::uint64_t pair, std::uint64_t sample,
                                      std::uint64_t stream, double* z) {
  CounterRng rng(seed, pair, sample, stream);
  for (int k = 0; k < N; k += 2) rng.gaussian_pair(z[k], z[k + 1]);
}

}  // namespace batchcol::detail
