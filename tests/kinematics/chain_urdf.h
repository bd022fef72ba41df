#pragma once
// A serial chain of the joint kinds given, as URDF text, for the kinematics tests: each joint's origin has
// every coordinate and angle nonzero (so that no term of a product vanishes and a change in the order of
// the sums shows), revolute and prismatic joints their limits at ±3.
#include <iterator>
#include <random>
#include <string>
#include <vector>

namespace clearway::test {

/// One joint of a chain: its URDF type, its axis ("" for none) and the joint it mimics ("" for none).
struct ChainJoint {
  const char* type;
  const char* axis;
  const char* mimic;
};

/// The chain l0 → j0 → l1 → j1 → ...: joint k joins link k to link k + 1; a mimic follows with multiplier
/// −1.5 and offset 0.25. The origins are drawn from a fixed seed: the same text every time.
inline std::string chainUrdf(const std::vector<ChainJoint>& joints) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto num = [&] { return std::to_string(u(rng) * 0.7 + (u(rng) < 0 ? -0.3 : 0.3)); };
  std::string urdf = "<robot name=\"chain\"><link name=\"l0\"/>";
  for (int k = 0; k < static_cast<int>(joints.size()); ++k) {
    const std::string type = joints[k].type, n = std::to_string(k);
    urdf += "<link name=\"l" + std::to_string(k + 1) + "\"/><joint name=\"j" + n + "\" type=\"" + type +
            "\"><parent link=\"l" + n + "\"/><child link=\"l" + std::to_string(k + 1) + "\"/><origin xyz=\"" + num() +
            " " + num() + " " + num() + "\" rpy=\"" + num() + " " + num() + " " + num() + "\"/>";
    if (*joints[k].axis) urdf += std::string("<axis xyz=\"") + joints[k].axis + "\"/>";
    if (type == "revolute" || type == "prismatic")
      urdf += "<limit lower=\"-3\" upper=\"3\" velocity=\"1\" effort=\"1\"/>";
    if (*joints[k].mimic)
      urdf += std::string("<mimic joint=\"") + joints[k].mimic + "\" multiplier=\"-1.5\" offset=\"0.25\"/>";
    urdf += "</joint>";
  }
  return urdf + "</robot>";
}

/// Every joint kind: turns about z, −z and skew axes, slides along skew axes, a fixed joint, planar and
/// floating joints between turning ones, and mimics of a revolute (j0, j4) and a prismatic (j1) joint, which
/// come before any planar or floating joint (so dropping those keeps every mimic's leader and its name).
inline std::vector<ChainJoint> everyJointKind() {
  return {{"revolute", "0 0 1", ""},      {"prismatic", "0.3 -0.5 0.8", ""},
          {"revolute", "0 0 -1", ""},     {"fixed", "", ""},
          {"continuous", "-2 1 0.5", ""}, {"planar", "0 0 1", ""},
          {"revolute", "1 0 0", "j0"},    {"floating", "", ""},
          {"prismatic", "0 1 0", "j1"},   {"revolute", "0.3 -0.5 0.8", "j4"},
          {"planar", "0.6 0.8 0", ""},    {"revolute", "0 1 0", ""}};
}

}  // namespace clearway::test
