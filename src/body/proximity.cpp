// The proximity ladder (proximity.h): its rungs, the link-level queries of intersection, screening, bounds
// and distances between links and convex shapes, and BodyPair, which climbs them. Every query runs in
// the frame of its first link (A): B's tree is seen through b_in_a, primitives are placed in A's frame,
// and only the final witnesses go back to the world frame.
//
// Tolerance bookkeeping: a pair counts as intersecting when its distance is at most
//   slack = padding + band,   band = max(tol.gjk_absolute, 64 ulps) · scale,
// scale bounding every coordinate of the pair in A's frame. Box tests and the triangle SAT only
// discard pairs certainly farther apart than slack (the band dwarfs their rounding); what they keep,
// GJK decides within its own band, which is at most this one.
#include <clearway/body/proximity.h>

#include <clearway/detail/margins.h>
#include <clearway/narrowphase/epa.h>
#include <clearway/tree/oriented_box_test.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

namespace clearway {
namespace {

// ---- Query helpers ----------------------------------------------------------------------------------

// Triangle of A (A's frame) against triangle of B (B's frame, placed by b_in_a): the SAT discards
// pairs certainly apart; GJK decides the rest (and pads).
bool trianglePairIntersects(const Triangle& ta, const Triangle& tb, const Pose& b_in_a, const Tolerances& tol,
                            double padding, double slack) noexcept {
  const Vec3 vb[3] = {b_in_a * tb.v[0], b_in_a * tb.v[1], b_in_a * tb.v[2]};
  if (detail::trianglesSeparated(ta.v, vb, slack)) return false;
  SimplexCache cache;
  return gjkIntersect(Margin<Triangle>{ta, padding}, Pose::identity(), tb, b_in_a, tol, cache).intersecting;
}

// A convex shape placed in the link's frame by `shape_in_link` against the link's triangles.
template <class S>
bool shapeIntersectsTriangles(const S& s, const Pose& shape_in_link, const LinkGeometry& link, const Tolerances& tol,
                              double padding, double slack) noexcept {
  if (link.triangles().empty()) return false;
  // Nodes are tested against the shape's world box (cheap) and then against its own box as an oriented
  // box (SAT lite; full SAT for single triangles): a large primitive turned against the link's frame,
  // such as a pedestal beside an arm, would otherwise reach every triangle its world box covers.
  const Aabb box = placedBox(s, shape_in_link).inflated(slack);
  const Aabb own = placedBox(s, Pose::identity()).inflated(slack);
  const double scale = link.boundingRadius() + shape_in_link.t.norm() + own.min.cwiseAbs().cwiseMax(own.max.cwiseAbs()).norm();
  const detail::OrientedBoxTest test(shape_in_link, 0.0, scale);
  const detail::OrientedBoxTest::PlacedB placed = test.place(own);
  const std::vector<Triangle>& tris = link.triangles();
  const AabbTree& tree = link.tree();
  const auto apart = [&](const Aabb& node, auto full) {
    if (!overlaps(node, box)) return true;
    double c[3], h[3];
    detail::OrientedBoxTest::centerHalf(node, c, h);
    return test.separated<decltype(full)::value>(c, h, placed);
  };
  std::int32_t stack[AabbTree::kMaxDepth + 1];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const AabbTree::Node& n = tree.nodes()[stack[--top]];
    if (apart(n.box, std::false_type{})) continue;
    if (!n.isLeaf()) {
      stack[top++] = n.first + 1;
      stack[top++] = n.first;
      continue;
    }
    for (std::int32_t slot = n.first; slot < n.first + n.count; ++slot) {
      if (apart(tree.slotBoxes()[slot], std::true_type{})) continue;
      SimplexCache cache;
      if (gjkIntersect(Margin<S>{s, padding}, shape_in_link, tris[tree.items()[slot]], Pose::identity(), tol, cache)
              .intersecting)
        return true;
    }
  }
  return false;
}

bool shapeIntersectsTriangles(const Shape& s, const Pose& shape_in_link, const LinkGeometry& link, const Tolerances& tol,
                              double padding, double slack) noexcept {
  return std::visit([&](const auto& c) { return shapeIntersectsTriangles(c, shape_in_link, link, tol, padding, slack); },
                    s);
}

bool shapesIntersect(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const Tolerances& tol,
                     double padding) noexcept {
  return std::visit(
      [&](const auto& sa, const auto& sb) {
        using SA = std::decay_t<decltype(sa)>;
        SimplexCache cache;
        return gjkIntersect(Margin<SA>{sa, padding}, pa, sb, pb, tol, cache).intersecting;
      },
      a, b);
}

// The exact part of a Mesh-mode test, in A's frame.
bool exactIntersect(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a, const Tolerances& tol,
                    double padding, double slack, TrianglePair* witness = nullptr) noexcept {
  const std::vector<Triangle>& ta = a.triangles();
  const std::vector<Triangle>& tb = b.triangles();
  if (!ta.empty() && !tb.empty() &&
      forEachOverlapDeeperFirst(
          a.tree(), b.tree(), b_in_a,
          [&](std::int32_t i, std::int32_t j) {
            if (!trianglePairIntersects(ta[i], tb[j], b_in_a, tol, padding, slack)) return false;
            if (witness) *witness = {i, j};
            return true;
          },
          slack))
    return true;
  if (!a.primitives().empty() || !b.primitives().empty()) {
    const Pose a_in_b = b_in_a.inverse();
    for (const auto& p : a.primitives())
      if (shapeIntersectsTriangles(p.shape, a_in_b * p.pose, b, tol, padding, slack)) return true;
    for (const auto& p : b.primitives())
      if (shapeIntersectsTriangles(p.shape, b_in_a * p.pose, a, tol, padding, slack)) return true;
    for (const auto& p : a.primitives())
      for (const auto& q : b.primitives())
        if (shapesIntersect(p.shape, p.pose, q.shape, b_in_a * q.pose, tol, padding)) return true;
  }
  return false;
}

bool validPadding(double padding) noexcept { return padding >= 0.0 && std::isfinite(padding); }

// A box containing the shape, in its own frame (exact for boxes, spheres, capsules, cylinders and cones).
Aabb localBox(const Shape& shape) noexcept {
  return std::visit(
      [](const auto& s) -> Aabb {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, Box>) return Aabb::fromCenterHalf(Vec3::Zero(), s.half);
        else if constexpr (std::is_same_v<S, Sphere>) return Aabb::fromCenterHalf(Vec3::Zero(), Vec3::Constant(s.r));
        else if constexpr (std::is_same_v<S, Capsule> || std::is_same_v<S, Cylinder> || std::is_same_v<S, Cone>) {
          return Aabb::fromCenterHalf(Vec3::Zero(), Vec3(s.r, s.r, s.h + s.radius()));
        } else {
          return placedBox(s, Pose::identity());
        }
      },
      shape);
}

