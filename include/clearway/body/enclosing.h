#pragma once
// The enclosing layer: every link's bounding ball and its parts' balls (LinkGeometry::parts(), whose union
// contains the link) placed in the world once per configuration. A pair of links is cleared by its bounding
// balls apart, else by its hulls' boxes apart on a face axis; a link is cleared from the obstacles by its
// balls' look-ups (Scene::isFree). Placing once per link instead of once per pair is what makes it cheap for
// robots with many checked pairs; only pairs it cannot clear go on to the hulls and the triangles
// (proximity.h).
#include <clearway/body/robot_geometry.h>
#include <clearway/detail/margins.h>
#include <clearway/tolerances.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace clearway {

/// The enclosing balls of a robot's links at one configuration. Made per thread; place() allocates nothing.
class EnclosingBalls {
 public:
  /// No robot: apart() is never called before a reset().
  EnclosingBalls() = default;
  /// Sized for the robot's links with geometry.
  explicit EnclosingBalls(const RobotGeometry& geometry);

  /// True when sized for this robot's geometry (a default-made layer is for none).
  bool madeFor(const RobotGeometry& geometry) const noexcept { return geometry_ == &geometry; }
  /// Places every link's bounding ball by its world pose (one per link, indexed as the robot's links);
  /// a link's parts' balls are placed when a pair first needs them, from the same poses, which must
  /// therefore stay unchanged until the next place().
  void place(const Pose* link_poses) noexcept;
  /// True when links a and b, as last placed, are certainly more than `padding` metres apart (beyond the
  /// narrow phase's band: tol.gjk_absolute of their size): their bounding balls apart, or their hulls'
  /// boxes apart on a face axis. Both hold the hulls, so the answer holds in every geometry mode. False
  /// proves nothing; a non-finite pose, or a link without geometry, is never apart.
  bool apart(int a, int b, double padding, const Tolerances& tol) const noexcept;
  /// For k < n: out[k] = 1 when links a[k] and b[k], as last placed, have bounding balls more than
  /// padding[k] apart beyond the band (apart()'s first test, for many pairs at once in SIMD lanes, the target
  /// chosen at run time as KinematicLanes' is), else 0, which proves nothing.
  void boundsApart(const std::int64_t* a, const std::int64_t* b, const double* padding, int n, const Tolerances& tol,
                   std::uint8_t* out) const noexcept;

  /// A ball as placed, world frame.
  struct Placed {
    Vec3 center;    ///< world frame
    double radius;  ///< grown by the rounding of the placement: it holds what the link-frame ball held
  };
  /// How many balls link i has: 0 without geometry, else its bounding ball and, when it has several
  /// parts whose balls were proven to hold it (LinkGeometry::partBallMargin), one per part.
  int ballCount(int i) const noexcept { return links_[i].count; }
  /// Link i's ball k as last placed: k = 0 its bounding ball; 1 ≤ k < ballCount(i) its parts' (placed at
  /// the first such call since place()). The parts' balls together hold the whole link, the inside of its
  /// closed meshes included.
  Placed placed(int i, int k) noexcept {
    Link& l = links_[i];
    if (k > 0 && l.parts_at != placement_) placeParts(i);
    const int at = l.first + k;
    // (|t| ≤ |R·c + t| + |c| bounds the translation's norm.)
    const double rounding = margins::placedRounding(local_norms_[at], local_norms_[at] + norms_[at]);
    return {centers_[at], radii_[at] * (1.0 + margins::kRounding) + rounding};
  }

 private:
  struct Link {
    int first = 0;  // its balls in centers_/radii_: [first] the bounding ball, then the parts' balls
    int count = 0;
    std::uint64_t parts_at = 0;  // the placement its parts' balls were placed at
  };
  void placeParts(int link) noexcept;
  const Pose* poses_ = nullptr;  // as last placed
  std::uint64_t placement_ = 0;  // place() calls (the first is 1)
  const RobotGeometry* geometry_ = nullptr;
  std::vector<Link> links_;
  std::vector<Vec3> local_;    // ball centres, link frame
  std::vector<Vec3> centers_;  // ball centres, world frame (as last placed)
  std::vector<double> norms_;   // |centre|, which sizes the rounding band
  std::vector<double> local_norms_;  // |centre| in the link frame
  std::vector<double> radii_;
  // Per link, its bounding ball as last placed, one array per coordinate for the lanes (a link without
  // geometry: an infinite radius, never apart).
  std::vector<double> bound_x_, bound_y_, bound_z_, bound_r_, bound_norm_;
};

}  // namespace clearway
