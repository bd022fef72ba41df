// The narrow-phase benchmark: what accuracy costs in time, with FCL 0.7 side by side in one run.
//
// GJK distance and the GJK ray cast sweep their relative tolerance 1e-1 … 1e-7 over convex hulls of 16,
// 64 and 256 points and over primitive pairs. Each row gives the mean time per query, the mean number
// of iterations and the error against a reference: for distance Clearway's GJK at 1e-12, itself checked
// against FCL's two solvers at their tightest setting; for the ray cast the exact ray–solid
// intersection. FCL's solvers (libccd, and its own "indep" GJK) answer the same distance pairs at the
// same tolerances; FCL 0.7 has no GJK ray cast. Intersection follows pairs moving smoothly along a
// path, cold (a fresh SimplexCache per query) and warm (one cache per path), beside FCL's intersection.
//
// Every pair list is fixed by a seed; every timing is the median over the passes of the whole list (thread
// CPU time), after one warm-up pass, with the passes of all methods interleaved. Results go to stdout
// (tables) and to CSV files in the output directory; plot_narrowphase.gp draws them (run_narrowphase.sh).
//
// Usage: bench_narrowphase [--out DIR] [--quick] [--only FAMILY]
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>

#include "fcl_robot.h"
#include "narrowphase_shapes.h"

#include <fcl/config.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cone.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/detail/gjk_solver_indep.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>  // clock_gettime (POSIX)
#include <deque>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#ifndef CLEARWAY_BENCH_BUILD
#define CLEARWAY_BENCH_BUILD "unknown"
#endif
#ifndef CLEARWAY_BENCH_REVISION
#define CLEARWAY_BENCH_REVISION "unknown"
#endif

namespace cw = clearway;
using cw::Vec3;

using cw::bench::Rng;
using cw::bench::toFcl;
using cw::bench::reach;
using cw::bench::makeHull;
using cw::bench::makeBox;
using cw::bench::makeSphere;
using cw::bench::makeCapsule;
using cw::bench::makeCylinder;
using cw::bench::makeCone;
using cw::bench::kTight;
using cw::bench::tightTolerances;
using cw::bench::PairCase;
using cw::bench::Family;
using cw::bench::makePools;
using cw::bench::addSeparatedPairs;

namespace {

// ---- Settings ---------------------------------------------------------------------------------------

const double kTolerances[] = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
// G. van den Bergen, "Ray Casting against General Convex Objects with Application to Continuous
// Collision Detection" (2004): GJK ray cast time per query in µs on a 2.6 GHz CPU, by tolerance.
const double kVanDenBergenRayUs[] = {0.62, 0.77, 1.02, 1.43, 2.03, 2.80, 3.65};
// Errors of this size (metres, on shapes about 1 m across) are rounding of the reference itself: two
// methods both under it count as equally accurate.
constexpr double kErrorFloor = 1e-12;

struct Settings {
  int pairs = 2000;        // pairs per distance / ray family
  int path_steps = 2000;   // steps per intersection path
  int paths = 4;           // paths per intersection family
  int reps = 9;            // timed passes (median)
  std::string out = "benchmarks/results";
  std::string only;  // when set, run only the families with this name (profiling)
  bool wanted(const std::string& family) const { return only.empty() || only == family; }
};

// ---- Sinks and timing -------------------------------------------------------------------------------

// Makes the compiler assume the value is read, so the computation producing it cannot be dropped.
template <class T>
inline void doNotOptimize(const T& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

// The CPU time of this thread (ns): time spent descheduled while other work runs on the machine is not
// counted, which keeps the comparison fair on a shared machine (wall-clock passes were off by 2–3×).
double threadCpuNs() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e9 * static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec);
}

// One timed pass: body(0 … n−1) in order, returning the mean CPU time per call (ns). The body is inlined
// into the loop; only the pass itself is type-erased.
using Pass = std::function<double()>;
template <class Body>
Pass makePass(std::size_t n, Body body) {
  return [n, body]() mutable {
    const double start = threadCpuNs();
    for (std::size_t i = 0; i < n; ++i) body(i);
    return (threadCpuNs() - start) / static_cast<double>(n);
  };
}

// Runs every pass once to warm up, then `reps` rounds of all passes in turn, and returns each pass's
// median. Interleaving spreads any slow phase of the machine over all methods alike, so the ratios
// between them stay fair even when the absolute times drift.
std::vector<double> medianInterleaved(std::vector<Pass>& passes, int reps) {
  std::vector<std::vector<double>> ns(passes.size());
  for (Pass& p : passes) p();
  for (int r = 0; r < reps; ++r)
    for (std::size_t k = 0; k < passes.size(); ++k) ns[k].push_back(passes[k]());
  std::vector<double> median;
  for (std::vector<double>& v : ns) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    median.push_back(v[v.size() / 2]);
  }
  return median;
}