// True when the bounding spheres (centres given in one frame) are farther apart than the padding and
// the band (of the pair's scale, as in the exact tests).
bool spheresApart(const Vec3& ca, double ra, const Vec3& cb, double rb, double padding, const Tolerances& tol) noexcept {
  const double reach = ra + rb + padding;
  const double scale = ca.norm() + cb.norm() + reach;
  const double limit = reach + margins::narrowBand(tol.gjk_absolute) * scale;
  return (ca - cb).squaredNorm() > limit * limit;
}

}  // namespace

// ---- Queries ------------------------------------------------------------------------------------------

namespace {
double partsBound(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                  const Tolerances& tol, double enough, double relative, SimplexCache* caches) noexcept;
}  // namespace

double partsLowerBound(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                       const Tolerances& tol, double enough, double relative, SimplexCache* caches) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite() || !(enough >= 0.0)) return 0.0;  // (a NaN `enough` too)
  const double d = partsBound(a, pose_a, b, pose_b, tol, enough, relative, caches);
  // The parts cover the surfaces, not a closed mesh's inside: a piece in there is 0 away.
  if (d > 0.0 && (a.solidCount() > 0 || b.solidCount() > 0) && linkContained(a, b, relativePose(pose_a, pose_b)))
    return 0.0;
  return d;
}

namespace {
// Each part pair certified at least needOf(j) apart (j: b's part), from `first` on, which is set to the pair
// that was too near when false; then neither link inside the other's closed meshes.
template <class NeedOf>
bool partsClear(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                const Tolerances& tol, const NeedOf& needOf, int* first) noexcept {
  const int na = static_cast<int>(a.parts().size()), nb = static_cast<int>(b.parts().size());
  if (!pose_a.isFinite() || !pose_b.isFinite() || na == 0 || nb == 0) return false;
  for (int j = 0; j < nb; ++j)
    if (!(needOf(j) >= 0.0) || !std::isfinite(needOf(j))) return false;
  const int start = first && *first >= 0 && *first < na * nb ? *first : 0;
  for (int k = 0; k < na * nb; ++k) {
    const int at = (start + k) % (na * nb), i = at / nb, j = at % nb;
    const LinkGeometry::Part& pa = a.parts()[i];
    const LinkGeometry::Part& pb = b.parts()[j];
    const double need = needOf(j);
    if ((pose_a * pa.center - pose_b * pb.center).norm() - pa.radius - pb.radius >= need) continue;
    SimplexCache cache;  // (only "at least need" is asked: GJK stops there)
    if (!(gjkLowerBound(pa.hull, pose_a, pb.hull, pose_b, tol, cache, need, 0.0) >= need)) {
      if (first) *first = at;
      return false;
    }
  }
  // The parts hold the surfaces, not a closed mesh's inside.
  return (a.solidCount() == 0 && b.solidCount() == 0) || !linkContained(a, b, relativePose(pose_a, pose_b));
}
}  // namespace

bool partsApart(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                const Tolerances& tol, const double* need_b, int* first) noexcept {
  return partsClear(
      a, pose_a, b, pose_b, tol, [need_b](int j) { return need_b[j]; }, first);
}

