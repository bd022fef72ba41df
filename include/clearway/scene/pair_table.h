#pragma once
// Certified verdicts of one self pair whose relative pose depends on one or two joint variables (a link
// and its grandchild, a wrist and the gripper it turns), tabulated over those variables at load.
//
// Each cell of the table is a box of joint values around a centre c with half-widths h. Every point of
// the lower link moves, relative to the upper one, by at most δ = Σ h_k·ρ_k as the variables range over
// the cell, where ρ_k is the largest distance of the lower link's hull from joint k's axis (exact for the
// lower joint, whose axis the hull turns about; at the cell's value of the lower joint for the upper
// one: turn the upper joint first, then the lower, and the two legs' bounds add up), or 1 for a slide. So
// a pair certified more than padding + δ apart at c is apart everywhere in the cell (Free), and a pair
// whose cores overlap by more than δ at c overlaps everywhere in it (Colliding). In Mesh mode each convex
// part of the lower link (LinkGeometry::parts) also has its own δ from its own reaches, and a cell where
// every part is that far from the upper link's parts is Free too: near a joint, the near part lies close
// to the axes and moves far less than the link's farthest point.
// Other cells are Unsure and the pair is checked as before, after one triangle test of the pair that
// touched at the cell's centre. A coarse grid is refined where it is unsure.
// A pair moved by three variables, the lowest of which turns the lower link about its own axis (a wrist's
// last link, and what it carries, against the forearm), is tabulated over the other two: the lower body is
// then the solid the link sweeps over the whole turn (its profile about the axis cut into four slabs, each
// the hull of the polygons circumscribing its corners' circles), so a cell is Free for every angle of the
// turn; such a table is free-only (never Colliding, no witness).
#include <clearway/body/proximity.h>
#include <clearway/body/robot_geometry.h>
#include <clearway/kinematics/robot_model.h>
#include <clearway/tolerances.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

namespace clearway {

/// How finely a pair table is cut: cells per variable of the coarse grid, then at most this many (rounded
/// down to a power of two) within an unsure coarse cell, reached by halving where still unsure.
struct PairTableOptions {
  ///@{
  int coarse_one = 64, fine_one = 16;   ///< a pair moved by one variable
  ///@}
  ///@{
  int coarse_two = 16, fine_two = 16;  ///< a pair moved by two
  ///@}
  /// Cell centres checked at most, per table (each a distance query at load): a level of halving that
  /// would pass it is not begun, and its cells stay Unsure.
  long max_checks = 50000;
  /// No table for a pair whose probe (one coarse cell in 4 per variable) settles less than this share.
  double min_probe_share = 0.25;
  ///@{
  /// Cells checked down to the triangles (the finest, near contact) at most, per table, and only for links
  /// of at most max_exact_triangles triangles each: past either, cells are checked on the hulls alone. A
  /// search among many triangles within a wide padding is what makes a table dear; counted, not timed, a
  /// table is the same on every machine (and so is which colliding pair a check reports).
  long max_exact_checks = 8000;
  int max_exact_triangles = 4096;
  ///@}
  /// No cell is checked after this moment (the cells left stay Unsure). None by default: a deadline makes
  /// the tables, though never the verdicts, depend on the machine's speed.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  /// Tables a robot's load builds at once (sharedMany): 0 for as many as the machine runs at once
  /// (detail::loadThreads: at most 16), 1 for the calling thread alone. The tables are the same whatever
  /// this is.
  int threads = 0;
  /// These options with the deadline brought forward to `seconds` from now, if that is sooner (a
  /// budget beyond 10⁶ s counts as 10⁶ s; a negative or NaN one as 0).
  PairTableOptions within(double seconds) const;
};

/// Certified verdicts of one self pair moved by one or two joint variables (or three, the lowest turning
/// the lower link: freeOnly()), per cell of those variables' values. Immutable once built; lookups are
/// const and thread-safe.
class PairTable {
 public:
  /// A cell's verdict: Free or Colliding at every configuration in it, or Unsure (check the pair).
  enum class Verdict : std::uint8_t { Unsure, Free, Colliding };

  /// The table of links a and b (geometries ga, gb), checked with `padding` in `mode`; null when their
  /// relative pose depends on other than one or two revolute, continuous or prismatic, non-mimic joints
  /// (a prismatic one with finite limits), or three whose lowest turns the lower link (freeOnly()). held[v], when
  /// finite, fixes variable v at that value (a joint the scene holds is then fixed); empty: every variable moves.
  static std::unique_ptr<const PairTable> build(const RobotModel& model, int a, const LinkGeometry& ga, int b,
                                                const LinkGeometry& gb, double padding, GeometryMode mode,
                                                const Tolerances& tol, const std::vector<double>& held = {},
                                                const PairTableOptions& options = {});

