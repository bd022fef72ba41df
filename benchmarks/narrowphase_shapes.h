#pragma once
// Random convex shapes and poses that are the same for Clearway and for FCL, from a seeded generator of
// our own (so that every run, shard and library sees the same pairs).
#include "bench_rng.h"
#include "fcl_robot.h"

#include <clearway/narrowphase/gjk.h>
#include <clearway/shape/convex_hull.h>
#include <clearway/shape/shape.h>
#include <clearway/tolerances.h>

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cone.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <memory>
#include <utility>
#include <vector>

namespace clearway::bench {

// How far the posed shape reaches along unit d, measured from its pose's origin (skin included).
inline double reach(const clearway::Shape& shape, const clearway::Pose& pose, const Vec3& d) {
  return std::visit([&](const auto& s) { return d.dot(pose.R * s.support(pose.R.transpose() * d)) + s.radius(); },
                    shape);
}

// ---- Shapes: each maker returns the same shape for Clearway and for FCL ------------------------------

// The convex hull of n points on the surface of an ellipsoid with random semi-axes in [0.5, 1.5] m, so
// that nearly every point is a vertex. FCL gets exactly our hull's vertices and triangles.
inline std::pair<clearway::Shape, fcl::Convexd> makeHull(Rng& rng, int n) {
  const Vec3 axes(rng.uniform(0.5, 1.5), rng.uniform(0.5, 1.5), rng.uniform(0.5, 1.5));
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.push_back(axes.cwiseProduct(rng.unitVector()));
  clearway::ConvexHull hull(pts);
  auto vertices = std::make_shared<std::vector<Vec3>>(hull.vertices());
  auto faces = std::make_shared<std::vector<int>>();
  for (const auto& t : hull.triangles()) faces->insert(faces->end(), {3, t[0], t[1], t[2]});
  const int nf = static_cast<int>(hull.triangles().size());
  // throw_if_invalid = true proves FCL accepted the mesh as watertight and convex (its edge walk is on).
  fcl::Convexd convex(vertices, nf, faces, /*throw_if_invalid=*/true);
  return {clearway::Shape(std::move(hull)), convex};
}

inline std::pair<clearway::Shape, fcl::Boxd> makeBox(Rng& rng) {
  const Vec3 h(rng.uniform(0.2, 1.0), rng.uniform(0.2, 1.0), rng.uniform(0.2, 1.0));
  return {clearway::Box(h), fcl::Boxd(2 * h.x(), 2 * h.y(), 2 * h.z())};
}
inline std::pair<clearway::Shape, fcl::Sphered> makeSphere(Rng& rng) {
  const double r = rng.uniform(0.2, 1.0);
  return {clearway::Sphere(r), fcl::Sphered(r)};
}
inline std::pair<clearway::Shape, fcl::Capsuled> makeCapsule(Rng& rng) {
  const double r = rng.uniform(0.1, 0.5), h = rng.uniform(0.1, 1.0);
  return {clearway::Capsule(r, h), fcl::Capsuled(r, 2 * h)};
}
inline std::pair<clearway::Shape, fcl::Cylinderd> makeCylinder(Rng& rng) {
  const double r = rng.uniform(0.2, 0.8), h = rng.uniform(0.2, 1.0);
  return {clearway::Cylinder(r, h), fcl::Cylinderd(r, 2 * h)};
}
inline std::pair<clearway::Shape, fcl::Coned> makeCone(Rng& rng) {
  const double r = rng.uniform(0.2, 0.8), h = rng.uniform(0.2, 1.0);
  return {clearway::Cone(r, h), fcl::Coned(r, 2 * h)};  // both: apex at +h, base at −h
}

constexpr double kTight = 1e-12;  ///< the reference tolerance

// ---- Pair families --------------------------------------------------------------------------------------

inline clearway::Tolerances tightTolerances() {
  clearway::Tolerances t;
  t.gjk_relative = kTight;
  t.gjk_max_iterations = 1000;
  t.cast_relative = kTight;
  t.cast_max_iterations = 1000;
  return t;
}

struct PairCase {
  int ia = 0, ib = 0;  // indices into the shape pools
  clearway::Pose pa, pb;
  fcl::Transform3d ta, tb;
  double ref = 0.0;        // reference distance (Clearway at 1e-12)
  bool path_start = false;  // intersection paths: the first pose of a path (warm caches restart)
};

// Shape pools for A and B (the same shapes in both libraries) and the list of posed pairs.
template <class FA, class FB>
struct Family {
  std::string name;
  std::vector<clearway::Shape> ca, cb;
  std::vector<FA> fa;
  std::vector<FB> fb;
  std::vector<PairCase> cases;
  int reference_failures = 0;  // candidate pairs dropped because the reference did not converge
};

template <class FA, class FB, class MakeA, class MakeB>
inline Family<FA, FB> makePools(const std::string& name, int pool, std::uint64_t seed, MakeA makeA, MakeB makeB) {
  Family<FA, FB> f;
  f.name = name;
  Rng rng(seed);
  for (int i = 0; i < pool; ++i) {
    auto a = makeA(rng);
    f.ca.push_back(std::move(a.first));
    f.fa.push_back(std::move(a.second));
    auto b = makeB(rng);
    f.cb.push_back(std::move(b.first));
    f.fb.push_back(std::move(b.second));
  }
  return f;
}

// Random separated pairs: random rotations, B placed along a random direction at (0.8 … 1.8) × the
// sum of both shapes' reaches, kept when the reference gap is at least 1 cm.
template <class FA, class FB>
inline void addSeparatedPairs(Family<FA, FB>& f, int n, std::uint64_t seed) {
  Rng rng(seed);
  const clearway::Tolerances tight = tightTolerances();
  while (static_cast<int>(f.cases.size()) < n) {
    PairCase c;
    c.ia = static_cast<int>(rng.next() % f.ca.size());
    c.ib = static_cast<int>(rng.next() % f.cb.size());
    c.pa = rng.pose(Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
    c.pb = rng.pose(Vec3::Zero());
    const Vec3 u = rng.unitVector();
    const double reach_sum = reach(f.ca[c.ia], c.pa, u) + reach(f.cb[c.ib], c.pb, -u);
    c.pb.t = c.pa.t + rng.uniform(0.8, 1.8) * reach_sum * u;
    const clearway::DistanceResult r = clearway::gjkDistance(f.ca[c.ia], c.pa, f.cb[c.ib], c.pb, tight);
    if (clearway::isFailure(r.status)) ++f.reference_failures;
    if (clearway::isFailure(r.status) || !(r.distance >= 0.01)) continue;
    c.ref = r.distance;
    c.ta = toFcl(c.pa);
    c.tb = toFcl(c.pb);
    f.cases.push_back(c);
  }
}

}  // namespace clearway::bench