namespace {
double partsBound(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                  const Tolerances& tol, double enough, double relative, SimplexCache* caches) noexcept {
  double best = enough;  // any bound at or above `enough` serves as well as the distance
  const int na = static_cast<int>(a.parts().size()), nb = static_cast<int>(b.parts().size());
  const auto gjk = [&](int i, int j, double balls) {
    SimplexCache scratch;
    SimplexCache& cache = caches ? caches[i * nb + j] : scratch;
    best = std::min(best, std::max(balls, gjkLowerBound(a.parts()[i].hull, pose_a, b.parts()[j].hull, pose_b, tol,
                                                        cache, best, relative)));
  };
  const auto balls = [&](int i, int j) {
    return (pose_a * a.parts()[i].center - pose_b * b.parts()[j].center).norm() - a.parts()[i].radius -
           b.parts()[j].radius;
  };
  constexpr int kPairs = LinkGeometry::kMaxParts * LinkGeometry::kMaxParts;
  if (na * nb > kPairs) {  // (links with many primitives, which add a part each: every pair in turn)
    for (int i = 0; i < na; ++i) {
      for (int j = 0; j < nb; ++j) {
        const double x = balls(i, j);
        if (x >= best) continue;
        gjk(i, j, x);
        if (!(best > 0.0)) return 0.0;
      }
    }
    return best;
  }
  // Nearest balls first: the first pair's distance is then usually the answer, and each later pair
  // stops its GJK as soon as it is proved farther, or is never started once the balls are.
  std::array<std::pair<double, int>, kPairs> near;
  int count = 0;
  for (int i = 0; i < na; ++i) {
    for (int j = 0; j < nb; ++j) {
      const double x = balls(i, j);
      // (A NaN, which finite poses do not give, would break the sort: it goes first and GJK decides.)
      if (!(x >= best)) near[count++] = {std::isnan(x) ? -std::numeric_limits<double>::infinity() : x, i * nb + j};
    }
  }
  std::sort(near.begin(), near.begin() + count, [](const auto& x, const auto& y) { return x.first < y.first; });
  for (int k = 0; k < count && near[k].first < best; ++k) {
    gjk(near[k].second / nb, near[k].second % nb, near[k].first);
    if (!(best > 0.0)) return 0.0;
  }
  return best;
}

// True when a core of one link meets a primitive of the other (b_in_a: b's pose in a's frame, finite).
bool coreInPrimitive(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a) noexcept {
  if (!b.cores().empty() && !a.primitives().empty()) {
    const Pose a_in_b = b_in_a.inverse();
    for (const LinkGeometry::Primitive& p : a.primitives())
      if (coreMeetsShape(p.shape, a_in_b * p.pose, b)) return true;
  }
  if (!a.cores().empty())
    for (const LinkGeometry::Primitive& p : b.primitives())
      if (coreMeetsShape(p.shape, b_in_a * p.pose, a)) return true;
  return false;
}

// Past this many triangles in either link, a pair the cheaper rungs leave is screened by its convex parts
// before the triangle search. The search's cost grows with the triangles near the contact; the parts' is
// a few GJK calls. Measured on the shared robots' uniform states: the Panda (200–300 triangles a link)
// loses 5% on self-colliding states when screened so (its searches are cheap, its colliding pairs pay the
// parts for nothing); the UR5 (450–1,200 a link, and tens of thousands in its gripper) gains 12% on free
// states and 4–5% on self-colliding ones.
constexpr std::size_t kPartsScreenTriangles = 512;

// The convex parts' rung: every part pair more than padding apart (beyond the band), stopping at the first
// pair too near (`first`, when given, is tried first and set to it).
// (`apart`: |b's origin − a's|, b_in_a.t's norm, which a caller that has b_in_a passes rather than have it
// computed again.)
bool partsScreen(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                 const Tolerances& tol, double padding, double apart, int* first) noexcept {
  if (a.parts().size() <= 1 && b.parts().size() <= 1) return false;  // (one part is the hull: no tighter)
  if (std::max(a.triangles().size(), b.triangles().size()) <= kPartsScreenTriangles) return false;
  const double scale = a.boundingRadius() + b.boundingRadius() + apart;
  const double need = (padding + narrowBand(scale + padding, tol)) * margins::kBeyond;
  return partsClear(
      a, pose_a, b, pose_b, tol, [need](int) { return need; }, first);
}

// Two primitives placed in their links (b's link placed in a's frame by b_in_a): whether they lie within
// `padding`, as exactIntersect tests them. (Out of line, as primitivesBound: the rungs that links of meshes
// climb, which never come here, stay as compact as they were.)
[[gnu::noinline]] bool primitivesIntersect(const LinkGeometry::Primitive& a, const LinkGeometry::Primitive& b,
                                           const Pose& b_in_a, const Tolerances& tol, double padding) noexcept {
  return shapesIntersect(a.shape, a.pose, b.shape, b_in_a * b.pose, tol, padding);
}

// screenMeshes' cheap rungs, a few operations each: bounding spheres, the boxes of the hulls as oriented
// boxes (6 face axes), the cores. Unsure where the hulls must decide; then `placed`, when given, holds b's
// pose in a's frame for dearRungs.
Screen cheapRungs(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                  const Tolerances& tol, double padding, Pose* placed = nullptr) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite() || !validPadding(padding)) return Screen::Touching;
  if (spheresApart(pose_a * a.sphereCenter(), a.sphereRadius(), pose_b * b.sphereCenter(), b.sphereRadius(), padding,
                   tol))
    return Screen::Apart;
  const Pose b_in_a = relativePose(pose_a, pose_b);
  if (placed) *placed = b_in_a;
  if (boxesApart(a, b, b_in_a, tol, padding)) return Screen::Apart;
  // Overlapping cores settle a contact (in any mode: the cores lie in the hulls) before the hulls' GJK, which
  // costs most exactly there, enclosing the origin (about 5,000 instructions for a UR5 arm link dipping
  // into another), and before the triangle search; so does a core of one link inside a primitive of the
  // other (a solid, whose own distance is exact). A pair they leave pays about 1,100 more.
  if (coresOverlap(a, b, b_in_a) || coreInPrimitive(a, b, b_in_a)) return Screen::Touching;
  return Screen::Unsure;
}

// The rungs after cheapRungs (for a pair it left Unsure): the primitives' or the hulls' GJK, then the convex
// parts when `parts`. `placed`: b's pose in a's frame where cheapRungs gave it (else computed if needed).
Screen dearRungs(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                 const Tolerances& tol, GeometryMode mode, double padding, SimplexCache* hull_cache, bool parts,
                 const Pose* placed = nullptr) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite() || !validPadding(padding)) return Screen::Touching;
  const auto bInA = [&] { return placed ? *placed : relativePose(pose_a, pose_b); };
  // Two links of one primitive each are those primitives (convex solids): their own GJK decides, as the
  // exact test would, where the hulls' (circumscribed polytopes: 82 vertices for a capsule) only screens.
  const LinkGeometry::Primitive* sole_a = mode == GeometryMode::Mesh ? a.solePrimitive() : nullptr;
  const LinkGeometry::Primitive* sole_b = sole_a ? b.solePrimitive() : nullptr;
  if (sole_b) return primitivesIntersect(*sole_a, *sole_b, bInA(), tol, padding) ? Screen::Touching : Screen::Apart;
  SimplexCache scratch;
  SimplexCache& cache = hull_cache ? *hull_cache : scratch;
  const IntersectResult hulls = gjkIntersect(Margin<ConvexHull>{a.hull(), padding}, pose_a, b.hull(), pose_b, tol, cache);
  if (!hulls.intersecting) return Screen::Apart;
  if (mode == GeometryMode::Hull) return Screen::Touching;
  // A pair the parts clear skips the triangle search, which costs tens of thousands of operations near a
  // mesh of a thousand triangles.
  if (parts && partsScreen(a, pose_a, b, pose_b, tol, padding, bInA().t.norm(), nullptr)) return Screen::Apart;
  return Screen::Unsure;
}

