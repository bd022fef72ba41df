#pragma once
// Random joint vectors for the kinematics tests: each variable uniform within its limits (±4 where a limit
// is not finite), then stretched as the test asks (angles far past the ranges, where sin and cos fall back
// to libm).
#include <clearway/kinematics/robot_model.h>

#include <cmath>
#include <random>
#include <vector>

namespace clearway::test {

/// n joint vectors of m drawn from `seed`; variable v of state s is then multiplied by stretch(s, v, draw),
/// where draw() gives the next uniform number in [0, 1) (1: left as drawn).
template <class Stretch>
std::vector<std::vector<double>> randomJointVectors(const RobotModel& m, int n, unsigned seed, Stretch&& stretch) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto draw = [&] { return u(rng); };
  std::vector<std::vector<double>> out(n, std::vector<double>(m.variableCount()));
  for (int s = 0; s < n; ++s)
    for (int v = 0; v < m.variableCount(); ++v) {
      const JointVariable& var = m.variables()[v];
      const double lo = std::isfinite(var.lower) ? var.lower : -4.0, hi = std::isfinite(var.upper) ? var.upper : 4.0;
      const double x = lo + (hi - lo) * draw();
      out[s][v] = x * stretch(s, v, draw);
    }
  return out;
}

}  // namespace clearway::test
