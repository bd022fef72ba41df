// The mid-phase benchmark: LinkGeometry build time per robot mesh, and the time of a link–link test in
// Hull and Mesh mode on the Panda's and the UR5's collision meshes, with the design choices of the
// exact stage measured one at a time: median or SAH split, leaf size, 6 or 15 box axes, and the
// triangle–triangle test (separating axes then GJK, GJK alone, separating axes alone).
//
// Cases: every pair of link meshes (a mesh with itself included) at random relative poses, origins
// within the sum of the meshes' radii; a third of them moved into near contact along the normal of
// closest approach (0.8 … 1.2 times the distance), where the trees work hardest, and a third drawn
// until the hulls overlap while the meshes do not (the exact stage's hardest "free"). Each case falls in one
// bucket: hulls apart, hulls overlapping but meshes apart, or meshes intersecting. Times are the median
// over passes of the mean per query (thread CPU time), after a warm-up pass.
//
// Self-collision: the robot loaded from its URDF and SRDF, random joint vectors within the limits, every
// link pair not disabled by the SRDF and not adjacent, all pairs checked per state (no early exit):
// ns per state and per pair, colliding fraction, with a fresh hull cache per query (cold) and with
// one cache per link pair kept across states (warm).
//
// Usage: bench_tree [--quick] [--shared DIR]     (DIR defaults to CLEARWAY_SHARED_DIR, ../shared)
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/robot_loader.h>
#include <clearway/load/mesh_loader.h>
#include <clearway/body/proximity.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <functional>
#include <memory>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#ifndef CLEARWAY_SHARED_DIR
#define CLEARWAY_SHARED_DIR "../shared"
#endif

namespace cw = clearway;
using cw::Pose;
using cw::Vec3;

namespace {

double threadSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

volatile int g_sink = 0;  // keeps results alive

// Median over `passes` of the mean ns per call of f over n calls; f(i) runs call i.
double nsPerCall(int n, int passes, const std::function<int(int)>& f) {
  if (n == 0) return 0.0;
  std::vector<double> t;
  for (int p = 0; p <= passes; ++p) {
    int acc = 0;
    const double t0 = threadSeconds();
    for (int i = 0; i < n; ++i) acc += f(i);
    const double dt = threadSeconds() - t0;
    g_sink = g_sink + acc;
    if (p > 0) t.push_back(1e9 * dt / n);  // pass 0 warms up
  }
  std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
  return t[t.size() / 2];
}

struct NamedMesh {
  std::string name;
  cw::TriangleMesh mesh;
};

std::vector<NamedMesh> loadDir(const std::string& dir) {
  std::vector<NamedMesh> out;
  if (!std::filesystem::is_directory(dir)) return out;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".stl" || e.path().extension() == ".STL") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    std::vector<std::string> warnings;
    out.push_back({f.stem().string(), cw::loadMesh(f.string(), Vec3::Ones(), &warnings)});
  }
  return out;
}

double meshRadius(const cw::TriangleMesh& m) {
  double r = 0.0;
  for (const Vec3& v : m.vertices) r = std::max(r, v.norm());
  return r;
}

Pose randomPose(std::mt19937_64& rng, double reach) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Pose p;
  p.R = Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
  Vec3 t;
  do t = Vec3(u(rng), u(rng), u(rng));
  while (t.squaredNorm() > 1.0);
  p.t = reach * t;
  return p;
}

enum Bucket { kHullsApart, kHullOnly, kColliding, kBuckets };
const char* const kBucketNames[] = {"hulls apart", "hull only", "colliding"};

struct Case {
  int a, b;
  Pose pa, pb;
  Bucket bucket;
};

// The exact stage with its choices open, on the public pieces (trees, SAT, GJK): the library's
// meshesIntersect runs the measured winner.
enum class TriTest { SatThenGjk, GjkOnly, SatOnly };

template <bool kFull>
bool exactStage(const cw::LinkGeometry& a, const cw::LinkGeometry& b, const Pose& b_in_a, TriTest tri) {
  const cw::Tolerances tol;
  const double scale = a.boundingRadius() + b.boundingRadius() + b_in_a.t.norm();
  const double slack = tol.gjk_absolute * scale;
  const auto& ta = a.triangles();
  const auto& tb = b.triangles();
  return cw::forEachOverlap<kFull>(
      a.tree(), b.tree(), b_in_a,
      [&](int i, int j) {
        if (tri != TriTest::GjkOnly) {
          const Vec3 vb[3] = {b_in_a * tb[j].v[0], b_in_a * tb[j].v[1], b_in_a * tb[j].v[2]};
          if (cw::detail::trianglesSeparated(ta[i].v, vb, slack)) return false;
          if (tri == TriTest::SatOnly) return true;
        }
        cw::SimplexCache cache;
        return cw::gjkIntersect(ta[i], Pose::identity(), tb[j], b_in_a, tol, cache).intersecting;
      },
      slack);
}

