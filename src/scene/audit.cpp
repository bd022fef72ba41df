#include <clearway/scene/audit.h>

#include <clearway/body/proximity.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/input_limits.h>

#include <tinyxml2.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <tuple>

namespace clearway {

namespace {

// MoveIt's default: 0 when within the limits, else the middle; a floating joint's quaternion is identity.
std::vector<double> defaultConfiguration(const RobotModel& model) {
  std::vector<double> q(model.variableCount());
  for (int v = 0; v < model.variableCount(); ++v) {
    const JointVariable& var = model.variables()[v];
    const bool qw = var.name.size() > 3 && var.name.compare(var.name.size() - 3, 3, "/qw") == 0;
    double x = qw ? 1.0 : 0.0;
    if (x < var.lower || x > var.upper)
      x = std::isfinite(var.lower) && std::isfinite(var.upper) ? 0.5 * var.lower + 0.5 * var.upper
                                                               : (std::isfinite(var.lower) ? var.lower : var.upper);
    q[v] = x;
  }
  return q;
}

// Only joints that move links relative to each other are sampled: a planar or floating joint moves its
// whole subtree rigidly, which changes no pair inside it (and a root one changes none at all).
bool sampled(const RobotModel& model, const JointVariable& var) {
  const JointType t = model.joint(var.joint).type;
  return t != JointType::Planar && t != JointType::Floating;
}

// True when no sampled joint lies on the tree path between links a and b, so that their relative pose is
// the same in every sample (a gripper's fixed parts, a sensor on a flange). Links are in topological
// order: the larger index is the deeper one on its side, and the walk stops at the common ancestor.
bool rigidPair(const RobotModel& model, int a, int b) {
  while (a != b) {
    int& deeper = a > b ? a : b;
    const Joint& j = model.joint(model.link(deeper).parent_joint);
    if (j.type != JointType::Fixed && j.type != JointType::Planar && j.type != JointType::Floating) return false;
    deeper = j.parent_link;
  }
  return true;
}

// log P(X ≤ k) for X ~ Binomial(n, p), summed in log space; log_choose[i] = log C(n, i) for i = 0 … k.
double logBinomialCdf(const std::vector<double>& log_choose, int n, double p) {
  const int k = static_cast<int>(log_choose.size()) - 1;
  if (p <= 0.0) return 0.0;
  if (p >= 1.0) return k >= n ? 0.0 : -std::numeric_limits<double>::infinity();
  const double log_p = std::log(p), log_q = std::log1p(-p);
  // A running log-sum-exp: the sum is rescaled whenever a larger term arrives.
  double best = -std::numeric_limits<double>::infinity(), sum = 0.0;
  for (int i = 0; i <= k; ++i) {
    const double term = log_choose[i] + i * log_p + (n - i) * log_q;
    if (term > best) {
      sum = sum * std::exp(best - term) + 1.0;
      best = term;
    } else {
      sum += std::exp(term - best);
    }
  }
  return best + std::log(sum);
}

}  // namespace

double clopperPearsonUpper(int k, int n) {
  if (n <= 0 || k >= n) return 1.0;
  if (k == 0) return 1.0 - std::pow(0.05, 1.0 / n);  // the closed form of the case below
  // log C(n, i) does not depend on p: computed once, not at each step of the bisection (summed as before,
  // so the answer is the same to the bit).
  std::vector<double> log_choose(k + 1);
  for (int i = 0; i <= k; ++i) log_choose[i] = std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0);
  // The p at which P(X ≤ k) falls to 5%: P(X ≤ k) decreases in p, so bisection; 100 halvings of [0, 1]
  // reach double precision.
  double lo = static_cast<double>(k) / n, hi = 1.0;
  const double target = std::log(0.05);
  for (int it = 0; it < 100 && hi - lo > 1e-15; ++it) {
    const double mid = 0.5 * (lo + hi);
    (logBinomialCdf(log_choose, n, mid) > target ? lo : hi) = mid;
  }
  return hi;
}

int maxAuditThreads() {
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());  // 0 when unknown
  return static_cast<int>(std::min(256u, 4 * hardware));
}