// Smooth paths: A still; B circles A (azimuth once round, elevation swinging) while turning about a
// fixed axis, its centre at k(s) × (reach of A + reach of B along the direction), k in [0.96, 1.16].
// k ≥ 1 guarantees a gap; the dips below 1 make the pair touch or overlap now and then.
template <class FA, class FB>
void addPaths(Family<FA, FB>& f, int paths, int steps, std::uint64_t seed) {
  Rng rng(seed);
  const cw::Tolerances tight = tightTolerances();
  for (int p = 0; p < paths; ++p) {
    const int ia = static_cast<int>(rng.next() % f.ca.size()), ib = static_cast<int>(rng.next() % f.cb.size());
    const cw::Pose pa = rng.pose(Vec3::Zero()), pb0 = rng.pose(Vec3::Zero());
    const Vec3 axis = rng.unitVector();
    const double phase = rng.uniform(0, 2 * M_PI);
    for (int i = 0; i < steps; ++i) {
      const double s = static_cast<double>(i) / steps;
      const double theta = 2 * M_PI * s + phase, phi = 0.6 * std::sin(4 * M_PI * s);
      const Vec3 u(std::cos(theta) * std::cos(phi), std::sin(theta) * std::cos(phi), std::sin(phi));
      PairCase c;
      c.ia = ia;
      c.ib = ib;
      c.pa = pa;
      c.pb = pb0;
      c.pb.R = Eigen::AngleAxisd(3 * M_PI * s, axis).toRotationMatrix() * pb0.R;
      const double k = 1.06 + 0.10 * std::sin(10 * M_PI * s + phase);
      c.pb.t = k * (reach(f.ca[ia], pa, u) + reach(f.cb[ib], c.pb, -u)) * u;
      c.ta = toFcl(c.pa);
      c.tb = toFcl(c.pb);
      const cw::DistanceResult r = cw::gjkDistance(f.ca[ia], c.pa, f.cb[ib], c.pb, tight);
      // Without a certificate the step has no reference: it is timed but not judged (NaN).
      if (cw::isFailure(r.status)) ++f.reference_failures;
      c.ref = cw::isFailure(r.status) ? NAN : r.distance;
      c.path_start = i == 0;
      f.cases.push_back(c);
    }
  }
}

// ---- Statistics and reports ------------------------------------------------------------------------------

struct Row {
  std::string family, method;
  double tol = 0, ns = 0, iterations = NAN, mean_err = 0, max_err = 0;
  int failures = 0, n = 0;
  // Clearway distance rows: FCL's best time at the same tolerance, and at equal or better accuracy.
  double fcl_same_ns = NAN, fcl_acc_ns = NAN;
  std::string fcl_same_method, fcl_acc_method;
  double fcl_acc_tol = NAN;
};

void errorStats(Row& row, const std::vector<double>& value, const std::vector<double>& ref,
                const std::vector<char>& failed) {
  double sum = 0, mx = 0;
  int counted = 0;
  row.failures = 0;
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (failed[i]) { ++row.failures; continue; }
    const double e = std::abs(value[i] - ref[i]);
    sum += e;
    mx = std::max(mx, e);
    ++counted;
  }
  row.mean_err = counted ? sum / counted : NAN;
  row.max_err = counted ? mx : NAN;
  row.n = static_cast<int>(value.size());
}

std::string fmt(const char* f, double x) {
  if (std::isnan(x)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

std::string machineNote(const Settings& s) {
  std::string cpu = "unknown CPU";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);) {
    if (line.rfind("model name", 0) == 0) { cpu = line.substr(line.find(':') + 2); break; }
  }
  std::string load;
  std::ifstream la("/proc/loadavg");
  std::getline(la, load);
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::ostringstream o;
  o << "# machine: " << cpu << ", " << std::thread::hardware_concurrency()
    << " hardware threads; loadavg at start: " << load << "\n# build: clearway " << CLEARWAY_BENCH_REVISION << ", "
    << CLEARWAY_BENCH_BUILD << "; compiler: " << __VERSION__ << "; FCL " << FCL_VERSION
    << "\n# run: " << date << "; " << s.pairs << " pairs per family, " << s.reps
    << " timed passes (median of thread CPU time), fixed seeds; errors in metres on shapes about 1 m across";
  return o.str();
}

}  // namespace