// screenMeshes, the convex parts' rung only when `parts`: cheapRungs, then dearRungs.
Screen screenRungs(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                   const Tolerances& tol, GeometryMode mode, double padding, SimplexCache* hull_cache,
                   bool parts) noexcept {
  Pose b_in_a;
  const Screen cheap = cheapRungs(a, pose_a, b, pose_b, tol, padding, &b_in_a);
  return cheap != Screen::Unsure ? cheap
                                 : dearRungs(a, pose_a, b, pose_b, tol, mode, padding, hull_cache, parts, &b_in_a);
}
}  // namespace

Screen screenMeshes(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                    const Tolerances& tol, GeometryMode mode, double padding, SimplexCache* hull_cache) noexcept {
  return screenRungs(a, pose_a, b, pose_b, tol, mode, padding, hull_cache, true);
}

bool meshesIntersectExactly(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                            const Tolerances& tol, double padding) noexcept {
  return meshesIntersectExactly(a, pose_a, b, pose_b, tol, padding, nullptr);
}

bool meshesIntersectExactly(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                            const Tolerances& tol, double padding, TrianglePair* witness) noexcept {
  if (witness) *witness = {};
  if (!pose_a.isFinite() || !pose_b.isFinite() || !validPadding(padding)) return true;
  const Pose b_in_a = relativePose(pose_a, pose_b);
  const double scale = a.boundingRadius() + b.boundingRadius() + b_in_a.t.norm();
  const double slack = padding + narrowBand(scale + padding, tol);
  return exactIntersect(a, b, b_in_a, tol, padding, slack, witness) || linkContained(a, b, b_in_a);
}

bool trianglesTouch(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                    TrianglePair w, const Tolerances& tol, double padding) noexcept {
  if (!w.valid() || w.a >= static_cast<std::int32_t>(a.triangles().size()) ||
      w.b >= static_cast<std::int32_t>(b.triangles().size()) || !validPadding(padding))
    return false;
  const Pose b_in_a = relativePose(pose_a, pose_b);
  const double scale = a.boundingRadius() + b.boundingRadius() + b_in_a.t.norm();
  const double slack = padding + narrowBand(scale + padding, tol);
  // (Non-finite poses fail the box test inside: false, which proves nothing.)
  return b_in_a.isFinite() && trianglePairIntersects(a.triangles()[w.a], b.triangles()[w.b], b_in_a, tol, padding, slack);
}

bool meshesIntersect(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                     const Tolerances& tol, GeometryMode mode, double padding, SimplexCache* hull_cache) noexcept {
  const Screen s = screenMeshes(a, pose_a, b, pose_b, tol, mode, padding, hull_cache);
  if (s != Screen::Unsure) return s == Screen::Touching;
  return meshesIntersectExactly(a, pose_a, b, pose_b, tol, padding);
}

bool shapeIntersectsLink(const Shape& shape, const Pose& pose_shape, const LinkGeometry& link, const Pose& pose_link,
                         const Tolerances& tol, GeometryMode mode, double padding, SimplexCache* hull_cache) noexcept {
  if (!pose_shape.isFinite() || !pose_link.isFinite() || !validPadding(padding)) return true;
  if (spheresApart(pose_shape.t, boundingRadius(shape), pose_link * link.sphereCenter(), link.sphereRadius(), padding,
                   tol))
    return false;
  // The shape's own box against the link's box, both oriented (15 axes): obstacles are mostly boxes, often
  // turned, so this clears most of what their world boxes let through, at a third of a GJK call.
  const Pose shape_in_link = relativePose(pose_link, pose_shape);
  const double scale = link.boundingRadius() + shape_in_link.t.norm() + boundingRadius(shape);
  const double slack = padding + narrowBand(scale + padding, tol);
  if (detail::OrientedBoxTest(shape_in_link, slack, scale).separated<true>(link.bounds(), localBox(shape))) return false;
  // A core (inside the link, so inside its hull) that meets the shape settles a contact in either mode, for
  // a few point distances where the hulls' GJK and the triangles cost far more: a link in an obstacle.
  if (coreMeetsShape(shape, shape_in_link, link)) return true;
  SimplexCache scratch;
  SimplexCache& cache = hull_cache ? *hull_cache : scratch;
  const bool hulls = std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        return gjkIntersect(Margin<S>{s, padding}, pose_shape, link.hull(), pose_link, tol, cache).intersecting;
      },
      shape);
  if (!hulls) return false;
  if (mode == GeometryMode::Hull) return true;
  if (shapeIntersectsTriangles(shape, shape_in_link, link, tol, padding, slack)) return true;
  for (const auto& p : link.primitives())
    if (shapesIntersect(shape, shape_in_link, p.shape, p.pose, tol, padding)) return true;
  return shapeInsideLink(shape, shape_in_link, link);
}

namespace {

// The running minimum of a distance query, in A's frame.
struct DistanceMin {
  DistanceResult best;
  // Pairs certainly farther than this are skipped: the caller's limit, then best.distance / (1 + relative_error).
  double cutoff = std::numeric_limits<double>::infinity();
  double shrink = 1.0;
  bool failed = false;

