// Quickhull: C. B. Barber, D. P. Dobkin, H. Huhdanpaa, "The Quickhull Algorithm for Convex Hulls",
// ACM Transactions on Mathematical Software 22(4), 1996. Each outside point sits in the conflict list
// of one face; the farthest point of a face is added by removing the faces it sees (found by walking
// face neighbours), walking the horizon, closing it with a cone of new faces and handing the removed
// faces' points to the new ones.
//
// Which side of a face plane a point lies on is decided *exactly*: a floating-point evaluation with a
// proven error bound, and expansion arithmetic when that bound cannot decide (J. R. Shewchuk,
// "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates", Discrete &
// Computational Geometry 18, 1997; shape/orientation.h). An epsilon test of visibility can call a
// face visible and its coplanar neighbour not, which makes a pinched horizon or a slightly reflex
// edge; exact signs make every intermediate mesh exactly the hull of the points added so far, so the
// horizon is always one simple cycle and the result is closed and convex by construction.
//
// The epsilon (kHullEpsilon) only ever leaves a point out, and only after measuring that it is within
// eps of the hull: during quickhull, a point within eps/2 of a hull triangle is not added; afterwards, a
// vertex within eps/2 of a segment or triangle of kept neighbouring corners is removed, as is any
// vertex lying exactly inside a flat face or on an edge, and the hull is rebuilt from the kept corners
// (exact, nothing left out). Near-coplanar noise thus adds no vertices, every vertex is a corner (which
// hill climbing in support() relies on), and the hull contains every input point up to eps.
#include <clearway/shape/convex_hull.h>

#include "shape/orientation.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#if defined(__FAST_MATH__)
#error "convex_hull.cpp needs IEEE arithmetic: the exact predicates break under -ffast-math"
#endif