namespace {

// ---- GJK distance ----------------------------------------------------------------------------------------

double meanOf(const std::vector<int>& v) {
  double s = 0;
  for (int x : v) s += x;
  return v.empty() ? NAN : s / static_cast<double>(v.size());
}

// One configuration's results: the row and its per-pair outputs (filled by the last pass).
struct Outputs {
  std::vector<double> value;       // distance, or time of impact
  std::vector<int> iterations;
  std::vector<char> failed;        // the status carries no certificate
  std::vector<char> yes;           // the boolean answer: ray hit, pair intersecting
  explicit Outputs(std::size_t n) : value(n), iterations(n), failed(n), yes(n) {}
};

template <class FA, class FB>
void benchDistance(const Family<FA, FB>& f, const Settings& s, std::vector<Row>& out) {
  const std::size_t n = f.cases.size();
  std::vector<double> ref(n);
  for (std::size_t i = 0; i < n; ++i) ref[i] = f.cases[i].ref;
  std::deque<Outputs> outputs;  // a deque: the passes keep references into it
  std::vector<Row> rows;
  std::vector<Pass> passes;

  auto clearway = [&](double tol) {
    cw::Tolerances t = tol <= kTight ? tightTolerances() : cw::Tolerances{};
    t.gjk_relative = tol;
    Outputs& o = outputs.emplace_back(n);
    passes.push_back(makePass(n, [&f, &o, t](std::size_t i) {
      const PairCase& c = f.cases[i];
      const cw::DistanceResult r = cw::gjkDistance(f.ca[c.ia], c.pa, f.cb[c.ib], c.pb, t);
      doNotOptimize(r.point_a);
      doNotOptimize(r.point_b);
      o.value[i] = r.distance;
      o.iterations[i] = r.iterations;
      o.failed[i] = cw::isFailure(r.status);
    }));
    Row row;
    row.family = f.name, row.method = "clearway", row.tol = tol;
    rows.push_back(row);
  };
  // FCL's own GJK: gjk_tolerance is relative in its main test ((‖v‖ − v·w/‖v‖) ≤ tol·‖v‖) but also
  // absolute: ‖v‖ < tol is reported as "inside", and a support point within √tol of one of the last
  // four ends the loop.
  // Both FCL solvers run through the same pass; only their tolerance fields differ.
  auto fclPass = [&](auto solver, const char* method, double tol) {
    Outputs& o = outputs.emplace_back(n);
    passes.push_back(makePass(n, [&f, &o, solver](std::size_t i) {
      const PairCase& c = f.cases[i];
      double d = -1;
      Vec3 p1, p2;
      const bool ok = solver.shapeDistance(f.fa[c.ia], c.ta, f.fb[c.ib], c.tb, &d, &p1, &p2);
      doNotOptimize(p1);
      doNotOptimize(p2);
      o.value[i] = d;
      o.failed[i] = !ok;
    }));
    Row row;
    row.family = f.name, row.method = method, row.tol = tol;
    rows.push_back(row);
  };
  auto indep = [&](double tol) {
    fcl::detail::GJKSolver_indep<double> solver;
    solver.gjk_tolerance = tol;
    if (tol <= kTight) solver.gjk_max_iterations = 1000;
    fclPass(solver, "fcl_indep", tol);
  };
  // libccd: distance_tolerance is absolute (metres): stop when ‖v‖ improved by less than it.
  auto libccd = [&](double tol) {
    fcl::detail::GJKSolver_libccd<double> solver;
    solver.distance_tolerance = tol;
    fclPass(solver, "fcl_libccd", tol);
  };

  // The reference itself (error 0 by definition) and FCL at its tightest: the cross-check.
  clearway(kTight);
  indep(kTight);
  libccd(kTight);
  for (double tol : kTolerances) {
    clearway(tol);
    indep(tol);
    libccd(tol);
  }
  const std::vector<double> ns = medianInterleaved(passes, s.reps);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    rows[k].ns = ns[k];
    errorStats(rows[k], outputs[k].value, ref, outputs[k].failed);
    if (rows[k].method == "clearway") rows[k].iterations = meanOf(outputs[k].iterations);
  }
  std::fprintf(stderr, "  distance  %-16s done\n", f.name.c_str());

  // Ratios for Clearway's rows: FCL's faster solver at the same tolerance, and FCL's fastest setting
  // (either solver, any tolerance including 1e-12) whose worst error is no larger than ours.
  for (Row& r : rows) {
    if (r.method != "clearway") continue;
    for (const Row& q : rows) {
      if (q.method == "clearway") continue;
      if (q.tol == r.tol && !(q.ns >= r.fcl_same_ns)) r.fcl_same_ns = q.ns, r.fcl_same_method = q.method;
      const bool accurate = q.failures == 0 && q.max_err <= std::max(r.max_err, kErrorFloor);
      if (accurate && !(q.ns >= r.fcl_acc_ns)) r.fcl_acc_ns = q.ns, r.fcl_acc_method = q.method, r.fcl_acc_tol = q.tol;
    }
  }
  out.insert(out.end(), rows.begin(), rows.end());
}

// ---- GJK ray cast --------------------------------------------------------------------------------------------

struct RayCase {
  int is = 0;
  cw::Pose pose;
  cw::Ray ray;
  double ref_t = 0;
  bool ref_hit = false;
};

struct RayFamily {
  std::string name;
  std::vector<cw::Shape> pool;
  std::vector<RayCase> cases;
};

// ---- Ray references: exact ray–solid intersection, independent of GJK ----------------------------------
// The GJK ray cast is measured against closed forms: clipping the ray by each face plane of a polytope
// (Cyrus–Beck), quadrics for the curved primitives. The ray starts outside the solid, so the first
// parameter at which it is inside is the time of impact.

struct Interval {
  double lo = -INFINITY, hi = INFINITY;
  bool empty() const { return !(lo <= hi); }
};

// Keeps the part of the ray o + t·d with n·x ≤ c.
void clipPlane(Interval& iv, const Vec3& n, double c, const Vec3& o, const Vec3& d) {
  const double nd = n.dot(d), no = n.dot(o);
  if (nd == 0.0) {
    if (no > c) iv.lo = INFINITY, iv.hi = -INFINITY;
  } else if (nd < 0.0) {
    iv.lo = std::max(iv.lo, (c - no) / nd);
  } else {
    iv.hi = std::min(iv.hi, (c - no) / nd);
  }
}