  explicit DistanceMin(double relative_error, double limit = std::numeric_limits<double>::infinity())
      : cutoff(limit), shrink(1.0 / (1.0 + relative_error)) {
    best.distance = limit;
    best.lower_bound = limit;
    best.status = Status::Separated;
  }
  // The result in the world, given the frame the search ran in: a failure carries no certificate, and
  // pairs skipped were at least the final cutoff apart (with a relative error, below the distance).
  DistanceResult finish(const Pose& frame) const {
    DistanceResult r = best;
    if (failed) {
      r.status = Status::NotConverged;
      r.distance = 0.0;
      r.lower_bound = 0.0;
      return r;
    }
    r.lower_bound = std::min({r.lower_bound, r.distance, cutoff});
    r.point_a = frame * r.point_a;
    r.point_b = frame * r.point_b;
    r.normal = frame.R * r.normal;
    return r;
  }
  // One body lies inside the other's closed mesh: they overlap (no witness points on the surfaces).
  void inside() {
    best.distance = best.lower_bound = 0.0;
    best.status = Status::Overlapping;
    best.normal = Vec3::Zero();
    cutoff = 0.0;
  }
  // Returns true when the search can stop (an overlap, or a failure).
  bool add(const DistanceResult& r) {
    best.iterations += r.iterations;
    if (isFailure(r.status)) {
      failed = true;
      return true;
    }
    best.lower_bound = std::min(best.lower_bound, r.lower_bound);
    if (r.distance < best.distance) {
      const int iterations = best.iterations;
      const double lower = best.lower_bound;
      best = r;
      best.iterations = iterations;
      best.lower_bound = lower;
      cutoff = r.distance * shrink;
    }
    return best.distance <= 0.0;
  }
};

// How far apart two triangles are along the unit axis u (from a's side towards b's): their projections'
// gap, a lower bound on their distance (negative when the projections overlap).
double projectedGap(const Vec3 a[3], const Vec3 b[3], const Vec3& u) noexcept {
  const double a0 = u.dot(a[0]), a1 = u.dot(a[1]), a2 = u.dot(a[2]);
  const double b0 = u.dot(b[0]), b1 = u.dot(b[1]), b2 = u.dot(b[2]);
  return std::max(std::min({b0, b1, b2}) - std::max({a0, a1, a2}), std::min({a0, a1, a2}) - std::max({b0, b1, b2}));
}

// A lower bound on the distance between the triangles below node ia of A's tree and node ib of B's, at
// least `gap` (their boxes'): where one is a leaf, the least distance from its triangles' planes to the
// other's box. A large triangle's box, askew, holds many boxes of a fine mesh that its plane keeps away.
// `slack` covers the rounding of a plane's gap (as of meshDistance's projected gaps).
double leafPlanesGap(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a, double slack, std::int32_t ia,
                     std::int32_t ib, double gap) noexcept {
  const AabbTree::Node& x = a.tree().nodes()[ia];
  const AabbTree::Node& y = b.tree().nodes()[ib];
  // The least distance from the planes of a leaf's triangles (placed in A's frame by to_a) to a box of
  // centre c and half widths h along the columns of `axes` (A's frame); it stops once at most `gap`, and
  // a degenerate triangle gives no bound.
  const auto planes = [&](const AabbTree::Node& leaf, const LinkGeometry& g, const Pose& to_a, const Vec3& c,
                          const Vec3& h, const Mat3& axes) {
    double least = std::numeric_limits<double>::infinity();
    for (std::int32_t s = leaf.first; s < leaf.first + leaf.count && least > gap; ++s) {
      const Triangle& t = g.triangles()[g.tree().items()[s]];
      const Vec3 n = to_a.R * (t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]);
      const double len = n.norm();
      if (!(len > 0.0) || !std::isfinite(len)) return gap;
      const Vec3 u = n / len;
      least = std::min(least, std::abs(u.dot(c - to_a * t.v[0])) - (axes.transpose() * u).cwiseAbs().dot(h) - slack);
    }
    return std::max(gap, least);
  };
  if (x.isLeaf())  // B's box placed in A
    gap = planes(x, a, Pose::identity(), b_in_a * (0.5 * (y.box.min + y.box.max)), 0.5 * (y.box.max - y.box.min),
                 b_in_a.R);
  if (y.isLeaf())
    gap = planes(y, b, b_in_a, 0.5 * (x.box.min + x.box.max), 0.5 * (x.box.max - x.box.min), Mat3::Identity());
  return gap;
}

template <class S>
void shapeTrianglesDistance(const S& s, const Pose& shape_in_link, const LinkGeometry& link, const Tolerances& tol,
                            DistanceMin& m, bool shape_is_a, const Pose& link_in_a) {
  if (link.triangles().empty()) return;
  const std::vector<Triangle>& tris = link.triangles();
  // The tree is in the link's frame; the results go to A's frame (identity when the shape is B's). The
  // shape's own box, turned, prunes far more than its bounds in the link frame (a slab seen askew).
  link.tree().forEachWithin(placedBox(s, Pose::identity()), shape_in_link, m.cutoff, [&](std::int32_t i) {
    DistanceResult r = shape_is_a ? gjkDistance(s, shape_in_link, tris[i], Pose::identity(), tol)
                                  : gjkDistance(tris[i], Pose::identity(), s, shape_in_link, tol);
    r.point_a = link_in_a * r.point_a;
    r.point_b = link_in_a * r.point_b;
    r.normal = link_in_a.R * r.normal;
    return m.add(r);
  });
}

}  // namespace

