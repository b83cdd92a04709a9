// A seeded random source that gives the same numbers with every standard library: std::uniform_real_distribution
// differs between implementations, raw mt19937_64 bits do not. Used by the CLI scenes, the testkit fixtures and the
// test generators (tests/support), so a fixed seed gives the same shapes and poses on every machine.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace batchcol::testkit {

class PortableRandom {
 public:
  explicit PortableRandom(std::uint64_t seed) : engine_(seed) {}
  // Raw 64-bit draws: the standard fixes mt19937_64's output sequence (not the std:: distributions built on it, so
  // this class is deliberately not a UniformRandomBitGenerator: a std:: distribution fed from it does not compile).
  std::uint64_t operator()() { return engine_(); }
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  std::size_t index(std::size_t n) { return std::min(n - 1, static_cast<std::size_t>(uniform() * double(n))); }
  Eigen::Vector3d unit_vector() {
    const double z = uniform(-1.0, 1.0), phi = uniform(0.0, 2.0 * kPi), s = std::sqrt(1.0 - z * z);
    return {s * std::cos(phi), s * std::sin(phi), z};
  }
  // Uniformly distributed rotation (Shoemake 1992).
  Eigen::Quaterniond rotation() {
    const double u1 = uniform(), a = 2.0 * kPi * uniform(), b = 2.0 * kPi * uniform();
    const double s = std::sqrt(1.0 - u1), t = std::sqrt(u1);
    return Eigen::Quaterniond(t * std::cos(b), s * std::sin(a), s * std::cos(a), t * std::sin(b)).normalized();
  }

 private:
  static constexpr double kPi = 3.14159265358979323846;
  std::mt19937_64 engine_;
};

}  // namespace batchcol::testkit