void benchRobot(const std::string& robot, const std::vector<NamedMesh>& meshes, bool quick) {
  if (meshes.empty()) {
    std::printf("%s: no meshes found, skipped\n", robot.c_str());
    return;
  }
  const int passes = quick ? 3 : 7;
  std::printf("\n== %s ==\n", robot.c_str());
  std::printf("%-22s %9s %12s %12s %12s %6s\n", "mesh", "triangles", "build us", "tree us", "hull us", "depth");
  std::vector<cw::LinkGeometry> geoms;
  for (const auto& m : meshes) {
    const int reps = quick ? 5 : 21;
    std::vector<double> build, tree, hull;
    for (int r = 0; r < reps; ++r) {
      double t0 = threadSeconds();
      const cw::LinkGeometry g(m.mesh);
      build.push_back(threadSeconds() - t0);
      std::vector<cw::Aabb> boxes;
      for (const auto& t : g.triangles()) {
        cw::Aabb b;
        for (const Vec3& v : t.v) b.grow(v);
        boxes.push_back(b);
      }
      t0 = threadSeconds();
      const cw::AabbTree tr(boxes);
      tree.push_back(threadSeconds() - t0);
      t0 = threadSeconds();
      const cw::ConvexHull h(m.mesh.vertices);
      hull.push_back(threadSeconds() - t0);
      g_sink = g_sink + tr.nodeCount() + static_cast<int>(h.vertices().size());
    }
    for (auto* v : {&build, &tree, &hull}) std::nth_element(v->begin(), v->begin() + v->size() / 2, v->end());
    geoms.emplace_back(m.mesh);
    std::printf("%-22s %9zu %12.1f %12.1f %12.1f %6d\n", m.name.c_str(), m.mesh.triangles.size(),
                1e6 * build[build.size() / 2], 1e6 * tree[tree.size() / 2], 1e6 * hull[hull.size() / 2],
                geoms.back().tree().depth());
  }

  // Cases.
  std::mt19937_64 rng(2024);
  const cw::Tolerances tol;
  const int per_pair = quick ? 40 : 200;
  std::vector<Case> cases;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    for (std::size_t j = i; j < meshes.size(); ++j) {
      const double reach = meshRadius(meshes[i].mesh) + meshRadius(meshes[j].mesh);
      for (int c = 0; c < per_pair; ++c) {
        Case k{static_cast<int>(i), static_cast<int>(j), Pose(), Pose(), kColliding};
        for (int draw = 0; draw < 100; ++draw) {
          k.pa = randomPose(rng, 0.3 * reach);
          k.pb = randomPose(rng, reach);
          k.pb.t += k.pa.t;
          if (c % 3 != 2) break;
          if (cw::meshesIntersect(geoms[i], k.pa, geoms[j], k.pb, tol, cw::GeometryMode::Hull) &&
              !cw::meshesIntersect(geoms[i], k.pa, geoms[j], k.pb, tol, cw::GeometryMode::Mesh))
            break;
        }
        if (c % 3 == 1) {
          const cw::DistanceResult d = cw::meshDistance(geoms[i], k.pa, geoms[j], k.pb, tol);
          std::uniform_real_distribution<double> f(0.8, 1.2);
          if (d.distance > 0.0) k.pb.t -= d.distance * f(rng) * d.normal;
        }
        const bool hull = cw::meshesIntersect(geoms[i], k.pa, geoms[j], k.pb, tol, cw::GeometryMode::Hull);
        const bool mesh = cw::meshesIntersect(geoms[i], k.pa, geoms[j], k.pb, tol, cw::GeometryMode::Mesh);
        k.bucket = !hull ? kHullsApart : mesh ? kColliding : kHullOnly;
        cases.push_back(k);
      }
    }
  std::vector<Case> by[kBuckets];
  for (const Case& k : cases) by[k.bucket].push_back(k);
  std::printf("\n%zu cases: %zu hulls apart, %zu hull only, %zu colliding\n", cases.size(), by[0].size(), by[1].size(),
              by[2].size());

  // The library's queries, per bucket and over all cases.
  std::printf("\n%-34s %12s %12s %12s %12s\n", "ns per link-link query", kBucketNames[0], kBucketNames[1],
              kBucketNames[2], "all");
  const auto row = [&](const char* name, const std::function<int(const Case&)>& f) {
    std::printf("%-34s", name);
    for (int b = 0; b < kBuckets; ++b)
      std::printf(" %12.0f", nsPerCall(static_cast<int>(by[b].size()), passes, [&](int i) { return f(by[b][i]); }));
    std::printf(" %12.0f\n", nsPerCall(static_cast<int>(cases.size()), passes, [&](int i) { return f(cases[i]); }));
  };
  row("meshesIntersect Hull", [&](const Case& k) {
    return cw::meshesIntersect(geoms[k.a], k.pa, geoms[k.b], k.pb, tol, cw::GeometryMode::Hull);
  });
  row("meshesIntersect Mesh", [&](const Case& k) {
    return cw::meshesIntersect(geoms[k.a], k.pa, geoms[k.b], k.pb, tol, cw::GeometryMode::Mesh);
  });
  row("meshesIntersect Mesh, padding 1cm", [&](const Case& k) {
    return cw::meshesIntersect(geoms[k.a], k.pa, geoms[k.b], k.pb, tol, cw::GeometryMode::Mesh, 0.01);
  });
  row("meshDistance", [&](const Case& k) {
    return cw::meshDistance(geoms[k.a], k.pa, geoms[k.b], k.pb, tol).distance > 0.0;
  });
  row("meshDistance, relative error 0.2", [&](const Case& k) {
    return cw::meshDistance(geoms[k.a], k.pa, geoms[k.b], k.pb, tol, 0.2).distance > 0.0;
  });

  // The exact stage alone (no hull test) on the cases whose hulls overlap, one choice varied at a time
  // from the library's default (SAH split, leaf 3, 6 box axes, SAT then GJK).
  std::printf("\n%-34s %12s %12s\n", "exact stage alone, ns", kBucketNames[1], kBucketNames[2]);
  struct Variant {
    const char* name;
    cw::TreeBuildOptions options;
    bool full;
    TriTest tri;
  };
  const Variant variants[] = {
      {"SAH, leaf 3, 6 axes, SAT+GJK", {cw::TreeSplit::Sah, 3}, false, TriTest::SatThenGjk},
      {"SAH, leaf 1", {cw::TreeSplit::Sah, 1}, false, TriTest::SatThenGjk},
      {"SAH, leaf 2", {cw::TreeSplit::Sah, 2}, false, TriTest::SatThenGjk},
      {"SAH, leaf 4", {cw::TreeSplit::Sah, 4}, false, TriTest::SatThenGjk},
      {"median, leaf 1", {cw::TreeSplit::Median, 1}, false, TriTest::SatThenGjk},
      {"median, leaf 3", {cw::TreeSplit::Median, 3}, false, TriTest::SatThenGjk},
      {"SAH, leaf 3, 15 axes", {cw::TreeSplit::Sah, 3}, true, TriTest::SatThenGjk},
      {"SAH, leaf 3, GJK only", {cw::TreeSplit::Sah, 3}, false, TriTest::GjkOnly},
      {"SAH, leaf 3, SAT only", {cw::TreeSplit::Sah, 3}, false, TriTest::SatOnly},
  };
  for (const Variant& v : variants) {
    std::vector<cw::LinkGeometry> g;
    for (const auto& m : meshes) g.emplace_back(m.mesh, v.options);
    std::printf("%-34s", v.name);
    for (int b = kHullOnly; b < kBuckets; ++b) {
      int disagreements = 0;
      const double ns = nsPerCall(static_cast<int>(by[b].size()), passes, [&](int i) {
        const Case& k = by[b][i];
        const Pose b_in_a = cw::relativePose(k.pa, k.pb);
        const bool hit = v.full ? exactStage<true>(g[k.a], g[k.b], b_in_a, v.tri)
                                : exactStage<false>(g[k.a], g[k.b], b_in_a, v.tri);
        disagreements += hit != (b == kColliding);
        return static_cast<int>(hit);
      });
      std::printf(" %12.0f", ns);
      if (disagreements) std::printf(" (%d disagree)", disagreements);
    }
    std::printf("\n");
  }
}