namespace clearway {
namespace {

using orientation::collinear;
using orientation::FilteredSign;
using orientation::kUnitRoundoff;
using orientation::orient2dSign;
using orientation::orientFiltered;
using orientation::orientSign;

// Containment tolerance, relative to the largest |coordinate| M of the input: a point outside the hull
// by at most eps = kHullEpsilon · M may be left out of the vertices. The coordinates themselves carry
// a rounding of about 2^-53 · M from whatever produced them (mesh export, transforms), so a point
// outside by a few 2^-53 · M is not geometrically distinguishable from one on the hull; 2^-44 (≈ 5.7e-14,
// 512 roundings) keeps clear of that noise while staying eight orders of magnitude below any
// collision tolerance (Tolerances: 1e-6 relative), so the hull is conservative for every query.
// M rather than the hull's size: a hull far from its frame's origin has coordinates known only to
// 2^-53 · M.
constexpr double kHullEpsilon = 0x1p-44;
// Hulls with fewer vertices are scanned: a scan of a few dozen dot products beats hill climbing.
constexpr std::size_t kBruteForceBelow = 48;  // measured crossover: a 32-vertex scan 36 ns, the climb 56 ns

// ---- Distances (floating point; used only to certify that a dropped point is within eps) ----------

double segmentDistanceSquared(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp(ab.dot(p - a) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

double triangleDistanceSquared(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  // Projection inside the triangle: the distance is the distance to the plane; otherwise the closest
  // point is on an edge. Misjudging "inside" near an edge by rounding changes the value only by rounding.
  if (n2 > 0.0 && n.dot((b - a).cross(p - a)) >= 0.0 && n.dot((c - b).cross(p - b)) >= 0.0 &&
      n.dot((a - c).cross(p - c)) >= 0.0) {
    const double h = n.dot(p - a);
    return h * h / n2;
  }
  return std::min({segmentDistanceSquared(p, a, b), segmentDistanceSquared(p, b, c), segmentDistanceSquared(p, c, a)});
}

// ---- Dimension of the point set and a starting simplex ----------------------------------------------

enum class Dim { Point, Line, Plane, Solid };

struct Simplex {
  Dim dim = Dim::Point;
  std::array<int, 4> v{};  // the first 1, 2, 3 or 4 entries are meaningful
};

// Finds the affine dimension of points[ids] exactly, with a large simplex spanning it (the extreme pair
// along the widest axis, the point farthest from their line, the point farthest from that plane).
Simplex findSimplex(const std::vector<Vec3>& p, const std::vector<int>& ids) {
  Simplex s;
  std::array<int, 6> ext;
  ext.fill(ids[0]);
  for (const int i : ids) {
    for (int k = 0; k < 3; ++k) {
      if (p[i][k] > p[ext[2 * k]][k]) ext[2 * k] = i;
      if (p[i][k] < p[ext[2 * k + 1]][k]) ext[2 * k + 1] = i;
    }
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (p[ext[2 * k]][k] - p[ext[2 * k + 1]][k] > p[ext[2 * axis]][axis] - p[ext[2 * axis + 1]][axis]) axis = k;
  }
  s.v[0] = ext[2 * axis + 1];
  s.v[1] = ext[2 * axis];
  if (!(p[s.v[1]][axis] > p[s.v[0]][axis])) return s;  // widest extent is 0: all points coincide
  const Vec3& a = p[s.v[0]];
  const Vec3& b = p[s.v[1]];

  s.dim = Dim::Line;
  double best = -1.0;
  for (const int i : ids) {
    const double d2 = (p[i] - a).cross(b - a).squaredNorm();
    if (d2 > best) best = d2, s.v[2] = i;
  }
  if (collinear(a, b, p[s.v[2]])) {
    // Rounding (or underflow) hid the best candidate; an exact scan settles it.
    const auto it = std::find_if(ids.begin(), ids.end(), [&](int i) { return !collinear(a, b, p[i]); });
    if (it == ids.end()) return s;
    s.v[2] = *it;
  }
  const Vec3& c = p[s.v[2]];

  s.dim = Dim::Plane;
  best = -1.0;
  for (const int i : ids) {
    const double d = std::abs(orientFiltered(a, b, c, p[i]).vol);
    if (d > best) best = d, s.v[3] = i;
  }
  if (orientSign(a, b, c, p[s.v[3]]) == 0) {
    const auto it = std::find_if(ids.begin(), ids.end(), [&](int i) { return orientSign(a, b, c, p[i]) != 0; });
    if (it == ids.end()) return s;
    s.v[3] = *it;
  }
  s.dim = Dim::Solid;
  return s;
}

// The endpoints of collinear points: lexicographic order is the order along the line.
std::vector<int> segmentEnds(const std::vector<Vec3>& p, const std::vector<int>& ids) {
  const auto less = [&](int i, int j) {
    return std::lexicographical_compare(p[i].data(), p[i].data() + 3, p[j].data(), p[j].data() + 3);
  };
  return {*std::min_element(ids.begin(), ids.end(), less), *std::max_element(ids.begin(), ids.end(), less)};
}

// The corners of coplanar points (Andrew's monotone chain in the projection dropping the axis along
// which the plane's normal is nonzero; that projection preserves convexity exactly).
std::vector<int> polygonCorners(const std::vector<Vec3>& p, std::vector<int> ids, const Simplex& s) {
  const Vec3& a = p[s.v[0]];
  const Vec3& b = p[s.v[1]];
  const Vec3& c = p[s.v[2]];
  const Vec3 n = (b - a).cross(c - a).cwiseAbs();
  std::array<int, 3> axes = {0, 1, 2};
  std::sort(axes.begin(), axes.end(), [&](int i, int j) { return n[i] > n[j]; });
  int u = 0, v = 1;
  for (const int drop : axes) {
    u = (drop + 1) % 3, v = (drop + 2) % 3;
    if (orient2dSign(a[u], a[v], b[u], b[v], c[u], c[v]) != 0) break;
  }
  std::sort(ids.begin(), ids.end(), [&](int i, int j) { return p[i][u] < p[j][u] || (p[i][u] == p[j][u] && p[i][v] < p[j][v]); });
  ids.erase(std::unique(ids.begin(), ids.end(), [&](int i, int j) { return p[i][u] == p[j][u] && p[i][v] == p[j][v]; }),
            ids.end());
  const auto turn = [&](int i, int j, int k) {
    return orient2dSign(p[i][u], p[i][v], p[j][u], p[j][v], p[k][u], p[k][v]);
  };
  // Lower chain left to right, then upper chain right to left; a point is kept only on a strict left
  // turn, so collinear boundary points are dropped.
  std::vector<int> hull(2 * ids.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], ids[i]) <= 0) --k;
    hull[k++] = ids[i];
  }
  for (std::size_t i = ids.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn(hull[k - 2], hull[k - 1], ids[i]) <= 0) --k;
    hull[k++] = ids[i];
  }
  hull.resize(k - 1);
  return hull;
}

// ---- Quickhull ----------------------------------------------------------------------------------------