// Keeps the part with a·t² + b·t + c ≤ 0 for a > 0 (one interval between the roots, or nothing).
void clipQuadratic(Interval& iv, double a, double b, double c) {
  const double disc = b * b - 4 * a * c;
  if (!(disc >= 0.0)) { iv.lo = INFINITY, iv.hi = -INFINITY; return; }
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));  // roots q/a and c/q without cancellation
  double t1 = q / a, t2 = q != 0.0 ? c / q : t1;
  if (t1 > t2) std::swap(t1, t2);
  iv.lo = std::max(iv.lo, t1);
  iv.hi = std::min(iv.hi, t2);
}

// The solid cylinder |xy| ≤ r, |z| ≤ h as an interval of the ray (local frame).
Interval cylinderInterval(double r, double h, const Vec3& o, const Vec3& d) {
  Interval iv;
  clipPlane(iv, Vec3::UnitZ(), h, o, d);
  clipPlane(iv, -Vec3::UnitZ(), h, o, d);
  const double a = d.x() * d.x() + d.y() * d.y();
  const double c = o.x() * o.x() + o.y() * o.y() - r * r;
  if (a > 1e-300) clipQuadratic(iv, a, 2 * (o.x() * d.x() + o.y() * d.y()), c);
  else if (c > 0.0) iv.lo = INFINITY, iv.hi = -INFINITY;
  return iv;
}

Interval sphereInterval(const Vec3& center, double r, const Vec3& o, const Vec3& d) {
  Interval iv;
  const Vec3 oc = o - center;
  clipQuadratic(iv, d.squaredNorm(), 2 * oc.dot(d), oc.squaredNorm() - r * r);
  return iv;
}

// Entry parameter of the ray into one convex piece, or +∞.
double entry(const Interval& iv) { return iv.empty() || iv.hi < 0.0 ? INFINITY : std::max(iv.lo, 0.0); }

struct ExactRay {
  const Vec3& o;  // ray origin, local frame
  const Vec3& d;  // unit direction, local frame
  double operator()(const cw::ConvexHull& s) const {
    Interval iv;
    for (const auto& t : s.triangles()) {
      const Vec3& a = s.vertices()[t[0]];
      const Vec3 n = (s.vertices()[t[1]] - a).cross(s.vertices()[t[2]] - a);  // outward (counter-clockwise)
      clipPlane(iv, n, n.dot(a), o, d);
    }
    return entry(iv);
  }
  double operator()(const cw::Box& s) const {
    Interval iv;
    for (int k = 0; k < 3; ++k) {
      clipPlane(iv, Vec3::Unit(k), s.half[k], o, d);
      clipPlane(iv, -Vec3::Unit(k), s.half[k], o, d);
    }
    return entry(iv);
  }
  double operator()(const cw::Cylinder& s) const { return entry(cylinderInterval(s.r, s.h, o, d)); }
  double operator()(const cw::Capsule& s) const {
    // The union of a cylinder and two end spheres: the ray enters the union where it first enters a piece.
    return std::min({entry(cylinderInterval(s.r, s.h, o, d)), entry(sphereInterval(Vec3(0, 0, s.h), s.r, o, d)),
                     entry(sphereInterval(Vec3(0, 0, -s.h), s.r, o, d))});
  }
  double operator()(const cw::Cone& s) const {
    // Solid: −h ≤ z ≤ h and |xy| ≤ k (h − z), k = r / 2h. The entry point lies on the base disc or on the
    // lateral surface x² + y² = k² (h − z)²: take the first candidate that is on the solid.
    const double k = s.r / (2 * s.h), hz = s.h - o.z();
    std::vector<double> ts;
    if (d.z() != 0.0) ts.push_back((-s.h - o.z()) / d.z());
    const double a = d.x() * d.x() + d.y() * d.y() - k * k * d.z() * d.z();
    const double b = 2 * (o.x() * d.x() + o.y() * d.y() + k * k * hz * d.z());
    const double c = o.x() * o.x() + o.y() * o.y() - k * k * hz * hz;
    if (std::abs(a) > 1e-14) {
      const double disc = b * b - 4 * a * c;
      if (disc >= 0.0) {
        const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        ts.push_back(q / a);
        if (q != 0.0) ts.push_back(c / q);
      }
    } else if (b != 0.0) {
      ts.push_back(-c / b);
    }
    const double slack = 1e-12 * (s.r + s.h);
    double best = INFINITY;
    for (double t : ts) {
      if (!(t >= 0.0) || !(t < best)) continue;
      const Vec3 p = o + t * d;
      if (p.z() >= -s.h - slack && p.z() <= s.h + slack && std::hypot(p.x(), p.y()) <= k * (s.h - p.z()) + slack)
        best = t;
    }
    return best;
  }
  template <class S>
  double operator()(const S&) const {
    throw std::logic_error("no exact ray reference for this shape");
  }
};

double exactRayHit(const cw::Shape& shape, const cw::Pose& pose, const cw::Ray& ray) {
  const Vec3 o = pose.R.transpose() * (ray.origin - pose.t), d = pose.R.transpose() * ray.direction;
  const double t = std::visit(ExactRay{o, d}, shape);
  return t <= ray.max_t ? t : INFINITY;
}

