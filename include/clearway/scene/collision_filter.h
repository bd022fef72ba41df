#pragma once
// Which link pairs of a robot are checked against each other. A pair is skipped when the links are
// adjacent (MoveIt's definition, kinematics/robot_model.h), when the SRDF disables it, when a scene
// allows it, or when either link has no collision geometry; every other pair is checked.
#include <clearway/kinematics/robot_model.h>

#include <string>
#include <utility>
#include <vector>

namespace clearway {

/// A set of link pairs never checked, with the reason each was excluded. Value type: cheap to copy.
class CollisionFilter {
 public:
  /// The robot's adjacent pairs ("Adjacent") and SRDF disable_collisions pairs (their reasons).
  explicit CollisionFilter(const RobotModel& model);

  /// Never check links a and b (a ≠ b, both in range; otherwise std::out_of_range); `reason` is kept.
  void disable(int a, int b, const std::string& reason);
  /// True when the pair is checked: both links have geometry and nothing disables the pair.
  bool enabled(int a, int b) const noexcept;
  /// Why a disabled pair is skipped ("Adjacent", "Never", "allowed by scene", "no geometry", ...);
  /// empty when the pair is checked.
  const std::string& reason(int a, int b) const noexcept;
  /// The checked pairs (a, b), a < b, sorted.
  std::vector<std::pair<int, int>> enabledPairs() const;
  /// The number of links the filter covers (link indices run from 0 to linkCount() − 1).
  int linkCount() const noexcept { return n_; }

 private:
  int n_ = 0;
  std::vector<int> reason_of_;        // n × n, symmetric: index into reasons_, 0 = checked
  std::vector<std::string> reasons_;  // reasons_[0] is ""
};

}  // namespace clearway
