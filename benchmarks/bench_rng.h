#pragma once
// The benchmarks' random numbers: a seeded generator of our own, so that every run, shard and library
// sees the same states, segments and pairs whatever the standard library.
#include <clearway/math.h>

#include <cmath>
#include <cstdint>

namespace clearway::bench {

/// splitmix64 with uniform, normal, unit-vector and rotation draws.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  // splitmix64
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1p-53; }
  double normal() {  // Box–Muller
    const double u1 = 1.0 - uniform(0.0, 1.0), u2 = uniform(0.0, 1.0);
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  Vec3 unitVector() {
    for (;;) {
      const Vec3 v(normal(), normal(), normal());
      const double n = v.norm();
      if (n > 1e-6) return v / n;
    }
  }
  Vec3 inBall() {
    for (;;) {
      const Vec3 v(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      if (v.squaredNorm() <= 1.0) return v;
    }
  }
  // A uniformly distributed rotation (a normalised 4D Gaussian is a uniform unit quaternion).
  clearway::Pose pose(const Vec3& t) {
    return clearway::Pose::fromQuaternion(normal(), normal(), normal(), normal() + 1e-12, t);
  }

 private:
  std::uint64_t state_;
};

}  // namespace clearway::bench
