#pragma once
// Self-collision audit of a robot, as MoveIt Setup Assistant's collision matrix but with evidence: every
// pair of links with geometry is classified Adjacent, Default (colliding at the default configuration),
// Always (colliding in at least always_fraction of the samples), Never (never seen colliding) or left
// checked, with its sample count, colliding count, a 95% Clopper–Pearson upper bound on its collision
// probability and the smallest clearance seen (so that a "never" pair that came within a millimetre is
// told apart from one that stayed far).
#include <clearway/scene/self_collision.h>  // RobotGeometry

#include <memory>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace clearway {

/// How auditSelfCollision samples and classifies link pairs.
struct AuditOptions {
  int samples = 10000;            ///< random configurations, uniform within the limits (continuous: ±π)
  std::uint64_t seed = 1;         ///< the same seed gives the same audit, whatever the thread count
  double always_fraction = 0.95;  ///< MoveIt's default threshold for "always in collision"
  double near_margin = 1e-3;      ///< a Never pair whose clearance came under this is flagged near_miss
  /// A Default pair (disabled by MoveIt's rule) that collides in more than this fraction of the samples,
  /// yet less than always_fraction, gets a warning: disabling it hides those collisions.
  double warn_fraction = 0.01;
  /// A pair left checked that collides in more than this fraction of the samples gets a warning.
  double most_fraction = 0.5;
  /// Threads to sample on, at most maxAuditThreads() (more are capped to it); fewer run when the system
  /// cannot start them all, with the same audit: it depends on the capped count alone.
  int threads = 2;
  Tolerances tolerances = {};     ///< the narrow phase's, for every collision and distance test
  /// Called from the calling thread with (samples done, samples in all) about every 1% of a run and once
  /// at the end; may be empty. For progress bars.
  std::function<void(int, int)> progress;
};

/// One pair's verdict and evidence.
struct PairAudit {
  ///@{
  int a = -1, b = -1;        ///< the pair's link indices, a < b
  ///@}
  std::string reason;        ///< "Adjacent", "Default", "Always", "Never", or "" (must be checked)
  int samples = 0;           ///< configurations tested (0 for Adjacent pairs: nothing is measured)
  int colliding = 0;         ///< samples in collision (for a Default pair, away from the default configuration)
  /// 95% upper confidence bound on the collision probability; exact (0 or 1) for a rigid pair, whose links
  /// no sampled joint moves apart, measured once for all samples.
  double p_upper = 1.0;
  /// Smallest exact distance seen (0 when it collided; NaN when not measured), or one at most 2·gjk_relative
  /// (relative) above it: each distance is exact to gjk_relative only.
  double min_clearance = 0;
  bool near_miss = false;    ///< Never, but closer than near_margin at some sample
  /// Why the verdict may mislead ("" when it does not): a Default pair that collides in more than
  /// warn_fraction of the samples, or a checked pair that collides in more than most_fraction.
  std::string warning;
};

/// The most threads an audit runs on: 4 per hardware thread, at most 256.
int maxAuditThreads();

/// The 95% one-sided Clopper–Pearson upper bound on p after k successes in n trials (1 when n = 0).
double clopperPearsonUpper(int k, int n);

/// Audits every pair of links with geometry (the SRDF of the model is ignored: adjacency only). Throws
/// std::invalid_argument when samples < 1, threads < 1, always_fraction is not in (0, 1] or
/// warn_fraction or most_fraction is not in [0, 1].
std::vector<PairAudit> auditSelfCollision(std::shared_ptr<const RobotGeometry> geometry, const AuditOptions& options = {});

/// The SRDF of an audit: input_srdf (SRDF text; "" for a new document naming the model) with the
/// disable_collisions of every audited pair replaced by one per pair that has a reason (link1 < link2,
/// sorted by name), where the first replaced one stood or else at the end; every other element and
/// comment is kept. Written through an XML printer, so any link name is well-formed. Throws
/// std::invalid_argument when input_srdf is not XML with a `<robot>` root.
std::string auditSrdf(const RobotModel& model, const std::vector<PairAudit>& audit, const std::string& input_srdf = "");

}  // namespace clearway