class QuickHull {
 public:
  // points: scaled coordinates; eps: the containment tolerance in the same units.
  QuickHull(const std::vector<Vec3>& points, double eps)
      : p_(points), eps_(eps), next_(points.size(), -1), horizon_out_(points.size(), -1) {}

  // Builds the hull of points[ids] from a tetrahedron of nonzero volume among them. With
  // drop_within_eps, points outside by at most eps may be left out. Returns false only if the mesh
  // invariants fail, which exact signs rule out (kept as a guard, never expected).
  bool build(const Simplex& simplex, const std::vector<int>& ids, bool drop_within_eps) {
    drop_within_eps_ = drop_within_eps;
    std::array<int, 4> s = simplex.v;
    if (orientSign(p_[s[0]], p_[s[1]], p_[s[2]], p_[s[3]]) > 0) std::swap(s[1], s[2]);
    // Now s[3] is beneath face (s0, s1, s2); these four faces use each directed edge once: outward.
    const int tetra[4][3] = {{s[0], s[1], s[2]}, {s[0], s[3], s[1]}, {s[1], s[3], s[2]}, {s[2], s[3], s[0]}};
    std::vector<int> initial;
    for (const auto& t : tetra) initial.push_back(newFace(t[0], t[1], t[2]));
    for (const int f : initial) {
      for (int e = 0; e < 3; ++e) {
        const int a = faces_[f].v[e], b = faces_[f].v[(e + 1) % 3];
        for (const int g : initial) {
          for (int j = 0; j < 3; ++j) {
            if (faces_[g].v[j] == b && faces_[g].v[(j + 1) % 3] == a) faces_[f].adj[e] = g;
          }
        }
      }
    }
    for (const int q : ids) {
      if (q != s[0] && q != s[1] && q != s[2] && q != s[3]) assign(q, initial);
    }
    // Each iteration makes its eye point a vertex and never looks at it again: at most |ids| of them.
    std::size_t iterations = 0;
    while (!pending_faces_.empty()) {
      const int f = pending_faces_.back();
      pending_faces_.pop_back();
      if (!faces_[f].alive || faces_[f].head < 0) continue;
      if (++iterations > ids.size() || !addPoint(f)) return false;
    }
    return true;
  }

  // The hull's triangles (point indices), counter-clockwise seen from outside.
  std::vector<std::array<int, 3>> triangles() const {
    std::vector<std::array<int, 3>> out;
    for (const Face& f : faces_) {
      if (f.alive) out.push_back(f.v);
    }
    return out;
  }

 private:
  struct Face {
    std::array<int, 3> v{};          // point indices, counter-clockwise seen from outside
    std::array<int, 3> adj{};        // adj[e]: the face across edge v[e] → v[e+1]
    Vec3 origin = Vec3::Zero();      // the point v[0] (a copy: saves an indirection per test)
    Vec3 normal = Vec3::Zero();      // (b − a) × (c − a) in floating point: vol(a, b, c, q) ≈ normal·(q − a)
    Vec3 error = Vec3::Zero();       // |vol − normal·(q − a)| ≤ error·|q − a| (componentwise |·|)
    bool plane_valid = false;        // false if the bound above could be voided by underflow
    double normal_length = 0.0;      // |normal|: turns vol into a distance
    int head = -1;                   // conflict list: first outside point (then next_[...])
    int far = -1;                    // the point of the list with the largest vol (≈ distance)
    double far_vol = 0.0;
    int mark = -1;                   // iteration that last classified this face
    bool visible = false, alive = false;
  };
  struct HorizonEdge {
    int a, b;  // as the edge runs in the visible face
    int face;  // the face beyond it, which stays
  };
  struct Candidate {
    int face;
    double vol;
    bool beyond;  // exactly beyond (already certain in floating point)
  };