  /// build() for the geometry's links a and b, or the table already built for the same two link geometries
  /// joined by the same joints with the same settings, while both live (scenes sharing a loaded robot, and
  /// a robot and its edits with bodies attached elsewhere, share their tables). Thread-safe.
  static std::shared_ptr<const PairTable> shared(const std::shared_ptr<const RobotGeometry>& geometry, int a, int b,
                                                 double padding, GeometryMode mode, const Tolerances& tol,
                                                 const std::vector<double>& held = {},
                                                 const PairTableOptions& options = {});
  /// One table sharedMany() asks for: links a and b, checked with `padding`.
  struct Request {
    int a = -1;            ///< one link
    int b = -1;            ///< the other
    double padding = 0.0;  ///< metres
  };
  /// shared() for each request, in order, on up to options.threads threads at once: the same tables as
  /// one shared() after another (each is built whole on one thread). An exception of a build is rethrown
  /// here, once every thread has stopped.
  static std::vector<std::shared_ptr<const PairTable>> sharedMany(const std::shared_ptr<const RobotGeometry>& geometry,
                                                                  const std::vector<Request>& requests,
                                                                  GeometryMode mode, const Tolerances& tol,
                                                                  const std::vector<double>& held = {},
                                                                  const PairTableOptions& options = {});
  /// The work of shared()'s cache since the program started, for tests: what it shares and what keeping it
  /// costs are counts, not times.
  struct CacheStats {
    std::size_t entries = 0;  ///< tables (and pairs found to need none) held now
    long long built = 0;      ///< calls that built a table (or found none was due) instead of sharing one
    long long swept = 0;      ///< entries visited by the sweeps that drop those of link geometries gone
  };
  /// A snapshot of the counts (thread-safe).
  static CacheStats cacheStats();

  /// The verdict at the full variable vector q (held variables at their held values): Free and Colliding
  /// hold at every configuration of the cell holding q; Unsure for the other cells, and for values outside
  /// the table (beyond the limits, not finite). For an Unsure cell whose centre collides through two
  /// triangles, `witness` (optional) receives them (a's, b's): likely to touch near the centre too, they
  /// are worth one triangle test (trianglesTouch) before the search.
  Verdict lookup(const double* q, TrianglePair* witness = nullptr) const noexcept;

  /// True when every cell the straight segment q0 → q1 (full variable vectors, held variables at their held
  /// values) passes through is Free: the pair is then apart along all of it. False proves nothing (a segment
  /// leaving the table, through a cell not Free, or crossing more cells than the table has per turn).
  bool freeAlong(const double* q0, const double* q1) const noexcept;

  /// The variables the table is over (one or two).
  const std::vector<int>& variables() const noexcept { return var_; }
  /// True when the lower link's own joint, a third variable, is swept rather than tabulated: the table then
  /// answers Free or Unsure, never Colliding, and gives no witness.
  bool freeOnly() const noexcept { return free_only_; }
  /// The share of the variables' range (by volume) whose cells are certified Free or Colliding.
  double certifiedShare() const noexcept { return certified_; }
  /// How many cell centres were checked to build the table.
  int cellsChecked() const noexcept { return checked_; }

 private:
  PairTable() = default;
  // Cell coordinates of variable k's value x (in coarse cells), or −1 when outside the table.
  double coordinate(int k, double x) const noexcept;
  // freeAlong's walk through the fine cells of refined coarse cell c (unrolled coordinates; its fine cells
  // from fine_cells_[e]) that the segment u + s·d (coarse units) crosses for s in [t_in, t_out].
  bool fineFreeAlong(std::int32_t e, const int* c, const double* u, const double* d, double t_in,
                     double t_out) const noexcept;

  std::vector<int> var_;          // per dimension: the variable
  std::vector<char> periodic_;    // per dimension: a full turn (values reduced to [−π, π])
  std::vector<double> lo_, inv_;  // per dimension: the range's low end and coarse cells per unit
  std::vector<int> n_;            // per dimension: coarse cells
  int fine_ = 1;                  // fine cells per dimension of a refined coarse cell
  // Per coarse cell (first dimension fastest): ≥ 0 the first of its fine cells in fine_cells_, else
  // −1 − Verdict.
  std::vector<std::int32_t> coarse_;
  std::vector<Verdict> fine_cells_;
  std::vector<TrianglePair> witness_;  // per fine cell
  double certified_ = 0.0;
  int checked_ = 0;
  bool free_only_ = false;
};

}  // namespace clearway
