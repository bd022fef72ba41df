#pragma once
// Reference geometry for the narrow-phase property tests, deliberately NOT built on GJK, EPA or any
// support mapping: convex polytopes are lists of polygon faces in the world frame, and
//   distance      = the minimum over face-triangle pairs of the triangle–triangle distance, itself the
//                   minimum of the 6 point–triangle and 9 segment–segment distances (exact for disjoint
//                   polytopes, whose closest points lie on their boundaries);
//   overlap/depth = the separating axis test over face normals, edge-pair cross products, in-plane
//                   normals of flat shapes and the direction of the closest feature pair. The normals of
//                   every facet of A − B are among those axes, so the largest separation is > 0 exactly
//                   when the polytopes are disjoint, and when they overlap its negation is the
//                   penetration depth (the smallest projection overlap over all directions is attained
//                   at a facet normal of A − B);
//   ray / cast    = Kay–Kajiya slab clipping of the moving point (or the moving A's projections) against
//                   the face planes (or the same SAT axes).
// Every closest-point candidate is a realised pair of points, one on each feature, so rounding can only
// make a candidate slightly long, never hide a closer pair.
#include <clearway/math.h>
#include <clearway/shape/convex_hull.h>
#include <clearway/shape/primitives.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace clearway::ref {

/// A closest pair between two features: p on the first, q on the second.
struct Closest {
  double dist2 = std::numeric_limits<double>::infinity();
  Vec3 p = Vec3::Zero(), q = Vec3::Zero();
};

inline void keepCloser(Closest& best, const Vec3& p, const Vec3& q) {
  const double d2 = (p - q).squaredNorm();
  if (d2 < best.dist2) best = {d2, p, q};
}

/// The point of segment [a, b] closest to p (a degenerate segment is the point a).
inline Vec3 closestOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (!(len2 > 0.0)) return a;
  const double t = ab.dot(p - a) / len2;
  if (t <= 0.0) return a;
  if (t >= 1.0) return b;
  return a + t * ab;
}

/// The point of the closed triangle (a, b, c) closest to p; degenerate triangles fall back to their edges.
inline Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Candidates: the three edges always, and the projection onto the plane when it lies inside. The
  // minimum of realised candidates is exact: if the projection is inside, it beats every edge point.
  Closest best;
  keepCloser(best, p, closestOnSegment(p, a, b));
  keepCloser(best, p, closestOnSegment(p, b, c));
  keepCloser(best, p, closestOnSegment(p, c, a));
  const Vec3 n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  if (nn > 0.0 && n.dot((b - a).cross(p - a)) >= 0.0 && n.dot((c - b).cross(p - b)) >= 0.0 &&
      n.dot((a - c).cross(p - c)) >= 0.0) {
    // Measure the height from the vertex nearest p: less cancellation than from an arbitrary one.
    const Vec3* v = &a;
    if ((p - b).squaredNorm() < (p - *v).squaredNorm()) v = &b;
    if ((p - c).squaredNorm() < (p - *v).squaredNorm()) v = &c;
    keepCloser(best, p, p - n * (n.dot(p - *v) / nn));
  }
  return best.q;
}

/// The closest pair of segments [p0, p1] and [q0, q1] (either may be degenerate).
inline Closest segmentSegment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  // Either an endpoint takes part in a closest pair (four point–segment candidates), or both closest
  // points are interior and solve the 2×2 normal equations of the two lines. The interior candidate is
  // evaluated as a real pair of points, so an ill-conditioned solve (nearly parallel segments) can only
  // give a longer candidate, which the endpoint candidates then beat to rounding.
  Closest best;
  keepCloser(best, p0, closestOnSegment(p0, q0, q1));
  keepCloser(best, p1, closestOnSegment(p1, q0, q1));
  keepCloser(best, closestOnSegment(q0, p0, p1), q0);
  keepCloser(best, closestOnSegment(q1, p0, p1), q1);
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  const double denom = a * e - b * b;
  if (denom > 0.0) {
    const double s = (b * f - c * e) / denom, t = (a * f - b * c) / denom;
    if (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) keepCloser(best, p0 + s * d1, q0 + t * d2);
  }
  return best;
}

