#pragma once
// Reference geometry for the mid-phase tests, deliberately independent of the library's trees, SAT and
// GJK: triangles in the world frame, compared by
//   distance   = the minimum of the 6 point–triangle and 9 segment–segment distances (exact for disjoint
//                triangles, whose closest points lie on their boundaries; every candidate is a realised
//                pair of points, so rounding can only make it slightly long);
//   crossing   = an edge of one triangle passing through the other (two closed triangles intersect iff
//                an edge of one meets the other, or they touch, which the distance sees as 0),
//                with a robustness margin: how far the crossing is from failing (the edge's endpoints'
//                distances to the plane and the crossing point's distances to the triangle's edges).
// Pairs of meshes are classified robustly colliding, robustly free, or within the band (ambiguous).
// Also: generators of closed test meshes (UV spheres, tori, subdivided boxes and thin plates).
#include <clearway/shape/primitives.h>
#include <clearway/shape/triangle_mesh.h>
#include <clearway/math.h>
#include <clearway/tree/aabb.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace clearway::tree_ref {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

struct Tri {
  Vec3 v[3];
};

/// Distance from p to segment [a, b].
inline double pointSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  double t = len2 > 0.0 ? ab.dot(p - a) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (a + t * ab - p).norm();
}

/// Distance from p to the closed triangle: the plane projection when it falls inside, else the edges.
inline double pointTriangle(const Vec3& p, const Tri& t) {
  const Vec3& a = t.v[0];
  const Vec3& b = t.v[1];
  const Vec3& c = t.v[2];
  const Vec3 n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  if (nn > 0.0) {
    const Vec3 q = p - n * (n.dot(p - a) / nn);  // projection on the plane
    // Inside when q is on the inner side of all three edges (signs relative to n).
    const double s0 = (b - a).cross(q - a).dot(n), s1 = (c - b).cross(q - b).dot(n), s2 = (a - c).cross(q - c).dot(n);
    if (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) return (p - q).norm();
  }
  return std::min({pointSegment(p, a, b), pointSegment(p, b, c), pointSegment(p, c, a)});
}

/// Distance between segments [p0, p1] and [q0, q1]: the interior stationary point when it is inside
/// the parameter square, else the best endpoint–segment distance (the minimum is then on the square's border).
inline double segmentSegment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.dot(d1), e = d2.dot(d2), b = d1.dot(d2), c = d1.dot(r), f = d2.dot(r);
  const double det = a * e - b * b;
  double best = std::min({pointSegment(p0, q0, q1), pointSegment(p1, q0, q1), pointSegment(q0, p0, p1),
                          pointSegment(q1, p0, p1)});
  if (det > 1e-14 * a * e) {
    const double s = (b * f - c * e) / det, t = (a * f - b * c) / det;
    if (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0) best = std::min(best, (p0 + s * d1 - (q0 + t * d2)).norm());
  }
  return best;
}

/// How robustly segment [p, q] passes through the triangle: > 0 when it crosses the plane strictly
/// and the crossing point is inside, by the smallest of the endpoints' plane distances and the point's
/// distances to the edges; < 0 (by how far the point is outside) when it crosses the plane outside;
/// -inf when it does not cross the plane strictly (or the triangle is degenerate).
inline double crossingMargin(const Vec3& p, const Vec3& q, const Tri& t) {
  const Vec3& a = t.v[0];
  const Vec3& b = t.v[1];
  const Vec3& c = t.v[2];
  const Vec3 n = (b - a).cross(c - a);
  const double len = n.norm();
  if (!(len > 0.0)) return -kInf;
  const Vec3 u = n / len;
  const double sp = u.dot(p - a), sq = u.dot(q - a);
  if (!((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0))) return -kInf;
  const Vec3 x = p + (sp / (sp - sq)) * (q - p);
  double inside = kInf;
  const Vec3* v[3] = {&a, &b, &c};
  for (int k = 0; k < 3; ++k) {
    const Vec3& e0 = *v[k];
    const Vec3& e1 = *v[(k + 1) % 3];
    const Vec3 e = e1 - e0;
    const double el = e.norm();
    inside = std::min(inside, e.cross(x - e0).dot(u) / el);  // signed distance to the edge line, + inside
  }
  if (inside < 0.0) return inside;
  return std::min({inside, std::abs(sp), std::abs(sq)});
}