// Rays from 3 × the bounding radius away, aimed at a random point within 0.8 × that radius of the
// shape's origin: most hit, some graze or miss. Unit directions, so t is in metres.
template <class Make>
RayFamily makeRays(const std::string& name, int pool, int n, std::uint64_t seed, Make make) {
  RayFamily f;
  f.name = name;
  Rng rng(seed);
  for (int i = 0; i < pool; ++i) f.pool.push_back(make(rng).first);
  while (static_cast<int>(f.cases.size()) < n) {
    RayCase c;
    c.is = static_cast<int>(rng.next() % f.pool.size());
    c.pose = rng.pose(Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
    const double radius = cw::boundingRadius(f.pool[c.is]);
    c.ray.origin = c.pose.t + 3 * radius * rng.unitVector();
    const Vec3 target = c.pose.t + 0.8 * radius * rng.inBall();
    c.ray.direction = (target - c.ray.origin).normalized();
    c.ray.max_t = 6 * radius;
    c.ref_t = exactRayHit(f.pool[c.is], c.pose, c.ray);
    c.ref_hit = std::isfinite(c.ref_t);
    f.cases.push_back(c);
  }
  return f;
}

struct RayRow {
  std::string family;
  double tol = 0, ns = 0, iterations = 0, mean_err = 0, max_err = 0, vdb_us = NAN;
  int mismatches = 0, hits = 0, not_converged = 0, n = 0;
};

void benchRays(const RayFamily& f, const Settings& s, std::vector<RayRow>& out) {
  if (!s.wanted(f.name)) return;
  const std::size_t n = f.cases.size();
  std::deque<Outputs> outputs;
  std::vector<Pass> passes;
  for (double tol_value : kTolerances) {
    cw::Tolerances tol;
    tol.cast_relative = tol_value;
    Outputs& o = outputs.emplace_back(n);
    passes.push_back(makePass(n, [&f, &o, tol](std::size_t i) {
      const RayCase& c = f.cases[i];
      const cw::CastResult r = cw::gjkRayCast(f.pool[c.is], c.pose, c.ray, tol);
      doNotOptimize(r.normal);
      doNotOptimize(r.point);
      o.value[i] = r.t;
      o.yes[i] = r.hit;
      o.failed[i] = cw::isFailure(r.status);
      o.iterations[i] = r.iterations;
    }));
  }
  const std::vector<double> ns = medianInterleaved(passes, s.reps);
  for (std::size_t k = 0; k < std::size(kTolerances); ++k) {
    RayRow row;
    row.family = f.name;
    row.tol = kTolerances[k];
    row.vdb_us = kVanDenBergenRayUs[k];
    row.ns = ns[k];
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const RayCase& c = f.cases[i];
      row.not_converged += outputs[k].failed[i];
      if (static_cast<bool>(outputs[k].yes[i]) != c.ref_hit) { ++row.mismatches; continue; }
      if (!c.ref_hit) continue;
      const double e = std::abs(outputs[k].value[i] - c.ref_t);
      sum += e;
      row.max_err = std::max(row.max_err, e);
      ++row.hits;
    }
    row.mean_err = row.hits ? sum / row.hits : NAN;
    row.iterations = meanOf(outputs[k].iterations);
    row.n = static_cast<int>(n);
    out.push_back(row);
  }
  std::fprintf(stderr, "  ray cast  %-16s done\n", f.name.c_str());
}

// ---- Intersection along smooth paths -----------------------------------------------------------------------

struct IntersectRow {
  std::string family, method;
  double ns = 0, iterations = NAN, colliding = 0;
  int wrong = 0, n = 0;
};

// A boolean is wrong when it contradicts the reference distance outside a band of 1 µm around contact.
constexpr double kContactBand = 1e-6;