/// The closest pair of two disjoint closed triangles (min of 6 point–triangle and 9 segment–segment pairs).
/// For intersecting triangles this is not 0: callers decide overlap separately (SAT).
inline Closest triangleTriangle(const std::array<Vec3, 3>& s, const std::array<Vec3, 3>& t) {
  Closest best;
  for (int i = 0; i < 3; ++i) {
    keepCloser(best, s[i], closestOnTriangle(s[i], t[0], t[1], t[2]));
    keepCloser(best, closestOnTriangle(t[i], s[0], s[1], s[2]), t[i]);
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const Closest c = segmentSegment(s[i], s[(i + 1) % 3], t[j], t[(j + 1) % 3]);
      if (c.dist2 < best.dist2) best = c;
    }
  }
  return best;
}

/// A convex polytope (or a flat polygon, segment or point) in the world frame, described by its faces.
struct Mesh {
  std::vector<Vec3> verts;
  std::vector<std::array<Vec3, 3>> tris;   ///< fan triangulation of the faces (degenerate for segments/points)
  std::vector<Vec3> tri_center;            ///< bounding sphere of each triangle, for culling only
  std::vector<double> tri_radius;
  std::vector<std::array<Vec3, 2>> edges;  ///< every distinct side of a triangle in tris (nonzero length)
  std::vector<Vec3> plane_n;               ///< solid only: unit outward face normals
  std::vector<double> plane_d;             ///< solid only: n·x ≤ d inside
  std::vector<Vec3> axes;                  ///< unit face normals (one per direction, sign ignored)
  std::vector<Vec3> edge_dirs;             ///< unit edge directions (one per direction, sign ignored)
  bool solid = false;                      ///< has volume (closed outward faces)
  Vec3 center = Vec3::Zero();
  std::vector<double> xyz;                 ///< verts as plain doubles: projections run thousands of times
};

/// Refreshes the plain copy of the vertices.
inline void syncFlat(Mesh& m) {
  m.xyz.clear();
  for (const Vec3& v : m.verts) m.xyz.insert(m.xyz.end(), {v.x(), v.y(), v.z()});
}

namespace detail {
// Adds u to a list of unit directions unless it is parallel (to 1e-12) to one already there: parallel
// directions give the same axis up to a rotation of 1e-12, which moves a projection by 1e-12·size.
inline void addDirection(std::vector<Vec3>& list, const Vec3& v) {
  const double len = v.norm();
  if (!(len > 0.0) || !std::isfinite(len)) return;
  const Vec3 u = v / len;
  for (const Vec3& w : list)
    if (u.cross(w).squaredNorm() < 1e-24) return;
  list.push_back(u);
}
}  // namespace detail

