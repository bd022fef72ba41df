// The shape-independent half of EPA: polytope bookkeeping (see epa.h).
#include <clearway/narrowphase/epa.h>

namespace clearway::detail {

bool EpaPolytope::makeFace(int i, int j, int k, EpaFace& f) const noexcept {
  const Vec3 n = (vs_[j].w - vs_[i].w).cross(vs_[k].w - vs_[i].w);
  const double len = n.norm();
  if (!(len > 0.0)) return false;
  f.v[0] = i; f.v[1] = j; f.v[2] = k;
  f.n = n / len;
  f.d = f.n.dot(vs_[i].w);
  f.alive = true;
  return true;
}

bool EpaPolytope::init(const SupportPoint tet[4]) noexcept {
  for (int i = 0; i < 4; ++i) vs_[i] = tet[i];
  nv_ = 4;
  nf_ = 0;
  // Orient so every face normal points away from the opposite vertex.
  if ((vs_[1].w - vs_[0].w).cross(vs_[2].w - vs_[0].w).dot(vs_[3].w - vs_[0].w) > 0.0) std::swap(vs_[1], vs_[2]);
  const int tri[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  for (const auto& t : tri)
    if (!makeFace(t[0], t[1], t[2], faces_[nf_++])) return false;
  return true;
}

int EpaPolytope::closestFace() const noexcept {
  int best = -1;
  for (int f = 0; f < nf_; ++f)
    if (faces_[f].alive && (best < 0 || faces_[f].d < faces_[best].d)) best = f;
  return best;
}

bool EpaPolytope::hasVertex(const Vec3& w) const noexcept {
  for (int i = 0; i < nv_; ++i)
    if (vs_[i].w == w) return true;
  return false;
}

bool EpaPolytope::expand(const SupportPoint& w, double eps) noexcept {
  if (nv_ >= kEpaMaxVertices) return false;
  // Remove every face that sees w; the edges bordering exactly one removed face form the horizon.
  // A shared edge appears once in each direction, so adding (b, a) cancels a stored (a, b).
  int horizon[kEpaMaxFaces][2];
  int nh = 0;
  for (int f = 0; f < nf_; ++f) {
    EpaFace& face = faces_[f];
    if (!face.alive || face.n.dot(w.w - vs_[face.v[0]].w) <= eps) continue;
    face.alive = false;
    for (int e = 0; e < 3; ++e) {
      const int a = face.v[e], b = face.v[(e + 1) % 3];
      int found = -1;
      for (int h = 0; h < nh; ++h)
        if (horizon[h][0] == b && horizon[h][1] == a) { found = h; break; }
      if (found >= 0) {
        horizon[found][0] = horizon[nh - 1][0];
        horizon[found][1] = horizon[nh - 1][1];
        --nh;
      } else {
        if (nh == kEpaMaxFaces) return false;
        horizon[nh][0] = a;
        horizon[nh][1] = b;
        ++nh;
      }
    }
  }
  if (nh == 0) return false;  // w sees no face: no progress possible
  const int wi = nv_;
  vs_[nv_++] = w;
  int slot = 0;
  for (int h = 0; h < nh; ++h) {
    while (slot < nf_ && faces_[slot].alive) ++slot;
    if (slot == nf_) {
      if (nf_ == kEpaMaxFaces) return false;
      ++nf_;
    }
    if (!makeFace(horizon[h][0], horizon[h][1], wi, faces_[slot])) return false;
  }
  return true;
}

void EpaPolytope::witnesses(int f, Vec3& a, Vec3& b) const noexcept {
  // The closest point of the face to the origin is the origin's projection when that lies inside
  // the face (the usual case at convergence); its weights map back to both cores.
  Simplex tri;
  tri.n = 3;
  for (int i = 0; i < 3; ++i) tri.p[i] = vs_[faces_[f].v[i]];
  double l[4];
  closestWeights(tri, l);
  a.setZero();
  b.setZero();
  for (int i = 0; i < 3; ++i) {
    a += l[i] * tri.p[i].a;
    b += l[i] * tri.p[i].b;
  }
}

}  // namespace clearway::detail