DistanceResult meshDistance(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                            const Tolerances& tol, double relative_error, double cutoff) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite() || !(relative_error >= 0.0) || !std::isfinite(relative_error) ||
      !(cutoff >= 0.0)) {
    DistanceResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  const Pose b_in_a = relativePose(pose_a, pose_b);
  DistanceMin m(relative_error, cutoff);
  const std::vector<Triangle>& ta = a.triangles();
  const std::vector<Triangle>& tb = b.triangles();
  bool stop = false;
  if (!ta.empty() && !tb.empty()) {
    // Box gaps are loose for distance (a triangle's box, turned, reaches far beyond it), so a triangle
    // pair passing them is first projected on four axes, each gap a lower bound on its distance: the
    // line through the centroids (tight for small triangles far apart), the normal of the best pair
    // so far (tight for surfaces facing each other) and each triangle's own normal (tight for a corner
    // over a face: fine meshes near a surface). GJK runs only when none reaches the cutoff.
    const double rounding = margins::kRounding * (a.boundingRadius() + b.boundingRadius() + b_in_a.t.norm());
    const auto planes = [&](std::int32_t ia, std::int32_t ib, double gap) {
      return leafPlanesGap(a, b, b_in_a, rounding, ia, ib, gap);
    };
    stop = forEachPairWithinBy(a.tree(), b.tree(), b_in_a, m.cutoff, planes, [&](std::int32_t i, std::int32_t j) {
      if (m.cutoff < std::numeric_limits<double>::infinity()) {
        const Vec3* va = ta[i].v;
        const Vec3 vb[3] = {b_in_a * tb[j].v[0], b_in_a * tb[j].v[1], b_in_a * tb[j].v[2]};
        const Vec3 u = (vb[0] + vb[1] + vb[2]) - (va[0] + va[1] + va[2]);
        const double len = u.norm();
        if (len > 0.0 && projectedGap(va, vb, u / len) - rounding >= m.cutoff) return false;
        if (projectedGap(va, vb, m.best.normal) - rounding >= m.cutoff) return false;
        for (const Vec3& n : {(va[1] - va[0]).cross(va[2] - va[0]), (vb[1] - vb[0]).cross(vb[2] - vb[0])}) {
          const double nn = n.norm();
          if (nn > 0.0 && projectedGap(va, vb, n / nn) - rounding >= m.cutoff) return false;
        }
      }
      return m.add(gjkDistance(ta[i], Pose::identity(), tb[j], b_in_a, tol));
    });
  }
  if (!stop && (!a.primitives().empty() || !b.primitives().empty())) {
    const Pose a_in_b = b_in_a.inverse();
    for (const auto& p : a.primitives())
      std::visit([&](const auto& s) { shapeTrianglesDistance(s, a_in_b * p.pose, b, tol, m, true, b_in_a); }, p.shape);
    for (const auto& p : b.primitives())
      std::visit([&](const auto& s) { shapeTrianglesDistance(s, b_in_a * p.pose, a, tol, m, false, Pose::identity()); },
                 p.shape);
    for (const auto& p : a.primitives())
      for (const auto& q : b.primitives())
        if (!m.failed) m.add(gjkDistance(p.shape, p.pose, q.shape, b_in_a * q.pose, tol));
  }
  if (!m.failed && m.best.distance > 0.0 && (a.solidCount() > 0 || b.solidCount() > 0) && linkContained(a, b, b_in_a))
    m.inside();
  return m.finish(pose_a);
}