  int newFace(int a, int b, int c) {
    int f;
    if (!free_faces_.empty()) {
      f = free_faces_.back();
      free_faces_.pop_back();
    } else {
      f = static_cast<int>(faces_.size());
      faces_.emplace_back();
    }
    Face& face = faces_[f];
    face = Face{};
    face.v = {a, b, c};
    face.alive = true;
    const Vec3 e1 = p_[b] - p_[a], e2 = p_[c] - p_[a];
    face.origin = p_[a];
    face.normal = e1.cross(e2);
    face.normal_length = face.normal.norm();
    // With P = (|e1y e2z| + |e1z e2y|, ...), the rounding of e1, e2 and of the cross product moves the
    // normal by ≤ 4u·P, and the rounding of q − a and of the dot product adds ≤ 4u·P·|q − a|: 10u·P
    // bounds the sum with room for second-order terms. Differences below 2^-500 could underflow.
    const Vec3 a1 = e1.cwiseAbs(), a2 = e2.cwiseAbs();
    face.error = 10.0 * kUnitRoundoff *
                 Vec3(a1.y() * a2.z() + a1.z() * a2.y(), a1.z() * a2.x() + a1.x() * a2.z(), a1.x() * a2.y() + a1.y() * a2.x());
    face.plane_valid = true;
    for (int k = 0; k < 3; ++k) {
      if ((a1[k] != 0.0 && a1[k] < 0x1p-500) || (a2[k] != 0.0 && a2[k] < 0x1p-500)) face.plane_valid = false;
    }
    return f;
  }

  // vol(face, q) in floating point from the face's cached plane, and whether its sign is exact.
  FilteredSign side(const Face& face, const Vec3& q) const {
    if (!face.plane_valid) return orientFiltered(p_[face.v[0]], p_[face.v[1]], p_[face.v[2]], q);
    const Vec3 d = q - face.origin;
    const double vol = face.normal.dot(d);
    const double bound = face.error.dot(d.cwiseAbs());
    // Below 2^-1000 the bound no longer dominates the absolute error of underflowed products.
    return {vol, bound >= 0x1p-1000 && std::abs(vol) > bound};
  }

  void addToFace(int f, int q, double vol) {
    Face& face = faces_[f];
    if (face.head < 0) pending_faces_.push_back(f);
    next_[q] = face.head;
    face.head = q;
    if (face.far < 0 || vol > face.far_vol) face.far = q, face.far_vol = vol;
  }

  bool beyond(int f, const Vec3& q) const {
    const Face& face = faces_[f];
    const FilteredSign o = side(face, q);
    if (o.certain) return o.vol > 0.0;
    return orientSign(p_[face.v[0]], p_[face.v[1]], p_[face.v[2]], q) > 0;
  }

  // Puts point q into the conflict list of a face of `faces` it is exactly beyond, or drops it: when
  // it is beyond none (it is then inside the hull: q was beyond a removed face, and such a point is
  // either inside the new hull or beyond a new face), or when it is within eps of one of their triangles.
  void assign(int q, const std::vector<int>& faces) {
    const Vec3& x = p_[q];
    candidates_.clear();
    for (const int f : faces) {
      const Face& face = faces_[f];
      const FilteredSign o = side(face, x);
      if (o.certain && o.vol < 0.0) continue;
      if (o.certain && o.vol > eps_ * face.normal_length) {
        addToFace(f, q, o.vol);
        return;
      }
      candidates_.push_back({f, o.vol, o.certain});
    }
    // Every candidate plane is within eps of q, or too close to decide in floating point. Within eps
    // of a triangle, q is within eps of the hull whichever side it is on: no exact sign needed.
    if (candidates_.empty() || (drop_within_eps_ && withinEps(x, faces))) return;
    for (const Candidate& c : candidates_) {
      if (c.beyond || beyond(c.face, x)) {
        addToFace(c.face, q, c.vol);
        return;
      }
    }
  }

  bool withinEps(const Vec3& x, const std::vector<int>& faces) const {
    for (const int f : faces) {
      const Face& face = faces_[f];
      if (triangleDistanceSquared(x, p_[face.v[0]], p_[face.v[1]], p_[face.v[2]]) <= eps_ * eps_) return true;
    }
    return false;
  }