std::vector<PairAudit> auditSelfCollision(std::shared_ptr<const RobotGeometry> geometry, const AuditOptions& options) {
  if (options.samples < 1) throw std::invalid_argument("audit: samples must be >= 1");
  if (options.threads < 1) throw std::invalid_argument("audit: threads must be >= 1");
  if (!(options.always_fraction > 0.0 && options.always_fraction <= 1.0))
    throw std::invalid_argument("audit: always_fraction must be in (0, 1]");
  if (!(options.warn_fraction >= 0.0 && options.warn_fraction <= 1.0) ||
      !(options.most_fraction >= 0.0 && options.most_fraction <= 1.0))
    throw std::invalid_argument("audit: warn_fraction and most_fraction must be in [0, 1]");
  const RobotModel& model = geometry->model();
  const int n_links = model.linkCount();
  const Tolerances& tol = options.tolerances;

  // Every pair of links with geometry; the SRDF is not consulted (the audit is what writes one).
  std::vector<char> adjacent(static_cast<std::size_t>(n_links) * n_links, 0);
  for (const auto& [a, b] : adjacentLinkPairs(model)) adjacent[a * n_links + b] = adjacent[b * n_links + a] = 1;
  const std::vector<int>& links = geometry->geometricLinks();
  std::vector<PairAudit> result;
  for (std::size_t i = 0; i < links.size(); ++i)
    for (std::size_t j = i + 1; j < links.size(); ++j) {
      PairAudit p;
      p.a = std::min(links[i], links[j]);
      p.b = std::max(links[i], links[j]);
      if (adjacent[p.a * n_links + p.b]) p.reason = "Adjacent";
      p.min_clearance = std::numeric_limits<double>::infinity();
      result.push_back(p);
    }
  const auto collides = [&](const PairAudit& p, const std::vector<Pose>& poses) {
    return meshesIntersect(*geometry->link(p.a), poses[p.a], *geometry->link(p.b), poses[p.b], tol, GeometryMode::Mesh);
  };

  // Default: in collision at the default configuration. Such pairs are still sampled: MoveIt's rule
  // disables them, and how often they collide elsewhere tells whether that hides real collisions.
  const std::vector<double> q_default = defaultConfiguration(model);
  std::vector<Pose> poses(n_links);
  computeLinkPoses(model, q_default.data(), poses.data());
  std::vector<int> sampled_pairs, rigid_pairs;
  std::vector<char> rigid(result.size(), 0);
  for (int k = 0; k < static_cast<int>(result.size()); ++k) {
    PairAudit& p = result[k];
    if (!p.reason.empty()) continue;  // Adjacent: not measured
    if (collides(p, poses)) p.reason = "Default";
    rigid[k] = rigidPair(model, p.a, p.b);
    (rigid[k] ? rigid_pairs : sampled_pairs).push_back(k);
  }
  // A rigid pair is the same in every sample: measured once, at the default configuration, it counts for
  // all of them (on the shared UR5 the gripper's fixed parts, a few mm apart on 40k-triangle meshes, took
  // most of the audit's time when measured per sample).
  for (const int k : rigid_pairs) {
    PairAudit& p = result[k];
    p.samples = options.samples;
    if (p.reason == "Default") {
      p.colliding = options.samples;
      p.min_clearance = 0.0;
      continue;
    }
    const DistanceResult d = meshDistance(*geometry->link(p.a), poses[p.a], *geometry->link(p.b), poses[p.b], tol);
    p.min_clearance = isFailure(d.status) ? 0.0 : d.distance;
  }

  // The samples, drawn up front from the seed: the audit is the same whatever the thread count.
  std::mt19937_64 rng(options.seed);
  std::vector<double> configurations(static_cast<std::size_t>(options.samples) * model.variableCount());
  for (int s = 0; s < options.samples; ++s)
    for (int v = 0; v < model.variableCount(); ++v) {
      const JointVariable& var = model.variables()[v];
      double x = q_default[v];
      if (sampled(model, var)) {
        // Within ±kMaxJointValue, as a state may be: limits of ±1e308 have an infinite width to sample in.
        const double lo = std::isfinite(var.lower) ? std::max(var.lower, -kMaxJointValue) : -M_PI;
        const double hi = std::max(lo, std::isfinite(var.upper) ? std::min(var.upper, kMaxJointValue) : M_PI);
        x = std::uniform_real_distribution<double>(lo, hi)(rng);
      }
      configurations[static_cast<std::size_t>(s) * model.variableCount() + v] = x;
    }

  // A Default pair's clearance is 0 (it collided at the default configuration): it is not measured.
  std::vector<char> measured(result.size(), 0);
  for (const int k : sampled_pairs) measured[k] = result[k].reason != "Default";
  // GJK gives each distance to tol.gjk_relative only. A pair that a joint turns about an axis of both (the
  // UR5's wrist_2_link and the gripper's links) is equally far at every sample, its distances differing in
  // that last digit alone, and each sample would search the triangles again to tell which is least: so
  // only a distance more than twice that below the smallest yet counts.
  const double tie = 1.0 - 2.0 * tol.gjk_relative;

  // Lane t takes every lanes-th sample from t, with its own warm starts, counts and minima (merged
  // after); the threads started take lanes until none is left. So the audit depends on the lanes alone,
  // not on how many threads the system gave.
  struct Partial {
    std::vector<int> colliding;
    std::vector<double> min_clearance;
  };
  const int lanes = std::min(options.threads, maxAuditThreads());
  std::vector<Partial> partial(lanes);
  std::atomic<int> next_lane{0}, done{0};
  const int report_every = std::max(1, options.samples / 100);
  const auto work = [&](bool reports) {
    std::vector<Pose> ps(n_links);
    for (int t; (t = next_lane.fetch_add(1)) < lanes;) {
      Partial& mine = partial[t];
      mine.colliding.assign(result.size(), 0);
      mine.min_clearance.assign(result.size(), std::numeric_limits<double>::infinity());
      std::vector<BodyPair> bodies;  // the pairs' warm starts, this lane's own
      bodies.reserve(result.size());
      for (const PairAudit& p : result) bodies.emplace_back(*geometry->link(p.a), *geometry->link(p.b));
      for (int s = t; s < options.samples; s += lanes) {
        // data() + offset: a robot without joints has no configurations to index (&v[0] of an empty vector).
        computeLinkPoses(model, configurations.data() + static_cast<std::size_t>(s) * model.variableCount(), ps.data());
        for (const int k : sampled_pairs) {
          const PairAudit& p = result[k];
          if (collides(p, ps)) {
            ++mine.colliding[k];
            mine.min_clearance[k] = 0.0;
            continue;
          }
          // The smallest clearance is a running minimum, so only a distance below it matters: as the cutoff,
          // it lets the balls, hulls and convex parts skip a sample they prove farther, and prunes element pairs.
          double& least = mine.min_clearance[k];
          if (!measured[k] || !(least > 0.0)) continue;
          DistanceQuery q;
          q.cutoff = least * tie;
          const DistanceResult d = bodies[k].distance(ps[p.a], ps[p.b], tol, q);
          if (!isFailure(d.status) && d.distance < q.cutoff) least = d.distance;
        }
        const int now = done.fetch_add(1, std::memory_order_relaxed) + 1;
        // Only the calling thread reports, so the callback needs no locking.
        if (reports && options.progress && now / report_every != (now - 1) / report_every) options.progress(now, options.samples);
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(lanes - 1);
  for (int t = 1; t < lanes; ++t) {
    try {
      pool.emplace_back(work, false);
    } catch (const std::system_error&) {
      break;  // no more threads (a process or memory limit): those started, and this one, take every lane
    }
  }
  work(true);
  for (auto& th : pool) th.join();
  if (options.progress) options.progress(options.samples, options.samples);

  for (const int k : sampled_pairs) {
    PairAudit& p = result[k];
    p.samples = options.samples;
    p.min_clearance = std::numeric_limits<double>::infinity();
    for (const Partial& part : partial) {
      p.colliding += part.colliding[k];
      p.min_clearance = std::min(p.min_clearance, part.min_clearance[k]);
    }
    if (p.reason == "Default") p.min_clearance = 0.0;  // it collided at the default configuration
  }
  char text[160];
  for (int k = 0; k < static_cast<int>(result.size()); ++k) {
    PairAudit& p = result[k];
    if (p.samples == 0) {  // Adjacent: nothing was measured
      p.min_clearance = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    // A rigid pair is the same at every sample: its probability is known exactly, not bounded.
    p.p_upper = rigid[k] ? (p.colliding > 0 ? 1.0 : 0.0) : clopperPearsonUpper(p.colliding, p.samples);
    const double fraction = static_cast<double>(p.colliding) / p.samples;
    if (p.reason == "Default") {
      // A pair that collides nearly always would be disabled as Always anyway; in between, disabling it
      // hides collisions a planner would otherwise see (the Panda's link5–link7: 8% of random states).
      if (fraction > options.warn_fraction && fraction < options.always_fraction) {
        std::snprintf(text, sizeof text,
                      "disabled as Default but collides in %d of %d samples (%.3g%%) away from the default configuration",
                      p.colliding, p.samples, 100.0 * fraction);
        p.warning = text;
      }
    } else if (p.colliding >= options.always_fraction * p.samples) {
      p.reason = "Always";
    } else if (p.colliding == 0) {
      p.reason = "Never";
      p.near_miss = p.min_clearance < options.near_margin;
    } else if (fraction > options.most_fraction) {
      std::snprintf(text, sizeof text, "checked but collides in %d of %d samples (%.3g%%): most states are refused by it",
                    p.colliding, p.samples, 100.0 * fraction);
      p.warning = text;
    }
  }
  return result;
}

namespace {

// tinyxml2's printer with two spaces per level (it has four), as MoveIt's SRDFs are indented, so that an
// SRDF written over its input changes only where the audit changed it.
class SrdfPrinter : public tinyxml2::XMLPrinter {
 protected:
  void PrintSpace(int depth) override {
    for (int i = 0; i < depth; ++i) Write("  ");
  }
};

}  // namespace

std::string auditSrdf(const RobotModel& model, const std::vector<PairAudit>& audit, const std::string& input_srdf) {
  using tinyxml2::XMLElement;
  using tinyxml2::XMLNode;
  // The pairs the audit decides, by name, link1 < link2; those with a reason are written, sorted.
  std::set<std::pair<std::string, std::string>> decided;
  std::vector<std::tuple<std::string, std::string, std::string>> written;
  for (const PairAudit& p : audit) {
    const auto names = std::minmax(model.link(p.a).name, model.link(p.b).name);  // references into the model
    decided.emplace(names.first, names.second);
    if (!p.reason.empty()) written.emplace_back(names.first, names.second, p.reason);
  }
  std::sort(written.begin(), written.end());

  tinyxml2::XMLDocument doc;
  XMLElement* robot = nullptr;
  if (input_srdf.empty()) {
    doc.InsertEndChild(doc.NewDeclaration());
    doc.InsertEndChild(doc.NewComment(" Written by clearway audit "));
    robot = doc.NewElement("robot");
    robot->SetAttribute("name", model.name().c_str());
    doc.InsertEndChild(robot);
  } else {
    if (doc.Parse(input_srdf.data(), input_srdf.size()) != tinyxml2::XML_SUCCESS)
      throw std::invalid_argument(std::string("auditSrdf: the input SRDF is not well-formed XML: ") + doc.ErrorStr());
    robot = doc.RootElement();
    if (robot == nullptr || std::string(robot->Name()) != "robot")
      throw std::invalid_argument("auditSrdf: the input SRDF's root element is not <robot>");
  }

  // Remove the decided pairs' disable_collisions, remembering what stood before the first of them: the
  // new ones go there (after the comment that introduces them in MoveIt's files), else at the end.
  bool replaced = false;
  XMLNode* before = nullptr;  // null with replaced: at the start
  for (XMLElement* e = robot->FirstChildElement("disable_collisions"); e != nullptr;) {
    XMLElement* next = e->NextSiblingElement("disable_collisions");
    const char* link1 = e->Attribute("link1");
    const char* link2 = e->Attribute("link2");
    if (link1 != nullptr && link2 != nullptr &&
        decided.count(std::string(link1) < link2 ? std::make_pair<std::string, std::string>(link1, link2)
                                                 : std::make_pair<std::string, std::string>(link2, link1))) {
      if (!replaced) before = e->PreviousSibling();
      replaced = true;
      robot->DeleteChild(e);
    }
    e = next;
  }
  for (const auto& [link1, link2, reason] : written) {
    XMLElement* e = doc.NewElement("disable_collisions");
    e->SetAttribute("link1", link1.c_str());
    e->SetAttribute("link2", link2.c_str());
    e->SetAttribute("reason", reason.c_str());
    if (!replaced) robot->InsertEndChild(e);
    else if (before == nullptr) robot->InsertFirstChild(e);
    else robot->InsertAfterChild(before, e);
    before = e;
    replaced = true;
  }
  SrdfPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

}  // namespace clearway