template <class FA, class FB>
void benchIntersect(const Family<FA, FB>& f, const Settings& s, std::vector<IntersectRow>& out) {
  const std::size_t n = f.cases.size();
  std::deque<Outputs> outputs;
  std::vector<IntersectRow> rows;
  std::vector<Pass> passes;
  const cw::Tolerances tol;
  auto add = [&](const char* method) -> Outputs& {
    IntersectRow row;
    row.family = f.name;
    row.method = method;
    rows.push_back(row);
    return outputs.emplace_back(n);
  };

  {
    Outputs& o = add("clearway_cold");
    passes.push_back(makePass(n, [&f, &o, tol](std::size_t i) {
      const PairCase& c = f.cases[i];
      cw::SimplexCache cache;
      const cw::IntersectResult r = cw::gjkIntersect(f.ca[c.ia], c.pa, f.cb[c.ib], c.pb, tol, cache);
      o.yes[i] = r.intersecting;
      o.iterations[i] = r.iterations;
    }));
  }
  {
    Outputs& o = add("clearway_warm");
    passes.push_back(makePass(n, [&f, &o, tol, cache = cw::SimplexCache{}](std::size_t i) mutable {
      const PairCase& c = f.cases[i];
      if (c.path_start) cache = cw::SimplexCache{};  // one cache per path
      const cw::IntersectResult r = cw::gjkIntersect(f.ca[c.ia], c.pa, f.cb[c.ib], c.pb, tol, cache);
      o.yes[i] = r.intersecting;
      o.iterations[i] = r.iterations;
    }));
  }
  for (bool cached : {false, true}) {
    // FCL's own GJK, optionally warm-started from the previous query's direction (its cached guess).
    Outputs& o = add(cached ? "fcl_indep_cached" : "fcl_indep");
    fcl::detail::GJKSolver_indep<double> solver;
    solver.enableCachedGuess(cached);
    passes.push_back(makePass(n, [&f, &o, solver](std::size_t i) mutable {
      const PairCase& c = f.cases[i];
      if (c.path_start) solver.setCachedGuess(Vec3(1, 0, 0));
      o.yes[i] = solver.shapeIntersect(f.fa[c.ia], c.ta, f.fb[c.ib], c.tb, nullptr);
    }));
  }
  {
    Outputs& o = add("fcl_libccd");
    fcl::detail::GJKSolver_libccd<double> solver;
    passes.push_back(makePass(n, [&f, &o, solver](std::size_t i) {
      const PairCase& c = f.cases[i];
      o.yes[i] = solver.shapeIntersect(f.fa[c.ia], c.ta, f.fb[c.ib], c.tb, nullptr);
    }));
  }

  const std::vector<double> ns = medianInterleaved(passes, s.reps);
  int colliding = 0;
  for (const PairCase& c : f.cases) colliding += c.ref <= 0.0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    IntersectRow& row = rows[k];
    row.ns = ns[k];
    row.n = static_cast<int>(n);
    row.colliding = static_cast<double>(colliding) / static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double d = f.cases[i].ref;
      const bool hit = outputs[k].yes[i];
      if ((d <= 0.0 && !hit) || (d > kContactBand && hit)) ++row.wrong;
    }
    if (row.method.rfind("clearway", 0) == 0) row.iterations = meanOf(outputs[k].iterations);
    out.push_back(row);
  }
  std::fprintf(stderr, "  intersect %-16s done\n", f.name.c_str());
}

// ---- One family through every query ---------------------------------------------------------------------

template <class FA, class FB>
void runFamily(Family<FA, FB> pools, std::uint64_t seed, const Settings& s, std::vector<Row>& distance,
               std::vector<IntersectRow>& intersect) {
  if (!s.wanted(pools.name)) return;
  Family<FA, FB> separated = pools;
  addSeparatedPairs(separated, s.pairs, seed + 1);
  if (separated.reference_failures > 0)
    std::printf("note: %s: %d candidate pairs dropped, reference (GJK at 1e-12) not converged\n", pools.name.c_str(),
                separated.reference_failures);
  benchDistance(separated, s, distance);
  addPaths(pools, s.paths, s.path_steps, seed + 2);
  if (pools.reference_failures > 0)
    std::printf("note: %s: %d path steps without a reference (GJK at 1e-12 not converged), not judged\n",
                pools.name.c_str(), pools.reference_failures);
  benchIntersect(pools, s, intersect);
}

// ---- Output -----------------------------------------------------------------------------------------------

const Row* findRow(const std::vector<Row>& rows, const std::string& family, const std::string& method, double tol) {
  for (const Row& r : rows)
    if (r.family == family && r.method == method && r.tol == tol) return &r;
  return nullptr;
}

std::vector<std::string> familiesOf(const std::vector<Row>& rows) {
  std::vector<std::string> f;
  for (const Row& r : rows)
    if (std::find(f.begin(), f.end(), r.family) == f.end()) f.push_back(r.family);
  return f;
}

void printDistance(const std::vector<Row>& rows) {
  std::printf("\n== GJK distance: mean time per query, iterations, |distance − reference| (m) ==\n");
  std::printf("reference: Clearway GJK at 1e-12; FCL columns use the same pairs and tolerance value\n");
  std::printf("(fcl_indep: gjk_tolerance, relative; fcl_libccd: distance_tolerance, absolute in m).\n");
  std::printf("ratio@tol = faster FCL solver at the same tolerance / Clearway;\n");
  std::printf("ratio@acc = fastest FCL setting (either solver, any tolerance) with max error <= Clearway's (floor %.0e m) / Clearway.\n",
              kErrorFloor);
  for (const std::string& fam : familiesOf(rows)) {
    std::printf("\n%-15s %7s | %8s %6s %9s %9s | %8s %9s %9s %4s | %8s %9s %9s %4s | %8s %s\n", fam.c_str(), "tol",
                "CW ns", "iters", "mean err", "max err", "indep ns", "mean err", "max err", "fail", "ccd ns",
                "mean err", "max err", "fail", "ratio@tol", "ratio@acc (FCL setting)");
    for (double tol : kTolerances) {
      const Row* c = findRow(rows, fam, "clearway", tol);
      const Row* i = findRow(rows, fam, "fcl_indep", tol);
      const Row* l = findRow(rows, fam, "fcl_libccd", tol);
      if (!c || !i || !l) continue;
      std::string acc = "none reaches it";
      if (!std::isnan(c->fcl_acc_ns))
        acc = fmt("%.2f", c->fcl_acc_ns / c->ns) + " (" + c->fcl_acc_method + "@" + fmt("%.0e", c->fcl_acc_tol) + ")";
      std::printf("%-15s %7.0e | %8.0f %6.2f %9.2e %9.2e | %8.0f %9.2e %9.2e %4d | %8.0f %9.2e %9.2e %4d | %9s %s\n",
                  "", tol, c->ns, c->iterations, c->mean_err, c->max_err, i->ns, i->mean_err, i->max_err, i->failures,
                  l->ns, l->mean_err, l->max_err, l->failures, fmt("%.2f", c->fcl_same_ns / c->ns).c_str(), acc.c_str());
    }
    const Row* ref = findRow(rows, fam, "clearway", kTight);
    const Row* i = findRow(rows, fam, "fcl_indep", kTight);
    const Row* l = findRow(rows, fam, "fcl_libccd", kTight);
    if (ref && i && l)
      std::printf("%-15s   1e-12 | %8.0f %6.2f (reference) | cross-check: max |FCL − reference| indep %.2e (%d fail), "
                  "libccd %.2e (%d fail); %.0f / %.0f ns\n",
                  "", ref->ns, ref->iterations, i->max_err, i->failures, l->max_err, l->failures, i->ns, l->ns);
  }
}