/// Builds a mesh from vertex loops (each loop one planar convex face, any orientation); `solid` when
/// the faces bound a volume. Normals are oriented away from the centroid of the vertices.
inline Mesh meshFromFaces(const std::vector<Vec3>& verts, const std::vector<std::vector<int>>& faces, bool solid) {
  Mesh m;
  m.verts = verts;
  m.solid = solid;
  std::vector<std::pair<int, int>> edge_ids;
  for (const Vec3& v : verts) m.center += v;
  m.center /= static_cast<double>(verts.size());
  for (const auto& f : faces) {
    const int k = static_cast<int>(f.size());
    for (int i = 0; i < k; ++i) detail::addDirection(m.edge_dirs, verts[f[(i + 1) % k]] - verts[f[i]]);
    // Newell's normal: robust for any planar loop, zero for a degenerate one.
    Vec3 n = Vec3::Zero();
    for (int i = 0; i < k; ++i) n += verts[f[i]].cross(verts[f[(i + 1) % k]]);
    const auto addEdge = [&](int i, int j) {
      if (i == j) return;
      if (std::find(edge_ids.begin(), edge_ids.end(), std::make_pair(std::min(i, j), std::max(i, j))) == edge_ids.end())
        edge_ids.emplace_back(std::min(i, j), std::max(i, j));
    };
    if (k == 2) {  // a segment: a degenerate triangle
      m.tris.push_back({verts[f[0]], verts[f[1]], verts[f[1]]});
      addEdge(f[0], f[1]);
    }
    for (int i = 1; i + 1 < k; ++i) {
      m.tris.push_back({verts[f[0]], verts[f[i]], verts[f[i + 1]]});
      addEdge(f[0], f[i]);
      addEdge(f[i], f[i + 1]);
      addEdge(f[i + 1], f[0]);
    }
    if (k >= 3) {
      detail::addDirection(m.axes, n);
      if (solid && n.norm() > 0.0) {
        Vec3 un = n.normalized();
        // The largest offset over the face's vertices: rounding can only push the plane outward.
        if (un.dot(verts[f[0]] - m.center) < 0.0) un = -un;
        double d = -std::numeric_limits<double>::infinity();
        for (const int i : f) d = std::max(d, un.dot(verts[i]));
        m.plane_n.push_back(un);
        m.plane_d.push_back(d);
      }
    }
  }
  if (faces.empty()) m.tris.push_back({verts[0], verts[0], verts[0]});  // a point
  for (const auto& [i, j] : edge_ids) m.edges.push_back({verts[i], verts[j]});
  for (const auto& t : m.tris) {
    const Vec3 c = (t[0] + t[1] + t[2]) / 3.0;
    m.tri_center.push_back(c);
    m.tri_radius.push_back(std::sqrt(std::max({(t[0] - c).squaredNorm(), (t[1] - c).squaredNorm(), (t[2] - c).squaredNorm()})));
  }
  syncFlat(m);
  return m;
}

/// A ConvexHull placed by a pose (3D hulls from triangles(); flat hulls from their sorted polygon).
inline Mesh meshFromHull(const ConvexHull& hull, const Pose& pose) {
  std::vector<Vec3> v;
  for (const Vec3& p : hull.vertices()) v.push_back(pose * p);
  std::vector<std::vector<int>> faces;
  if (!hull.triangles().empty()) {
    for (const auto& t : hull.triangles()) faces.push_back({t[0], t[1], t[2]});
    return meshFromFaces(v, faces, true);
  }
  if (v.size() == 1) return meshFromFaces(v, {}, false);
  if (v.size() == 2) return meshFromFaces(v, {{0, 1}}, false);
  // Flat polygon: order the corners by angle around their centroid in the plane.
  Vec3 c = Vec3::Zero();
  for (const Vec3& p : v) c += p;
  c /= static_cast<double>(v.size());
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t j = 0; j < v.size(); ++j) {
      const Vec3 x = (v[i] - c).cross(v[j] - c);
      if (x.squaredNorm() > n.squaredNorm()) n = x;
    }
  const Vec3 e1 = (v[0] - c).normalized(), e2 = n.normalized().cross(e1);
  std::vector<int> loop(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) loop[i] = static_cast<int>(i);
  std::sort(loop.begin(), loop.end(), [&](int i, int j) {
    return std::atan2(e2.dot(v[i] - c), e1.dot(v[i] - c)) < std::atan2(e2.dot(v[j] - c), e1.dot(v[j] - c));
  });
  return meshFromFaces(v, {loop}, false);
}

/// An axis-aligned box of the given half extents, placed by a pose.
inline Mesh meshFromBox(const Vec3& half, const Pose& pose) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i)
    v.push_back(pose * Vec3((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(), (i & 4) ? half.z() : -half.z()));
  return meshFromFaces(v, {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}}, true);
}