/// The reference comparison of one triangle pair.
struct PairReference {
  double dist;    // min over feature pairs: the distance when the triangles are disjoint
  double margin;  // max crossing margin over the 6 edge–triangle crossings
};

inline PairReference comparePair(const Tri& s, const Tri& t) {
  PairReference r{kInf, -kInf};
  for (int i = 0; i < 3; ++i) {
    r.dist = std::min({r.dist, pointTriangle(s.v[i], t), pointTriangle(t.v[i], s)});
    for (int j = 0; j < 3; ++j) r.dist = std::min(r.dist, segmentSegment(s.v[i], s.v[(i + 1) % 3], t.v[j], t.v[(j + 1) % 3]));
    r.margin = std::max({r.margin, crossingMargin(s.v[i], s.v[(i + 1) % 3], t), crossingMargin(t.v[i], t.v[(i + 1) % 3], s)});
  }
  return r;
}

enum class Verdict { Collide, Free, Band };

/// A box as plain numbers (the brute-force loops below run over every triangle pair).
struct Box {
  double lo[3], hi[3];
};

/// Distance between two boxes.
inline double boxGap(const Box& a, const Box& b) {
  double s = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double g = std::max(a.lo[k] - b.hi[k], b.lo[k] - a.hi[k]);
    if (g > 0.0) s += g * g;
  }
  return std::sqrt(s);
}

/// The world triangles of a mesh placed by pose, with their boxes.
struct WorldMesh {
  std::vector<Tri> tris;
  std::vector<Box> boxes;
};

inline WorldMesh place(const TriangleMesh& m, const Pose& pose) {
  WorldMesh w;
  for (const auto& t : m.triangles) {
    Tri x{{pose * m.vertices[t[0]], pose * m.vertices[t[1]], pose * m.vertices[t[2]]}};
    Box b;
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = std::min({x.v[0][k], x.v[1][k], x.v[2][k]});
      b.hi[k] = std::max({x.v[0][k], x.v[1][k], x.v[2][k]});
    }
    w.tris.push_back(x);
    w.boxes.push_back(b);
  }
  return w;
}

/// Brute force over all triangle pairs: Collide when some pair robustly crosses (margin > band) or is
/// closer than padding − band; Free when every pair is farther than padding + band and none crosses
/// within the band; Band otherwise.
inline Verdict classify(const WorldMesh& a, const WorldMesh& b, double padding, double band) {
  bool all_free = true;
  for (std::size_t i = 0; i < a.tris.size(); ++i) {
    for (std::size_t j = 0; j < b.tris.size(); ++j) {
      if (boxGap(a.boxes[i], b.boxes[j]) > padding + band) continue;  // triangles inside their boxes
      const PairReference r = comparePair(a.tris[i], b.tris[j]);
      if (r.margin > band || r.dist < padding - band) return Verdict::Collide;
      if (!(r.margin < -band && r.dist > padding + band)) all_free = false;
    }
  }
  return all_free ? Verdict::Free : Verdict::Band;
}

/// The distance between two triangle sets (0 when some pair crosses).
inline double meshDistance(const WorldMesh& a, const WorldMesh& b) {
  double best = kInf;
  for (std::size_t i = 0; i < a.tris.size(); ++i) {
    for (std::size_t j = 0; j < b.tris.size(); ++j) {
      if (boxGap(a.boxes[i], b.boxes[j]) >= best) continue;
      const PairReference r = comparePair(a.tris[i], b.tris[j]);
      best = std::min(best, r.margin >= 0.0 ? 0.0 : r.dist);
    }
  }
  return best;
}