DistanceResult shapeLinkDistance(const Shape& shape, const Pose& pose_shape, const LinkGeometry& link,
                                 const Pose& pose_link, const Tolerances& tol, double relative_error) noexcept {
  if (!pose_shape.isFinite() || !pose_link.isFinite() || !(relative_error >= 0.0) || !std::isfinite(relative_error)) {
    DistanceResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  // In the link's frame: its tree needs no transform, and the shape is A (its results need none either).
  const Pose shape_in_link = relativePose(pose_link, pose_shape);
  DistanceMin m(relative_error);
  std::visit([&](const auto& s) { shapeTrianglesDistance(s, shape_in_link, link, tol, m, true, Pose::identity()); },
             shape);
  for (const auto& p : link.primitives())
    if (!m.failed && !(m.best.distance <= 0.0)) m.add(gjkDistance(shape, shape_in_link, p.shape, p.pose, tol));
  if (!m.failed && m.best.distance > 0.0 && shapeInsideLink(shape, shape_in_link, link)) m.inside();
  return m.finish(pose_link);
}

// ---- BodyPair ------------------------------------------------------------------------------------------

namespace {

// gjkLowerBound of two primitives placed in their links (placed by pose_a and pose_b).
[[gnu::noinline]] double primitivesBound(const LinkGeometry::Primitive& a, const Pose& pose_a,
                                         const LinkGeometry::Primitive& b, const Pose& pose_b, const Tolerances& tol,
                                         SimplexCache& cache, double enough, double relative) noexcept {
  return gjkLowerBound(a.shape, pose_a * a.pose, b.shape, pose_b * b.pose, tol, cache, enough, relative);
}

// A lower bound on the distance from the link's bounding ball (placed by pose_a) to the convex shape: the
// ball against the shape's own ball and against its box (in its frame), a dozen operations where GJK costs
// hundreds. The ball is grown by the rounding of placing its centre, both gaps shrunk by that of measuring them.
double ballShapeGap(const LinkGeometry& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) noexcept {
  // (A hull's ball and box cost a pass over its vertices: GJK, warm, costs less.)
  if (std::holds_alternative<ConvexHull>(b)) return -std::numeric_limits<double>::infinity();
  const Vec3 centre = pose_a * a.sphereCenter();
  const double reach =
      a.sphereRadius() * (1.0 + margins::kRounding) + margins::placedRounding(a.sphereCenter().norm(), pose_a.t.norm());
  const Vec3 c = pose_b.R.transpose() * (centre - pose_b.t);
  // (The margin is far above the few roundings of either distance.)
  const double margin =
      margins::kSlack * (1.0 + c.cwiseAbs().maxCoeff() + pose_b.t.cwiseAbs().maxCoeff() + centre.cwiseAbs().maxCoeff());
  const double balls = (centre - pose_b.t).norm() - reach - boundingRadius(b) * (1.0 + margins::kRounding) - margin;
  const Aabb box = localBox(b);
  const Vec3 gap = (box.min - c).cwiseMax(c - box.max).cwiseMax(0.0);
  const double boxed = gap.norm() - reach - margin;
  // (A norm that overflowed is no bound: only finite gaps count; a NaN gives way to the other.)
  const double x = std::isfinite(boxed) ? boxed : -std::numeric_limits<double>::infinity();
  const double y = std::isfinite(balls) ? balls : -std::numeric_limits<double>::infinity();
  return std::max(x, y);
}

// The least bound over the link's convex parts against the shape (cold starts: asked only once the hull has
// come near), each GJK stopping once it proves `enough`; 0 when the shape lies inside a closed mesh of the
// link, which the parts (covering the surfaces) do not hold.
double partsShapeBound(const LinkGeometry& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                       const Tolerances& tol, double enough, double relative) noexcept {
  double best = enough;
  const double rb = boundingRadius(b);
  for (const LinkGeometry::Part& part : a.parts()) {
    const Vec3 centre = pose_a * part.center;  // (the margin is far above the rounding of the gap)
    const double margin = margins::kSlack * (1.0 + centre.cwiseAbs().maxCoeff() + pose_b.t.cwiseAbs().maxCoeff());
    if ((centre - pose_b.t).norm() - part.radius - rb - margin >= best) continue;
    SimplexCache cold;
    best = std::min(best, std::visit([&](const auto& s) { return gjkLowerBound(part.hull, pose_a, s, pose_b, tol, cold, best, relative); }, b));
    if (!(best > 0.0)) return 0.0;
  }
  // (The shape's support point is a point of it.)
  if (a.solidCount() > 0) {
    const Vec3 p = std::visit([](const auto& s) { return s.support(Vec3::UnitX()); }, b);
    if (a.containsPoint(relativePose(pose_a, pose_b) * p)) return 0.0;
  }
  return best;
}

// A distance with A and B exchanged.
DistanceResult swapped(DistanceResult r) noexcept {
  std::swap(r.point_a, r.point_b);
  r.normal = -r.normal;
  return r;
}

}  // namespace

void BodyPair::forget() noexcept {
  hullCache() = SimplexCache{};
  sole_ = SimplexCache{};
  parts_first_ = -1;
  parts_stale_ = true;
}

Screen BodyPair::screen(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept {
  const Screen cheap = screenCheap(pose_a, pose_b, tol, q);
  return cheap != Screen::Unsure ? cheap : screenDear(pose_a, pose_b, tol, q);
}

Screen BodyPair::screenCheap(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                             const IntersectQuery& q) noexcept {
  if (shape_) return Screen::Unsure;  // (a shape's rungs are shapeIntersectsLink's: screenDear's)
  return cheapRungs(*a_, pose_a, *b_, pose_b, tol, q.padding);
}

Screen BodyPair::screenDear(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                            const IntersectQuery& q) noexcept {
  if (shape_) {  // (one convex piece: the hull-mode test screens, the exact one decides)
    if (!shapeIntersectsLink(*shape_, pose_b, *a_, pose_a, tol, GeometryMode::Hull, q.padding, &hullCache()))
      return Screen::Apart;
    return q.mode == GeometryMode::Hull ? Screen::Touching : Screen::Unsure;
  }
  return dearRungs(*a_, pose_a, *b_, pose_b, tol, q.mode, q.padding, &hullCache(), false);
}

bool BodyPair::intersectsExactly(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                                 double padding) noexcept {
  if (shape_) return shapeIntersectsLink(*shape_, pose_b, *a_, pose_a, tol, GeometryMode::Mesh, padding);
  if (pose_a.isFinite() && pose_b.isFinite() && validPadding(padding) &&
      partsScreen(*a_, pose_a, *b_, pose_b, tol, padding, relativePose(pose_a, pose_b).t.norm(), &parts_first_))
    return false;
  return meshesIntersectExactly(*a_, pose_a, *b_, pose_b, tol, padding);
}

double BodyPair::convexBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double enough,
                             double relative, double climb, GeometryMode mode, bool primitives) noexcept {
  const LinkGeometry& a = *a_;
  // (In every max() below the bound so far comes second: a NaN rung leaves it, and a NaN first bound
  // gives way to the rung's number.) A dearer rung only while the bound is at most climb and short of enough.
  const auto climbs = [&](double lower) { return lower <= climb && !(lower >= enough); };
  rung_ = Rung::Balls;
  double lower = shape_ ? ballShapeGap(a, pose_a, *shape_, pose_b)
                        : (pose_a * a.sphereCenter() - pose_b * b_->sphereCenter()).norm() - a.sphereRadius() -
                              b_->sphereRadius();
  // Two links of one primitive each, in Mesh mode: the primitives' own bound is the exact rung (nothing
  // dearer is left to climb to), a few iterations of analytic supports where the hulls' would search
  // polytopes of up to 82 vertices and stay short of the true distance by their facets.
  const LinkGeometry::Primitive* sole_a =
      primitives && mode == GeometryMode::Mesh && !shape_ ? a.solePrimitive() : nullptr;
  const LinkGeometry::Primitive* sole_b = sole_a ? b_->solePrimitive() : nullptr;
  if (sole_b && !(lower >= enough)) {
    rung_ = Rung::Exact;
    SimplexCache cold;  // (a pair whose hull warm start the caller keeps keeps none of its own)
    lower =
        std::max(primitivesBound(*sole_a, pose_a, *sole_b, pose_b, tol, warm_ ? cold : sole_, enough, relative), lower);
    return lower >= 0.0 ? lower : 0.0;
  }
  if (!(lower >= enough)) {
    rung_ = Rung::Hulls;
    SimplexCache& cache = hullCache();
    const double hulls =
        shape_ ? std::visit([&](const auto& s) { return gjkLowerBound(a.hull(), pose_a, s, pose_b, tol, cache, enough, relative); }, *shape_)
               : gjkLowerBound(a.hull(), pose_a, b_->hull(), pose_b, tol, cache, enough, relative);
    lower = std::max(hulls, lower);
  }
  if (!climbs(lower) || mode == GeometryMode::Hull) return lower >= 0.0 ? lower : 0.0;
  rung_ = Rung::Parts;
  if (shape_) return std::max(partsShapeBound(a, pose_a, *shape_, pose_b, tol, enough, relative), lower);
  SimplexCache* caches = nullptr;  // (a pair whose hull warm start the caller keeps starts its parts cold)
  if (!warm_) {
    if (parts_stale_ || parts_.empty()) {  // (allocated when first needed: most pairs never get this far)
      parts_.assign(a.parts().size() * b_->parts().size(), SimplexCache{});
      parts_stale_ = false;
    }
    caches = parts_.data();
  }
  return std::max(partsLowerBound(a, pose_a, *b_, pose_b, tol, enough, relative, caches), lower);
}

double BodyPair::lowerBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                            const BoundQuery& q) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite()) return 0.0;
  const double climb = q.climb >= 0.0 ? q.climb : q.enough;
  const GeometryMode mode = q.top <= Rung::Hulls ? GeometryMode::Hull : q.mode;
  const double lower = convexBound(pose_a, pose_b, tol, q.enough, q.relative, climb, mode, q.top >= Rung::Exact);
  // Two links of one primitive each, which convexBound measured: `within` decided as the exact rung decides it.
  if (rung_ == Rung::Exact) {
    if (!(q.within >= 0.0) || lower > q.within) return lower;
    return primitivesIntersect(*a_->solePrimitive(), *b_->solePrimitive(), relativePose(pose_a, pose_b), tol, q.within)
               ? 0.0
               : std::max(lower, q.within * margins::kBeyond);
  }
  if (rung_ != Rung::Parts || !(lower <= climb) || !(lower < q.enough) || q.top < Rung::Exact) return lower;
  rung_ = Rung::Exact;
  const LinkGeometry& a = *a_;
  // The convex pieces are near, so the triangles are (and a fine mesh has many near): whether they lie
  // within `within` is a search that stops at the first pair; only if not, how far they are.
  if (q.within >= 0.0 && intersectsExactly(pose_a, pose_b, tol, q.within)) return 0.0;
  const DistanceResult m = shape_ ? shapeLinkDistance(*shape_, pose_b, a, pose_a, tol, q.relative)
                                  : meshDistance(a, pose_a, *b_, pose_b, tol, q.relative, std::min(q.enough, q.near));
  if (isFailure(m.status)) return 0.0;
  return q.within >= 0.0 ? std::max(m.lower_bound, q.within * margins::kBeyond) : m.lower_bound;
}