/// Polytopes bracketing a cylinder (z-axis, radius r, half length h): the prism over the regular n-gon
/// inscribed in the circle (outer = false) or circumscribed about it (outer = true).
inline Mesh meshFromCylinder(double r, double h, int n, bool outer, const Pose& pose) {
  const double rr = outer ? r / std::cos(M_PI / n) : r;
  std::vector<Vec3> v;
  std::vector<std::vector<int>> faces(2);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    v.push_back(pose * Vec3(rr * std::cos(a), rr * std::sin(a), -h));
    v.push_back(pose * Vec3(rr * std::cos(a), rr * std::sin(a), h));
    faces[0].push_back(2 * i);
    faces[1].push_back(2 * i + 1);
    faces.push_back({2 * i, 2 * ((i + 1) % n), 2 * ((i + 1) % n) + 1, 2 * i + 1});
  }
  return meshFromFaces(v, faces, true);
}

/// Polytopes bracketing a cone (apex at +h, base of radius r at −h): the pyramid over the inscribed or
/// circumscribed regular n-gon.
inline Mesh meshFromCone(double r, double h, int n, bool outer, const Pose& pose) {
  const double rr = outer ? r / std::cos(M_PI / n) : r;
  std::vector<Vec3> v;
  std::vector<std::vector<int>> faces(1);
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    v.push_back(pose * Vec3(rr * std::cos(a), rr * std::sin(a), -h));
    faces[0].push_back(i);
    faces.push_back({i, (i + 1) % n, n});
  }
  v.push_back(pose * Vec3(0, 0, h));
  return meshFromFaces(v, faces, true);
}

/// A triangle, segment or point (flat, no volume).
inline Mesh meshFromTriangle(const Vec3& a, const Vec3& b, const Vec3& c) { return meshFromFaces({a, b, c}, {{0, 1, 2}}, false); }
inline Mesh meshFromSegment(const Vec3& a, const Vec3& b) { return meshFromFaces({a, b}, {{0, 1}}, false); }
inline Mesh meshFromPoint(const Vec3& a) { return meshFromFaces({a}, {}, false); }

/// The same mesh moved by a translation.
inline Mesh translated(Mesh m, const Vec3& t) {
  for (Vec3& v : m.verts) v += t;
  for (auto& tri : m.tris)
    for (Vec3& v : tri) v += t;
  for (auto& e : m.edges)
    for (Vec3& v : e) v += t;
  for (Vec3& c : m.tri_center) c += t;
  for (std::size_t i = 0; i < m.plane_n.size(); ++i) m.plane_d[i] += m.plane_n[i].dot(t);
  m.center += t;
  syncFlat(m);
  return m;
}

/// The closest pair of boundary features of two meshes (the distance when they are disjoint): the minimum
/// over triangle pairs of triangleTriangle. Evaluated without repeats: the 6 point–triangle and 9
/// segment–segment candidates of all triangle pairs are exactly every vertex against every triangle of
/// the other mesh, and every side against every side; shared vertices and sides are taken once.
inline Closest featureDistance(const Mesh& a, const Mesh& b) {
  // Start from the closest vertex pair (a realised pair, so the minimum stays exact) so that the
  // bounding-sphere tests below cull from the first candidate on; skipping a candidate whose lower
  // bound cannot beat the best is exact.
  Closest best;
  for (const Vec3& p : a.verts)
    for (const Vec3& q : b.verts) keepCloser(best, p, q);
  const auto cannotBeat = [&](double lower) { return lower > 0.0 && lower * lower > best.dist2 * (1.0 + 1e-9); };
  for (const Vec3& p : a.verts) {
    for (std::size_t j = 0; j < b.tris.size(); ++j) {
      if (cannotBeat((p - b.tri_center[j]).norm() - b.tri_radius[j])) continue;
      const auto& t = b.tris[j];
      keepCloser(best, p, closestOnTriangle(p, t[0], t[1], t[2]));
    }
  }
  for (const Vec3& q : b.verts) {
    for (std::size_t i = 0; i < a.tris.size(); ++i) {
      if (cannotBeat((q - a.tri_center[i]).norm() - a.tri_radius[i])) continue;
      const auto& t = a.tris[i];
      keepCloser(best, closestOnTriangle(q, t[0], t[1], t[2]), q);
    }
  }
  for (const auto& ea : a.edges) {
    const Vec3 ca = 0.5 * (ea[0] + ea[1]);
    const double ra = 0.5 * (ea[1] - ea[0]).norm();
    for (const auto& eb : b.edges) {
      if (cannotBeat((0.5 * (eb[0] + eb[1]) - ca).norm() - ra - 0.5 * (eb[1] - eb[0]).norm())) continue;
      const Closest c = segmentSegment(ea[0], ea[1], eb[0], eb[1]);
      if (c.dist2 < best.dist2) best = c;
    }
  }
  return best;
}