  // Adds the farthest point of face f's conflict list to the hull.
  bool addPoint(int f) {
    const int eye = faces_[f].far;
    const Vec3& e = p_[eye];
    ++stamp_;

    // Visible faces: breadth-first from f over neighbours; a face is classified once per iteration,
    // so the walk ends after at most all faces. Exact signs make the visible set a disk around f.
    visible_.assign(1, f);
    faces_[f].mark = stamp_;
    faces_[f].visible = true;
    horizon_.clear();
    for (std::size_t i = 0; i < visible_.size(); ++i) {
      const int vf = visible_[i];
      for (int k = 0; k < 3; ++k) {
        const int g = faces_[vf].adj[k];
        if (faces_[g].mark != stamp_) {
          faces_[g].mark = stamp_;
          faces_[g].visible = beyond(g, e);
          if (faces_[g].visible) visible_.push_back(g);
        }
        if (!faces_[g].visible) horizon_.push_back({faces_[vf].v[k], faces_[vf].v[(k + 1) % 3], g});
      }
    }

    // The horizon as one cycle: each horizon vertex starts exactly one edge, and following the edges
    // from the first returns to it after exactly all of them (at most |horizon| steps).
    const std::size_t h = horizon_.size();
    bool ok = h >= 3;
    for (std::size_t i = 0; i < h && ok; ++i) {
      int& out = horizon_out_[horizon_[i].a];
      if (out >= 0) ok = false;
      else out = static_cast<int>(i);
    }
    cycle_.clear();
    for (int cur = 0; ok && cycle_.size() < h;) {
      cycle_.push_back(cur);
      cur = horizon_out_[horizon_[cur].b];
      if (cur < 0 || (cur == 0) != (cycle_.size() == h)) ok = false;
    }
    for (const HorizonEdge& he : horizon_) horizon_out_[he.a] = -1;
    if (!ok) return false;

    orphans_.clear();
    for (const int vf : visible_) {
      for (int q = faces_[vf].head; q >= 0; q = next_[q]) {
        if (q != eye) orphans_.push_back(q);
      }
      faces_[vf].alive = false;
      free_faces_.push_back(vf);
    }

    // The cone: new face k spans horizon edge k and the eye; its neighbours are the face beyond the
    // edge and the new faces k + 1 (across b → eye) and k − 1 (across eye → a).
    cone_.clear();
    for (const int i : cycle_) cone_.push_back(newFace(horizon_[i].a, horizon_[i].b, eye));
    for (std::size_t k = 0; k < h; ++k) {
      const HorizonEdge& he = horizon_[cycle_[k]];
      faces_[cone_[k]].adj = {he.face, cone_[(k + 1) % h], cone_[(k + h - 1) % h]};
      Face& beyond_face = faces_[he.face];
      int j = 0;
      while (j < 3 && !(beyond_face.v[j] == he.b && beyond_face.v[(j + 1) % 3] == he.a)) ++j;
      if (j == 3) return false;
      beyond_face.adj[j] = cone_[k];
    }
    for (const int q : orphans_) assign(q, cone_);
    return true;
  }

  const std::vector<Vec3>& p_;
  const double eps_;
  bool drop_within_eps_ = true;
  std::vector<Face> faces_;
  std::vector<int> free_faces_, pending_faces_;
  std::vector<int> next_;         // conflict lists, linked through the points
  std::vector<int> horizon_out_;  // point → the horizon edge starting there (−1 outside addPoint)
  int stamp_ = 0;
  // Scratch, reused across iterations.
  std::vector<int> visible_, cycle_, orphans_, cone_;
  std::vector<HorizonEdge> horizon_;
  std::vector<Candidate> candidates_;
};

