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

/// A fixed list of link pairs laid out for EnclosingBalls::boundsApart: runs of pairs that share their first
/// link and whose second links, like their indices, follow one another, so that the lanes load the second
/// links' balls as they lie (no gathers) and store the verdicts as they lie (no scatters). Pairs sorted by
/// (a, b), as SelfCollision's, make few runs. Immutable; made once per pair list.
class BoundsRows {
 public:
  /// No pairs.
  BoundsRows() = default;
  /// Pairs (a[k], b[k]) with padding[k] metres, a[k] != b[k], every index in [0, link_count): any order.
  /// Throws std::invalid_argument otherwise.
  BoundsRows(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b, const std::vector<double>& padding,
             int link_count);
  /// Entries past the last link, past the last padding, and past the last verdict that a step of lanes may
  /// read or write: the widest.
  static constexpr int kSpare = 8;
  /// How many pairs.
  int size() const noexcept { return pairs_; }
  /// The robot's link count the pairs index.
  int linkCount() const noexcept { return link_count_; }

  /// Pairs first, ..., first + count − 1, of links (a, lo), ..., (a, lo + count − 1).
  struct Row {
    int a = 0;      ///< the first link of every pair of the run
    int lo = 0;     ///< the second link of its first pair
    int first = 0;  ///< its first pair's index
    int count = 0;  ///< how many pairs
  };
  /// The runs, for the lanes, in order of their first pair.
  const std::vector<Row>& rows() const noexcept { return rows_; }
  /// Per pair its padding, then kSpare zeros.
  const std::vector<double>& padding() const noexcept { return padding_; }
  /// For each pair k, out[k] = 1 when its balls are more than its padding apart beyond the band: |c_a − c_b|²
  /// > limit², limit = reach + band·(|c_a| + |c_b| + reach), reach = r_a + r_b + padding[k]; else 0, which
  /// proves nothing (a NaN or infinite radius is never apart). The balls by index, an array per coordinate
  /// (centre x, y, z, radius r, |centre| norm), each with kSpare entries past linkCount() (read, never
  /// used); out has room for size() + kSpare bytes. In SIMD lanes, the target chosen at run time.
  void apart(const double* x, const double* y, const double* z, const double* r, const double* norm, double band,
             std::uint8_t* out) const noexcept;

 private:
  std::vector<Row> rows_;
  std::vector<double> padding_;
  int pairs_ = 0;
  int link_count_ = 0;
};

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
  /// For each pair k of `pairs` (made for this robot's link count): out[k] = 1 when its links, as last placed,
  /// have bounding balls more than its padding apart beyond the band (apart()'s first test, by the same
  /// formula, for many pairs at once in SIMD lanes, the target chosen at run time as KinematicLanes' is), else
  /// 0, which proves nothing. Pairs made for another link count are all 0. out has room for
  /// pairs.size() + BoundsRows::kSpare bytes: the lanes write whole steps, the last past the last pair.
  void boundsApart(const BoundsRows& pairs, const Tolerances& tol, std::uint8_t* out) const noexcept;

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
    return {centers_[at], grown(radii_[at], local_norms_[at], norms_[at])};
  }
  /// A link's bounding ball placed by `pose` on its own, as placed(i, 0) gives it after place(): for a
  /// query that asks one link before it knows whether the others are needed.
  static Placed boundOf(const LinkGeometry& link, const Pose& pose) noexcept {
    const Vec3 center = pose * link.sphereCenter();
    return {center, grown(link.sphereRadius(), link.sphereCenter().norm(), center.norm())};
  }

 private:
  struct Link {
    int first = 0;  // its balls in centers_/radii_: [first] the bounding ball, then the parts' balls
    int count = 0;
    std::uint64_t parts_at = 0;  // the placement its parts' balls were placed at
  };
  void placeParts(int link) noexcept;
  // A ball's radius grown by the rounding of its placed centre: `local_norm` the centre's norm in the link
  // frame, `norm` its placed norm (|t| ≤ |R·c + t| + |c| bounds the translation's).
  static double grown(double radius, double local_norm, double norm) noexcept {
    return radius * (1.0 + margins::kRounding) + margins::placedRounding(local_norm, local_norm + norm);
  }
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
  // geometry: an infinite radius, never apart), and BoundsRows::kSpare entries more, never apart, which the
  // lanes of a run's last step read past it.
  std::vector<double> bound_x_, bound_y_, bound_z_, bound_r_, bound_norm_;
};

}  // namespace clearway