/// The generalized winding number of the triangles at p (their solid angles over 4π; A. Van Oosterom and
/// J. Strackee, 1983): ±1 inside a closed, consistently oriented mesh, 0 outside, between near its surface.
inline double windingNumber(const Vec3& p, const WorldMesh& m) {
  double sum = 0.0;
  for (const Tri& t : m.tris) {
    const Vec3 a = t.v[0] - p, b = t.v[1] - p, c = t.v[2] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * kPi);
}

/// True when every edge of the mesh (vertices welded by their coordinates) is shared by an even number of
/// triangles: a closed surface.
inline bool closedMesh(const TriangleMesh& m) {
  std::vector<std::array<double, 6>> edges;
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e) {
      const Vec3 &p = m.vertices[t[e]], &q = m.vertices[t[(e + 1) % 3]];
      std::array<double, 6> a{p.x(), p.y(), p.z(), q.x(), q.y(), q.z()};
      if (std::lexicographical_compare(a.begin() + 3, a.end(), a.begin(), a.begin() + 3))
        a = {q.x(), q.y(), q.z(), p.x(), p.y(), p.z()};
      if (p != q) edges.push_back(a);
    }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if ((j - i) % 2) return false;
    i = j;
  }
  return !m.triangles.empty();
}

/// Whether a point of `a` (up to `samples` of its vertices, spread over the list) lies inside the closed
/// mesh b: Collide when a winding number is near ±1, Band when one is near ½, Free otherwise. Meaningful
/// when the surfaces do not meet (then each connected piece of a is wholly inside or outside).
inline Verdict containment(const WorldMesh& a, const WorldMesh& b, int samples = 4) {
  Box box{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};
  for (const Box& t : b.boxes)
    for (int k = 0; k < 3; ++k) box.lo[k] = std::min(box.lo[k], t.lo[k]), box.hi[k] = std::max(box.hi[k], t.hi[k]);
  Verdict v = Verdict::Free;
  const std::size_t n = a.tris.size();
  for (int k = 0; k < samples && n > 0; ++k) {
    const Vec3& p = a.tris[k * n / samples].v[0];
    bool in_box = true;
    for (int i = 0; i < 3; ++i) in_box &= p[i] >= box.lo[i] && p[i] <= box.hi[i];
    if (!in_box) continue;
    const double w = std::abs(windingNumber(p, b));
    if (w > 0.75) return Verdict::Collide;
    if (w > 0.25) v = Verdict::Band;
  }
  return v;
}

// ---- Test meshes (closed, outward-facing) --------------------------------------------------------------

inline TriangleMesh uvSphere(double radius, int rings, int segments) {
  TriangleMesh m;
  m.vertices.emplace_back(0, 0, radius);
  for (int i = 1; i < rings; ++i) {
    const double th = kPi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double ph = 2 * kPi * j / segments;
      m.vertices.emplace_back(radius * std::sin(th) * std::cos(ph), radius * std::sin(th) * std::sin(ph),
                              radius * std::cos(th));
    }
  }
  m.vertices.emplace_back(0, 0, -radius);
  const int south = static_cast<int>(m.vertices.size()) - 1;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j) m.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
      m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
    }
  for (int j = 0; j < segments; ++j) m.triangles.push_back({south, ring(rings - 1, j + 1), ring(rings - 1, j)});
  return m;
}