void benchSelfCollision(const std::string& robot, const std::string& urdf, const std::string& srdf, bool quick) {
  if (!std::filesystem::exists(urdf)) {
    std::printf("%s: %s not found, skipped\n", robot.c_str(), urdf.c_str());
    return;
  }
  const cw::RobotModel model = cw::loadRobot(urdf, srdf);
  std::vector<std::unique_ptr<cw::LinkGeometry>> links(model.linkCount());
  for (int i = 0; i < model.linkCount(); ++i)
    if (!model.link(i).collisions.empty())
      links[i] = std::make_unique<cw::LinkGeometry>(model.link(i).collisions, model.meshes());
  std::vector<std::pair<int, int>> skip = cw::adjacentLinkPairs(model);
  for (const auto& d : model.disabledCollisions()) skip.emplace_back(d.link_a, d.link_b);
  std::sort(skip.begin(), skip.end());
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < model.linkCount(); ++i)
    for (int j = i + 1; j < model.linkCount(); ++j)
      if (links[i] && links[j] && !std::binary_search(skip.begin(), skip.end(), std::make_pair(i, j)))
        pairs.emplace_back(i, j);
  const int states = quick ? 1000 : 10000;
  std::mt19937_64 rng(7);
  std::vector<std::vector<Pose>> poses(states, std::vector<Pose>(model.linkCount()));
  std::vector<double> q(model.variableCount());
  for (int s = 0; s < states; ++s) {
    for (int v = 0; v < model.variableCount(); ++v) {
      const auto& var = model.variables()[v];
      const double lo = std::isfinite(var.lower) ? var.lower : -M_PI, hi = std::isfinite(var.upper) ? var.upper : M_PI;
      q[v] = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
    cw::computeLinkPoses(model, q.data(), poses[s].data());
  }
  const cw::Tolerances tol;
  const int passes = quick ? 3 : 5;
  std::printf("\n== %s self-collision: %d links with geometry, %zu pairs checked, %d states ==\n", robot.c_str(),
              static_cast<int>(std::count_if(links.begin(), links.end(), [](const auto& l) { return l != nullptr; })),
              pairs.size(), states);
  std::printf("%-26s %12s %12s %12s\n", "mode", "ns/state", "ns/pair", "colliding");
  for (const cw::GeometryMode mode : {cw::GeometryMode::Hull, cw::GeometryMode::Mesh})
    for (const bool warm : {false, true}) {
      std::vector<cw::SimplexCache> caches(pairs.size());
      int colliding = 0;
      const double ns = nsPerCall(states, passes, [&](int s) {
        bool any = false;
        for (std::size_t k = 0; k < pairs.size(); ++k) {
          cw::SimplexCache cold;
          const auto [i, j] = pairs[k];
          any |= cw::meshesIntersect(*links[i], poses[s][i], *links[j], poses[s][j], tol, mode, 0.0,
                                     warm ? &caches[k] : &cold);
        }
        return static_cast<int>(any);
      });
      for (int s = 0; s < states; ++s) {
        bool any = false;
        for (const auto& [i, j] : pairs) any |= cw::meshesIntersect(*links[i], poses[s][i], *links[j], poses[s][j], tol, mode);
        colliding += any;
      }
      std::printf("%-26s %12.0f %12.1f %11.1f%%\n",
                  (std::string(mode == cw::GeometryMode::Hull ? "hull" : "mesh") + (warm ? ", warm caches" : ", cold")).c_str(),
                  ns, ns / pairs.size(), 100.0 * colliding / states);
    }
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string shared = CLEARWAY_SHARED_DIR;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--shared") && i + 1 < argc) shared = argv[++i];
    else {
      std::fprintf(stderr, "usage: %s [--quick] [--shared DIR]\n", argv[0]);
      return 2;
    }
  }
  benchRobot("panda", loadDir(shared + "/robots/panda/meshes/collision"), quick);
  benchRobot("ur5", loadDir(shared + "/robots/ur5/meshes/ur5/collision"), quick);
  benchSelfCollision("panda", shared + "/robots/panda/panda.urdf", shared + "/robots/panda/panda.srdf", quick);
  benchSelfCollision("ur5", shared + "/robots/ur5/ur5.urdf", shared + "/robots/ur5/ur5.srdf", quick);
  return 0;
}
