#include <clearway/scene/collision_filter.h>

#include <algorithm>
#include <stdexcept>

namespace clearway {

namespace {
const char* const kNoGeometry = "no geometry";
}  // namespace

CollisionFilter::CollisionFilter(const RobotModel& model) : n_(model.linkCount()), reason_of_(n_ * n_, 0) {
  reasons_.emplace_back();
  for (int i = 0; i < n_; ++i)
    if (model.link(i).collisions.empty())
      for (int j = 0; j < n_; ++j)
        if (j != i) disable(i, j, kNoGeometry);
  for (const auto& [a, b] : adjacentLinkPairs(model)) disable(a, b, "Adjacent");
  for (const DisabledCollision& d : model.disabledCollisions()) disable(d.link_a, d.link_b, d.reason);
}

void CollisionFilter::disable(int a, int b, const std::string& reason) {
  if (a < 0 || b < 0 || a >= n_ || b >= n_ || a == b)
    throw std::out_of_range("CollisionFilter::disable: link pair (" + std::to_string(a) + ", " + std::to_string(b) +
                            ") out of range or not a pair");
  // The first reason stands: "no geometry" and "Adjacent" explain more than a later SRDF line.
  if (reason_of_[a * n_ + b] != 0) return;
  auto it = std::find(reasons_.begin() + 1, reasons_.end(), reason);
  const int k = static_cast<int>(it - reasons_.begin());
  if (it == reasons_.end()) reasons_.push_back(reason);
  reason_of_[a * n_ + b] = reason_of_[b * n_ + a] = k;
}

bool CollisionFilter::enabled(int a, int b) const noexcept {
  return a != b && a >= 0 && b >= 0 && a < n_ && b < n_ && reason_of_[a * n_ + b] == 0;
}

const std::string& CollisionFilter::reason(int a, int b) const noexcept {
  static const std::string kSame = "same link";
  if (a == b || a < 0 || b < 0 || a >= n_ || b >= n_) return kSame;
  return reasons_[reason_of_[a * n_ + b]];
}

std::vector<std::pair<int, int>> CollisionFilter::enabledPairs() const {
  std::vector<std::pair<int, int>> pairs;
  for (int a = 0; a < n_; ++a)
    for (int b = a + 1; b < n_; ++b)
      if (enabled(a, b)) pairs.emplace_back(a, b);
  return pairs;
}

}  // namespace clearway