// The vertices of a closed convex mesh worth keeping. Left out: every vertex that is not a corner
// (exactly: its incident triangles span fewer than three planes, as inside a flat face or an edge),
// and every corner within eps of a segment or triangle of neighbouring corners that are kept (those
// neighbours are then pinned), e.g. a point 1e-16 outside a cube edge that was added before the edge's
// ends. Every left-out vertex is thus within eps of the hull of the kept ones.
std::vector<int> keptVertices(const std::vector<Vec3>& p, const std::vector<std::array<int, 3>>& tris, double eps,
                              bool& all_kept) {
  std::vector<int> start(p.size() + 1, 0);
  for (const auto& t : tris) {
    for (const int v : t) ++start[v + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int> incident(start.back()), fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < tris.size(); ++t) {
    for (const int v : tris[t]) incident[fill[v]++] = static_cast<int>(t);
  }
  // The neighbour after v in an incident triangle: each directed edge v → u occurs once.
  const auto neighbour = [&](int v, int i) {
    const auto& t = tris[incident[i]];
    return t[0] == v ? t[1] : t[1] == v ? t[2] : t[0];
  };

  enum State : char { kAbsent, kCorner, kPinned, kDropped };
  std::vector<char> state(p.size(), kAbsent);
  for (std::size_t v = 0; v < p.size(); ++v) {
    if (start[v] == start[v + 1]) continue;
    std::array<int, 3> planes{};
    int n = 0;
    for (int i = start[v]; i < start[v + 1] && n < 3; ++i) {
      const auto& t = tris[incident[i]];
      bool known = false;
      for (int r = 0; r < n && !known; ++r) {
        const auto& rt = tris[planes[r]];
        known = true;
        for (int k = 0; k < 3 && known; ++k) {
          const bool shared = t[k] == rt[0] || t[k] == rt[1] || t[k] == rt[2];
          known = shared || orientSign(p[rt[0]], p[rt[1]], p[rt[2]], p[t[k]]) == 0;
        }
      }
      if (!known) planes[n++] = incident[i];
    }
    state[v] = n == 3 ? kCorner : kDropped;
  }

  // Witnesses are searched among at most this many neighbours (O(k²) pairs); above it v is kept.
  constexpr int kMaxNeighbours = 32;
  std::vector<int> near;
  for (std::size_t v = 0; v < p.size(); ++v) {
    if (state[v] != kCorner) continue;
    const Vec3& x = p[v];
    // Quick rejection: v is within eps of the hull of its neighbours only if, along the area-weighted
    // mean normal d of its triangles, no neighbour is more than eps·|d| below it.
    Vec3 d = Vec3::Zero();
    for (int i = start[v]; i < start[v + 1]; ++i) {
      const auto& t = tris[incident[i]];
      d += (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
    }
    double lowest_gap = std::numeric_limits<double>::infinity();
    for (int i = start[v]; i < start[v + 1]; ++i) lowest_gap = std::min(lowest_gap, d.dot(x - p[neighbour(v, i)]));
    if (!(lowest_gap <= eps * d.norm())) continue;

    near.clear();
    for (int i = start[v]; i < start[v + 1]; ++i) {
      const int u = neighbour(v, i);
      if (state[u] == kCorner || state[u] == kPinned) near.push_back(u);
    }
    if (near.empty() || near.size() > kMaxNeighbours) continue;
    // A point of the hull of `near` lies in a segment of two of them or, in a flat neighbourhood, in a
    // triangle (near[0], near[i], near[j]) (a fan from any one point covers a planar hull).
    std::array<int, 3> witness = {-1, -1, -1};
    const double eps2 = eps * eps;
    for (std::size_t i = 0; i < near.size() && witness[0] < 0; ++i) {
      for (std::size_t j = i + 1; j < near.size() && witness[0] < 0; ++j) {
        if (segmentDistanceSquared(x, p[near[i]], p[near[j]]) <= eps2) {
          witness = {near[i], near[j], near[j]};
        } else if (i > 0 && triangleDistanceSquared(x, p[near[0]], p[near[i]], p[near[j]]) <= eps2) {
          witness = {near[0], near[i], near[j]};
        }
      }
    }
    if (witness[0] < 0) continue;
    state[v] = kDropped;
    for (const int w : witness) state[w] = kPinned;
  }

  std::vector<int> kept;
  all_kept = true;
  for (std::size_t v = 0; v < p.size(); ++v) {
    if (state[v] == kCorner || state[v] == kPinned) kept.push_back(static_cast<int>(v));
    all_kept = all_kept && state[v] != kDropped;
  }
  return kept;
}

struct HullMesh {
  std::vector<int> vertices;                  // input indices
  std::vector<std::array<int, 3>> triangles;  // input indices
};

// The corners of points[ids] when they span less than a solid (dimension s.dim < Solid); no triangles.
HullMesh flatHull(const std::vector<Vec3>& p, const std::vector<int>& ids, const Simplex& s) {
  HullMesh mesh;
  if (s.dim == Dim::Point) mesh.vertices = {s.v[0]};
  if (s.dim == Dim::Line) mesh.vertices = segmentEnds(p, ids);
  if (s.dim == Dim::Plane) mesh.vertices = polygonCorners(p, ids, s);
  return mesh;
}

// The hull of scaled points: corners and, for a solid, its triangles.
HullMesh computeHull(const std::vector<Vec3>& p, double eps) {
  std::vector<int> ids(p.size());
  std::iota(ids.begin(), ids.end(), 0);
  const Simplex s = findSimplex(p, ids);
  if (s.dim != Dim::Solid) return flatHull(p, ids, s);
  HullMesh mesh;
  // Half of eps for points left out by quickhull, half for vertices left out afterwards: a point
  // within eps/2 of a hull whose every vertex is within eps/2 of the final hull is within eps of it.
  QuickHull first(p, 0.5 * eps);
  bool ok = first.build(s, ids, true);
  if (ok) {
    mesh.triangles = first.triangles();
    bool all_kept = true;
    const std::vector<int> kept = keptVertices(p, mesh.triangles, 0.5 * eps, all_kept);
    // Never none kept with finite points; if it happened, the first mesh is a hull of them all.
    if (!all_kept && !kept.empty()) {
      // A point added early (ties in the farthest-point choice among coplanar points) can end up inside
      // a flat face, on an edge, or within eps of them. Rebuilding from the kept corners alone cannot
      // repeat this: each is then a corner, hence beyond the hull until added. This pass leaves out
      // nothing, so the tolerances do not add up further.
      const Simplex s2 = findSimplex(p, kept);
      if (s2.dim != Dim::Solid) return flatHull(p, kept, s2);  // a slab thinner than eps
      QuickHull second(p, 0.5 * eps);
      ok = second.build(s2, kept, false);
      if (ok) mesh.triangles = second.triangles();
    }
  }
  if (!ok) {
    // Unreachable with exact signs (asserted in debug builds). Release builds keep the conservative
    // answer: every point, no mesh, so support() scans them all.
    assert(!"convex hull: quickhull mesh invariant violated");
    mesh.triangles.clear();
    mesh.vertices = ids;
    return mesh;
  }
  std::vector<char> used(p.size(), 0);
  for (const auto& t : mesh.triangles) {
    for (const int v : t) used[v] = 1;
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (used[i]) mesh.vertices.push_back(static_cast<int>(i));
  }
  return mesh;
}

}  // namespace

ConvexHull::ConvexHull(const std::vector<Vec3>& points) {
  if (points.empty()) throw ShapeError("convex hull: the point set is empty");
  double largest = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) throw ShapeError("convex hull: point " + std::to_string(i) + " is not finite");
    largest = std::max(largest, points[i].cwiseAbs().maxCoeff());
  }
  // Scale by a power of two (exact) so that every |coordinate| < 1, for the exact predicates.
  int exponent = 0;
  if (largest > 0.0) std::frexp(largest, &exponent);
  // ldexp on each coordinate: for subnormal points (a radius of 1e-310) the factor 2^-exponent itself
  // would overflow to infinity.
  std::vector<Vec3> scaled(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k < 3; ++k) scaled[i][k] = std::ldexp(points[i][k], -exponent);

  const HullMesh mesh = computeHull(scaled, kHullEpsilon * std::ldexp(largest, -exponent));

  std::vector<int> index(points.size(), -1);
  vertices_.reserve(mesh.vertices.size());
  for (const int i : mesh.vertices) {
    index[i] = static_cast<int>(vertices_.size());
    vertices_.push_back(points[i]);
  }
  triangles_.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles_.push_back({index[t[0]], index[t[1]], index[t[2]]});

  // Vertex adjacency from the triangles' directed edges: in a closed oriented mesh each directed edge
  // occurs once, so each neighbour is listed once.
  if (!triangles_.empty()) {
    offsets_.assign(vertices_.size() + 1, 0);
    for (const auto& t : triangles_) {
      for (const int v : t) ++offsets_[v + 1];
    }
    std::partial_sum(offsets_.begin(), offsets_.end(), offsets_.begin());
    adjacency_.resize(offsets_.back());
    std::vector<std::int32_t> fill(offsets_.begin(), offsets_.end() - 1);
    for (const auto& t : triangles_) {
      for (int k = 0; k < 3; ++k) adjacency_[fill[t[k]]++] = t[(k + 1) % 3];
    }
  }

  starts_.fill(0);
  center_ = Vec3::Zero();
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec3& v = vertices_[i];
    for (int k = 0; k < 3; ++k) {
      if (v[k] > vertices_[starts_[2 * k]][k]) starts_[2 * k] = static_cast<std::int32_t>(i);
      if (v[k] < vertices_[starts_[2 * k + 1]][k]) starts_[2 * k + 1] = static_cast<std::int32_t>(i);
    }
    center_ += v;
  }
  center_ /= static_cast<double>(vertices_.size());

  // The cube map (once): a direction's cell holds a vertex near its answer, so a climb from it takes a
  // step or two where one from a stale hint (another pose, or GJK's first, far-apart directions) crosses
  // much of a fine hull. Each cell's vertex is climbed to from its neighbour's (the cells of a face in a
  // snake, so neighbours' directions are close): a few steps each, where a scan over every vertex made
  // the map most of building a hull of a few hundred vertices. It only says where support() starts.
  if (!adjacency_.empty() && vertices_.size() >= kBruteForceBelow) {
    cube_.resize(6 * kCube * kCube);
    for (int face = 0; face < 6; ++face) {
      std::int32_t hint = starts_[face];  // (the extreme vertex along the face's axis)
      for (int i = 0; i < kCube; ++i)
        for (int jj = 0; jj < kCube; ++jj) {
          const int j = i % 2 ? kCube - 1 - jj : jj;
          Vec3 d = Vec3::Zero();
          const int axis = face / 2;
          d[axis] = face % 2 ? -1.0 : 1.0;
          d[(axis + 1) % 3] = (i + 0.5) * 2.0 / kCube - 1.0;
          d[(axis + 2) % 3] = (j + 0.5) * 2.0 / kCube - 1.0;
          cube_[(face * kCube + i) * kCube + j] = hint = climb(d, hint, d.dot(vertices_[hint]));
        }
    }
  }
}