inline TriangleMesh torus(double major, double minor, int nu, int nv) {
  TriangleMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
      m.vertices.emplace_back((major + minor * std::cos(v)) * std::cos(u), (major + minor * std::cos(v)) * std::sin(u),
                              minor * std::sin(v));
    }
  auto at = [&](int i, int j) { return ((i % nu) * nv) + (j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

/// A box of the given half extents with each face cut into n × n squares (a thin plate when one
/// half extent is small). Vertices on shared edges are shared.
inline TriangleMesh gridBox(const Vec3& half, int n) {
  TriangleMesh m;
  std::vector<std::array<int, 3>> keys;  // integer lattice coordinates, for sharing
  auto vertex = [&](int i, int j, int k) {
    const std::array<int, 3> key{i, j, k};
    const auto it = std::find(keys.begin(), keys.end(), key);
    if (it != keys.end()) return static_cast<std::int32_t>(it - keys.begin());
    keys.push_back(key);
    m.vertices.emplace_back(half.x() * (2.0 * i / n - 1), half.y() * (2.0 * j / n - 1), half.z() * (2.0 * k / n - 1));
    return static_cast<std::int32_t>(m.vertices.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side <= 1; ++side)
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          auto corner = [&](int da, int db) {
            std::array<int, 3> c{};
            c[axis] = side * n;
            c[(axis + 1) % 3] = a + da;
            c[(axis + 2) % 3] = b + db;
            return vertex(c[0], c[1], c[2]);
          };
          const std::int32_t p00 = corner(0, 0), p10 = corner(1, 0), p11 = corner(1, 1), p01 = corner(0, 1);
          if (side == 1) {
            m.triangles.push_back({p00, p10, p11});
            m.triangles.push_back({p00, p11, p01});
          } else {
            m.triangles.push_back({p00, p11, p10});
            m.triangles.push_back({p00, p01, p11});
          }
        }
  return m;
}

/// Two meshes as one (the second moved by `offset`): several components, a hull with empty space.
inline TriangleMesh joined(const TriangleMesh& a, const TriangleMesh& b, const Vec3& offset) {
  TriangleMesh m = a;
  const auto base = static_cast<std::int32_t>(m.vertices.size());
  for (const Vec3& v : b.vertices) m.vertices.push_back(v + offset);
  for (const auto& t : b.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return m;
}

/// The reference's mesh of a link's triangles (in the link frame), each with its own three vertices.
inline WorldMesh placeTriangles(const std::vector<Triangle>& triangles) {
  TriangleMesh m;
  for (const Triangle& t : triangles) {
    const int k = static_cast<int>(m.vertices.size());
    for (const Vec3& v : t.v) m.vertices.push_back(v);
    m.triangles.push_back({k, k + 1, k + 2});
  }
  return place(m, Pose::identity());
}

/// Closed meshes of several kinds, named: round, a hole, thin, coarse, two pieces joined.
inline std::vector<std::pair<std::string, TriangleMesh>> closedSamples() {
  return {{"sphere", uvSphere(0.1, 10, 16)},
          {"torus", torus(0.12, 0.03, 20, 10)},
          {"plate", gridBox(Vec3(0.15, 0.1, 0.002), 4)},
          {"box", gridBox(Vec3(0.05, 0.08, 0.1), 2)},
          {"dumbbell", joined(uvSphere(0.04, 6, 10), gridBox(Vec3(0.03, 0.03, 0.03), 2), Vec3(0.2, 0.05, 0.0))}};
}

inline Mat3 randomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  return q.normalized().toRotationMatrix();
}

inline Vec3 randomInBall(std::mt19937_64& rng, double radius) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vec3 p;
  do p = Vec3(u(rng), u(rng), u(rng));
  while (p.squaredNorm() > 1.0);
  return radius * p;
}

/// A point uniform in the box (one draw per axis, x first).
inline Vec3 randomInBox(std::mt19937_64& rng, const Aabb& box) {
  Vec3 p;
  for (int a = 0; a < 3; ++a) p[a] = std::uniform_real_distribution<double>(box.min[a], box.max[a])(rng);
  return p;
}

inline double meshRadius(const TriangleMesh& m) {
  double r = 0.0;
  for (const Vec3& v : m.vertices) r = std::max(r, v.norm());
  return r;
}

}  // namespace clearway::tree_ref