/// Projection interval of a mesh onto a unit axis.
inline void project(const Mesh& m, const Vec3& n, double& lo, double& hi) {
  lo = std::numeric_limits<double>::infinity();
  hi = -lo;
  const double nx = n.x(), ny = n.y(), nz = n.z();
  const double* v = m.xyz.data();
  for (std::size_t i = 0; i < m.xyz.size(); i += 3) {
    const double x = nx * v[i] + ny * v[i + 1] + nz * v[i + 2];
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
}

/// The SAT axes of a pair: both meshes' face normals, edge × edge, in-plane normals of flat meshes, and
/// `extra` (the direction of the closest feature pair) when nonzero. All unit length.
inline std::vector<Vec3> satAxes(const Mesh& a, const Mesh& b, const Vec3& extra = Vec3::Zero()) {
  std::vector<Vec3> axes;
  const auto add = [&](const Vec3& v) {
    const double len = v.norm();
    if (len > 0.0 && std::isfinite(len)) axes.push_back(v / len);
  };
  add(extra);
  for (const Vec3& n : a.axes) add(n);
  for (const Vec3& n : b.axes) add(n);
  for (const Vec3& ea : a.edge_dirs)
    for (const Vec3& eb : b.edge_dirs) add(ea.cross(eb));
  for (const Mesh* m : {&a, &b}) {
    if (m->solid) continue;
    for (const Vec3& n : m->axes)
      for (const Vec3& e : m->edge_dirs) add(n.cross(e));
  }
  return axes;
}

/// The largest separation of the projections over the SAT axes: > 0 iff disjoint; −depth when overlapping.
/// `axis` receives the maximising axis oriented from a towards b.
inline double satSeparation(const Mesh& a, const Mesh& b, const std::vector<Vec3>& axes, Vec3* axis = nullptr,
                            bool stop_when_separated = false) {
  double best = -std::numeric_limits<double>::infinity();
  for (const Vec3& n : axes) {
    double a0, a1, b0, b1;
    project(a, n, a0, a1);
    project(b, n, b0, b1);
    // b beyond a along +n, or along −n; the larger is this axis' separation (negative: overlap).
    const double plus = b0 - a1, minus = a0 - b1;
    const double sep = std::max(plus, minus);
    if (sep > best) {
      best = sep;
      if (axis) *axis = plus >= minus ? n : Vec3(-n);
      if (stop_when_separated && sep > 0.0) return best;
    }
  }
  return best;
}

/// Signed distance between two meshes: the distance when disjoint, −(penetration depth) when not.
struct Signed {
  double value;
  Closest closest;  ///< the closest pair (meaningful when disjoint)
  Vec3 axis;        ///< the separating / minimum-overlap axis, from a towards b
};

inline Signed signedDistance(const Mesh& a, const Mesh& b) {
  Signed s{0.0, featureDistance(a, b), Vec3::Zero()};
  const Vec3 pair_dir = s.closest.q - s.closest.p;
  // The closest pair's direction first: when the meshes are disjoint it separates them and ends the test.
  const std::vector<Vec3> axes = satAxes(a, b, pair_dir);
  // (Stopping early only ever skips axes after a positive separation, so a value ≤ 0 is the full maximum.)
  const double sep = satSeparation(a, b, axes, &s.axis, true);
  if (sep > 0.0) {
    s.value = std::sqrt(s.closest.dist2);
  } else if (axes.empty()) {
    s.value = 0.0;  // two coincident points: the Minkowski difference is a point at the origin
  } else {
    s.value = sep;
  }
  return s;
}

/// Distance from a point to a mesh: 0 inside a solid, else the distance to the nearest face triangle.
inline double pointDistance(const Mesh& m, const Vec3& p) {
  if (m.solid) {
    bool inside = true;
    for (std::size_t i = 0; i < m.plane_n.size() && inside; ++i) inside = m.plane_n[i].dot(p) <= m.plane_d[i];
    if (inside) return 0.0;
  }
  double best = std::numeric_limits<double>::infinity();
  for (const auto& t : m.tris) best = std::min(best, (closestOnTriangle(p, t[0], t[1], t[2]) - p).squaredNorm());
  return std::sqrt(best);
}

/// Result of a slab clip: the parameter interval [t_enter, t_exit] inside, or no hit.
struct Slab {
  bool hit = false;
  double t_enter = 0.0, t_exit = 0.0;
  Vec3 normal = Vec3::Zero();  ///< the plane (axis) that fixed t_enter; zero when starting inside
  double incidence = 1.0;      ///< |n·d̂| of that plane: how squarely the ray meets it
};

/// Kay–Kajiya clip of the ray o + t·d, t ∈ [0, max_t], against the face planes of a solid mesh pushed
/// out by `inflate` (negative: pulled in).
inline Slab raySlab(const Mesh& m, const Vec3& o, const Vec3& d, double max_t, double inflate = 0.0) {
  Slab s;
  double t0 = 0.0, t1 = max_t;
  const double dlen = d.norm();
  for (std::size_t i = 0; i < m.plane_n.size(); ++i) {
    const Vec3& n = m.plane_n[i];
    const double room = m.plane_d[i] + inflate - n.dot(o);  // ≥ 0: o is inside this half-space
    const double nd = n.dot(d);
    if (nd == 0.0) {
      if (room < 0.0) return s;
      continue;
    }
    const double t = room / nd;
    if (nd < 0.0) {
      if (t > t0) { t0 = t; s.normal = n; s.incidence = -nd / dlen; }
    } else {
      t1 = std::min(t1, t);
    }
  }
  s.hit = t0 <= t1;
  s.t_enter = t0;
  s.t_exit = t1;
  return s;
}

/// The same clip for a mesh A translated by t·v against a still mesh B, on the SAT axes of the pair:
/// on each axis the projections overlap for t in an interval; A and B touch on the intersection of those
/// intervals (each axis' overlap condition is relaxed by `inflate`).
inline Slab castSlab(const Mesh& a, const Vec3& v, const Mesh& b, double max_t, const std::vector<Vec3>& axes,
                     double inflate = 0.0) {
  Slab s;
  double t0 = 0.0, t1 = max_t;
  const double vlen = v.norm();
  for (const Vec3& n : axes) {
    double a0, a1, b0, b1;
    project(a, n, a0, a1);
    project(b, n, b0, b1);
    const double sv = n.dot(v);
    // Overlap at t:  b0 − inflate ≤ a1 + t·sv  and  a0 + t·sv ≤ b1 + inflate.
    const double lo_gap = b0 - inflate - a1, hi_gap = b1 + inflate - a0;
    if (sv == 0.0) {
      if (lo_gap > 0.0 || hi_gap < 0.0) return s;
      continue;
    }
    double lo = lo_gap / sv, hi = hi_gap / sv;
    if (sv < 0.0) std::swap(lo, hi);
    if (lo > t0) { t0 = lo; s.normal = sv > 0.0 ? n : Vec3(-n); s.incidence = std::abs(sv) / vlen; }
    t1 = std::min(t1, hi);
  }
  s.hit = t0 <= t1;
  s.t_enter = t0;
  s.t_exit = t1;
  return s;
}

}  // namespace clearway::ref