void printRays(const std::vector<RayRow>& rows) {
  std::printf("\n== GJK ray cast (Clearway; FCL 0.7 has none): time per query, iterations, |t − reference| (m) ==\n");
  std::printf("vdB04 = G. van den Bergen (2004), same algorithm, published µs per query on a 2.6 GHz CPU.\n");
  std::printf("reference: exact ray–solid intersection (face planes, quadrics); wrong = hit/miss differs from it;\n");
  std::printf("nconv = casts that reached the iteration cap (Status::NotConverged).\n");
  std::printf("%-10s %7s | %8s %6s %9s %9s %5s %5s %5s | %8s\n", "shape", "tol", "ns", "iters", "mean err", "max err",
              "hits", "wrong", "nconv", "vdB04 ns");
  for (const RayRow& r : rows)
    std::printf("%-10s %7.0e | %8.0f %6.2f %9.2e %9.2e %5d %5d %5d | %8.0f\n", r.family.c_str(), r.tol, r.ns,
                r.iterations, r.mean_err, r.max_err, r.hits, r.mismatches, r.not_converged, r.vdb_us * 1000);
}

double fastestFcl(const std::vector<IntersectRow>& rows, const std::string& family, std::string* which) {
  double best = NAN;
  for (const IntersectRow& r : rows)
    if (r.family == family && r.method.rfind("fcl", 0) == 0 && !(r.ns >= best)) best = r.ns, *which = r.method;
  return best;
}

void printIntersect(const std::vector<IntersectRow>& rows) {
  std::printf("\n== Intersection along smooth paths (default tolerances): time per query, iterations ==\n");
  std::printf("wrong = boolean contradicting the reference distance outside a %.0e m band; ratio = fastest FCL / this.\n",
              kContactBand);
  std::printf("%-15s %-17s | %8s %6s %6s %9s | %s\n", "family", "method", "ns", "iters", "wrong", "colliding",
              "ratio (fastest FCL)");
  for (const IntersectRow& r : rows) {
    std::string which;
    const double best = fastestFcl(rows, r.family, &which);
    std::printf("%-15s %-17s | %8.0f %6s %6d %8.1f%% | %.2f (%s)\n", r.family.c_str(), r.method.c_str(), r.ns,
                fmt("%.2f", r.iterations).c_str(), r.wrong, 100 * r.colliding, best / r.ns, which.c_str());
  }
}

std::ofstream openCsv(const Settings& s, const std::string& file, const std::string& note) {
  const std::string path = s.out + "/" + file;
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write " + path);
  f << note << "\n";
  f.precision(6);
  std::fprintf(stderr, "writing %s\n", path.c_str());
  return f;
}

std::string csvNum(double x) {
  if (std::isnan(x)) return "";
  std::ostringstream o;
  o.precision(6);
  o << x;
  return o.str();
}