namespace {

// The cube map's cell of direction d (n × n cells per face), −1 for a zero or non-finite d.
inline int cubeCell(const Vec3& d, int n) noexcept {
  const double ax = std::abs(d.x()), ay = std::abs(d.y()), az = std::abs(d.z());
  const int axis = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
  const double m = axis == 0 ? ax : axis == 1 ? ay : az;
  if (!(m > 0.0) || !(m < std::numeric_limits<double>::infinity())) return -1;
  const int face = 2 * axis + (d[axis] < 0.0 ? 1 : 0);
  // (A NaN coordinate compares false and lands in cell 0: any start is correct, only slower.)
  const double scale = 0.5 * n / m;
  const auto cell = [&](double u) {
    double x = u * scale + 0.5 * n;
    if (!(x >= 0.0)) x = 0.0;
    if (x > n - 1) x = n - 1;
    return static_cast<int>(x);
  };
  return (face * n + cell(d[(axis + 1) % 3])) * n + cell(d[(axis + 2) % 3]);
}

}  // namespace

Vec3 ConvexHull::support(const Vec3& d) const noexcept {
  std::int32_t hint = -1;
  return support(d, hint);
}

Vec3 ConvexHull::support(const Vec3& d, std::int32_t& hint) const noexcept {
  if (adjacency_.empty() || vertices_.size() < kBruteForceBelow) {
    std::size_t best = 0;
    double best_dot = d.dot(vertices_[0]);
    for (std::size_t i = 1; i < vertices_.size(); ++i) {
      const double x = d.dot(vertices_[i]);
      if (x > best_dot) best = i, best_dot = x;
    }
    return vertices_[best];
  }
  std::int32_t cur;
  double cur_dot;
  if (hint >= 0 && static_cast<std::size_t>(hint) < vertices_.size()) {
    // Consecutive support directions of one query (and of a pair moving smoothly) are close, so the
    // last answer is usually a step or two from the next one; the cube map's vertex when it is better.
    cur = hint;
    cur_dot = d.dot(vertices_[cur]);
    if (const int c = cubeCell(d, kCube); c >= 0) {
      const double x = d.dot(vertices_[cube_[c]]);
      if (x > cur_dot) cur = cube_[c], cur_dot = x;
    }
  } else if (const int c = cubeCell(d, kCube); c >= 0) {
    cur = cube_[c];
    cur_dot = d.dot(vertices_[cur]);
  } else {
    cur = starts_[0];
    cur_dot = d.dot(vertices_[cur]);
    for (int i = 1; i < 6; ++i) {
      const double x = d.dot(vertices_[starts_[i]]);
      if (x > cur_dot) cur = starts_[i], cur_dot = x;
    }
  }
  hint = climb(d, cur, cur_dot);
  return vertices_[hint];
}

std::int32_t ConvexHull::climb(const Vec3& d, std::int32_t cur, double cur_dot) const noexcept {
  // Steepest ascent over the edge graph. Every move strictly increases d·v (so no vertex is visited
  // twice and there are fewer moves than vertices); a NaN d compares false and stops at once. On a
  // convex polytope whose vertices are all corners, a vertex with no better neighbour is a maximiser.
  for (std::size_t moves = 0; moves < vertices_.size(); ++moves) {
    std::int32_t next = cur;
    double next_dot = cur_dot;
    for (std::int32_t k = offsets_[cur]; k < offsets_[cur + 1]; ++k) {
      const double x = d.dot(vertices_[adjacency_[k]]);
      if (x > next_dot) next = adjacency_[k], next_dot = x;
    }
    if (next == cur) break;
    cur = next;
    cur_dot = next_dot;
  }
  return cur;
}

}  // namespace clearway