double BodyPair::penetration(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                              double padding) const noexcept {
  if (!(padding >= 0.0) || !std::isfinite(padding)) return std::numeric_limits<double>::quiet_NaN();
  const PenetrationResult r =
      shape_ ? std::visit([&](const auto& s) { return epaPenetration(a_->hull(), pose_a, s, pose_b, tol); }, *shape_)
             : epaPenetration(a_->hull(), pose_a, b_->hull(), pose_b, tol);
  if (isFailure(r.status)) return std::numeric_limits<double>::quiet_NaN();
  return std::max(0.0, padding - r.signed_distance);  // padded bodies may overlap with their hulls apart
}

CastResult BodyPair::cast(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                          const CastQuery& q) const noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite() || !q.velocity.allFinite() || !(q.margin >= 0.0) ||
      !std::isfinite(q.margin) || !(q.max_s >= 0.0) || !std::isfinite(q.max_s))
    return CastResult{};  // (hit at 0)
  const Margin<ConvexHull> grown{a_->hull(), q.margin};
  if (!shape_) return gjkShapeCast(grown, pose_a, q.velocity, b_->hull(), pose_b, q.max_s, tol);
  return std::visit([&](const auto& s) { return gjkShapeCast(grown, pose_a, q.velocity, s, pose_b, q.max_s, tol); },
                    *shape_);
}

DistanceResult BodyPair::distance(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                                  const DistanceQuery& q) noexcept {
  // A finite cutoff lets the convex rungs answer first: bodies they prove at least the cutoff apart get
  // what meshDistance gives when no element pair is nearer (cutoff, points at A's origin), no triangle
  // touched. meshDistance's distance is at least any certified lower bound, so nothing else changes.
  const auto atCutoff = [&] {
    DistanceResult r;
    r.distance = r.lower_bound = q.cutoff;
    r.point_a = r.point_b = pose_a.t;
    r.status = Status::Separated;
    return r;
  };
  if (q.mode == GeometryMode::Hull) {
    rung_ = Rung::Hulls;
    const DistanceResult r =
        shape_ ? std::visit([&](const auto& s) { return gjkDistance(a_->hull(), pose_a, s, pose_b, tol); }, *shape_)
               : gjkDistance(a_->hull(), pose_a, b_->hull(), pose_b, tol);
    return !isFailure(r.status) && r.distance > q.cutoff ? atCutoff() : r;
  }
  if (q.cutoff < std::numeric_limits<double>::infinity() && q.cutoff > 0.0 && q.relative >= 0.0 &&
      std::isfinite(q.relative) && pose_a.isFinite() && pose_b.isFinite() &&
      convexBound(pose_a, pose_b, tol, q.cutoff, 0.0, q.cutoff, GeometryMode::Mesh) >= q.cutoff)
    return atCutoff();
  rung_ = Rung::Exact;
  if (!shape_) return meshDistance(*a_, pose_a, *b_, pose_b, tol, q.relative, q.cutoff);
  const DistanceResult r = swapped(shapeLinkDistance(*shape_, pose_b, *a_, pose_a, tol, q.relative));
  // (As meshDistance's cutoff: nothing nearer than it, the cutoff.)
  return !isFailure(r.status) && q.cutoff >= 0.0 && r.distance > q.cutoff ? atCutoff() : r;
}

}  // namespace clearway