void writeCsv(const Settings& s, const std::string& note, std::vector<Row> distance, const std::vector<RayRow>& rays,
              const std::vector<IntersectRow>& intersect) {
  // Grouped by family, then method, then tolerance (descending), so each curve is contiguous for gnuplot.
  auto rank = [](const std::string& m) { return m == "clearway" ? 0 : m == "fcl_indep" ? 1 : 2; };
  const std::vector<std::string> fams = familiesOf(distance);
  auto famRank = [&](const std::string& f) { return std::find(fams.begin(), fams.end(), f) - fams.begin(); };
  std::stable_sort(distance.begin(), distance.end(), [&](const Row& a, const Row& b) {
    if (famRank(a.family) != famRank(b.family)) return famRank(a.family) < famRank(b.family);
    if (rank(a.method) != rank(b.method)) return rank(a.method) < rank(b.method);
    return a.tol > b.tol;
  });
  {
    std::ofstream f = openCsv(s, "narrowphase_distance.csv",
                              note + "\n# distance error vs Clearway GJK at 1e-12; tolerance 1e-12 rows are the reference "
                                     "(clearway) and the cross-check (FCL)");
    f << "family,method,tolerance,ns_per_query,mean_iterations,mean_err,max_err,failures,n,"
         "fcl_same_tol_method,fcl_same_tol_ns,ratio_same_tol,fcl_eq_acc_method,fcl_eq_acc_tol,fcl_eq_acc_ns,ratio_eq_acc\n";
    for (const Row& r : distance) {
      f << r.family << ',' << r.method << ',' << csvNum(r.tol) << ',' << csvNum(r.ns) << ',' << csvNum(r.iterations)
        << ',' << csvNum(r.mean_err) << ',' << csvNum(r.max_err) << ',' << r.failures << ',' << r.n << ','
        << r.fcl_same_method << ',' << csvNum(r.fcl_same_ns) << ',' << csvNum(r.fcl_same_ns / r.ns) << ','
        << r.fcl_acc_method << ',' << csvNum(r.fcl_acc_tol) << ',' << csvNum(r.fcl_acc_ns) << ','
        << csvNum(r.fcl_acc_ns / r.ns) << '\n';
    }
  }
  {
    std::ofstream f = openCsv(s, "narrowphase_raycast.csv",
                              note + "\n# t error (m) vs exact ray-solid intersection; vdb2004_us: van den Bergen (2004), 2.6 GHz");
    f << "family,method,tolerance,ns_per_query,mean_iterations,mean_err,max_err,mismatches,not_converged,hits,n,"
         "vdb2004_us\n";
    for (const RayRow& r : rays)
      f << r.family << ",clearway," << csvNum(r.tol) << ',' << csvNum(r.ns) << ',' << csvNum(r.iterations) << ','
        << csvNum(r.mean_err) << ',' << csvNum(r.max_err) << ',' << r.mismatches << ',' << r.not_converged << ','
        << r.hits << ',' << r.n << ','
        << csvNum(r.vdb_us) << '\n';
  }
  {
    std::ofstream f = openCsv(s, "narrowphase_intersect.csv",
                              note + "\n# smooth paths; wrong: boolean contradicting the reference outside a 1e-6 m band");
    f << "family,method,ns_per_query,mean_iterations,wrong,n,colliding_fraction,fastest_fcl_method,ratio_fastest_fcl\n";
    for (const IntersectRow& r : intersect) {
      std::string which;
      const double best = fastestFcl(intersect, r.family, &which);
      f << r.family << ',' << r.method << ',' << csvNum(r.ns) << ',' << csvNum(r.iterations) << ',' << r.wrong << ','
        << r.n << ',' << csvNum(r.colliding) << ',' << which << ',' << csvNum(best / r.ns) << '\n';
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Settings s;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) {
      s.out = argv[++i];
    } else if (a == "--only" && i + 1 < argc) {
      s.only = argv[++i];
    } else if (a == "--quick") {  // a smoke run: small lists, one pass
      s.pairs = 200, s.path_steps = 200, s.paths = 2, s.reps = 1;
    } else {
      std::fprintf(stderr, "usage: %s [--out DIR] [--quick] [--only FAMILY]\n", argv[0]);
      return 2;
    }
  }
  const std::string note = machineNote(s);
  std::printf("%s\n", note.c_str());

  std::vector<Row> distance;
  std::vector<IntersectRow> intersect;
  std::vector<RayRow> rays;
  try {
    auto hull = [](int n) { return [n](Rng& r) { return makeHull(r, n); }; };
    // Hull pools are small (8 shapes), as a robot link's hull would be reused across queries; the
    // pairs draw from them with random poses.
    runFamily(makePools<fcl::Convexd, fcl::Convexd>("hull16", 8, 1601, hull(16), hull(16)), 1610, s, distance, intersect);
    runFamily(makePools<fcl::Convexd, fcl::Convexd>("hull64", 8, 6401, hull(64), hull(64)), 6410, s, distance, intersect);
    runFamily(makePools<fcl::Convexd, fcl::Convexd>("hull256", 8, 25601, hull(256), hull(256)), 25610, s, distance,
              intersect);
    runFamily(makePools<fcl::Boxd, fcl::Boxd>("box-box", 64, 101, makeBox, makeBox), 110, s, distance, intersect);
    runFamily(makePools<fcl::Sphered, fcl::Boxd>("sphere-box", 64, 201, makeSphere, makeBox), 210, s, distance,
              intersect);
    runFamily(makePools<fcl::Capsuled, fcl::Capsuled>("capsule-capsule", 64, 301, makeCapsule, makeCapsule), 310, s,
              distance, intersect);
    runFamily(makePools<fcl::Cylinderd, fcl::Coned>("cylinder-cone", 64, 401, makeCylinder, makeCone), 410, s,
              distance, intersect);

    benchRays(makeRays("hull16", 8, s.pairs, 1620, hull(16)), s, rays);
    benchRays(makeRays("hull64", 8, s.pairs, 6420, hull(64)), s, rays);
    benchRays(makeRays("hull256", 8, s.pairs, 25620, hull(256)), s, rays);
    benchRays(makeRays("box", 64, s.pairs, 120, makeBox), s, rays);
    benchRays(makeRays("capsule", 64, s.pairs, 320, makeCapsule), s, rays);
    benchRays(makeRays("cylinder", 64, s.pairs, 420, makeCylinder), s, rays);
    benchRays(makeRays("cone", 64, s.pairs, 520, makeCone), s, rays);

    printDistance(distance);
    printRays(rays);
    printIntersect(intersect);
    writeCsv(s, note, distance, rays, intersect);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_narrowphase: %s\n", e.what());
    return 1;
  }
  return 0;
}
