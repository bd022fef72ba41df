// VersionedAabbTree and the persistent AVL tree under it: random edit sequences checked against brute
// force over the live items (fixed seeds), old versions after later edits, readers on other threads
// while a writer edits, and PersistentMap against std::map.
#include <clearway/detail/persistent_avl.h>
#include <clearway/detail/persistent_map.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/tree/versioned_tree.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "tree/mesh_reference.h"

namespace clearway {
namespace {

using Tree = VersionedAabbTree<int>;
using Key = Tree::Key;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The AVL height bound with room for rounding: 1.4405·log₂(n + 2) − 0.3277 < this.
double heightBound(int size) { return 1.45 * std::log2(size + 2.0) + 1.0; }

// ---- Brute force -----------------------------------------------------------------------------------------

struct Live {
  Key key;
  Aabb box;
  int id;
};
using LiveSet = std::vector<Live>;

// Mostly ordinary boxes, and flat ones, boxes sharing one centre, boxes at ±0 and, with any_scale, tiny,
// subnormal and huge ones. (A huge box makes the oriented test's rounding margin huge, and with it every
// node within reach of the oriented box's own axes: without them, those axes prune.)
Aabb randomBox(std::mt19937_64& rng, bool any_scale = true) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  double kind = unit(rng);
  if (!any_scale && kind >= 0.50 && kind < 0.70) kind = 0.9;
  const Vec3 c(u(rng), u(rng), u(rng));
  const Vec3 h(unit(rng), unit(rng), unit(rng));
  if (kind < 0.50) return Aabb::fromCenterHalf(10.0 * c, 1.5 * h.cwiseProduct(h));
  if (kind < 0.57) return Aabb::fromCenterHalf(1e-300 * c, 1e-301 * h);
  if (kind < 0.60) return Aabb::ofPoint(1e-310 * c);
  if (kind < 0.66) return Aabb::fromCenterHalf(1e250 * c, 1e249 * h);
  if (kind < 0.70) {  // a bar through everything along one axis
    Aabb b = Aabb::fromCenterHalf(10.0 * c, 0.2 * h);
    const int axis = static_cast<int>(3 * unit(rng)) % 3;
    b.min[axis] = -1e250;
    b.max[axis] = 1e250;
    return b;
  }
  if (kind < 0.80) return Aabb::fromCenterHalf(Vec3(1.0, -2.0, 3.0), 2.0 * h);
  if (kind < 0.85) return Aabb::fromMinMax(Vec3(-0.0, -0.0, 0.0), Vec3(-0.0, 0.0, h.z()));
  Aabb b = Aabb::fromCenterHalf(10.0 * c, h);
  b.max.z() = b.min.z();  // flat
  return b;
}

Aabb randomQuery(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-12.0, 12.0), unit(0.0, 1.0);
  return Aabb::fromCenterHalf(Vec3(u(rng), u(rng), u(rng)), 3.0 * Vec3(unit(rng), unit(rng), unit(rng)).cwiseAbs2());
}

Pose randomPose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  return Pose{tree_ref::randomRotation(rng), Vec3(u(rng), u(rng), u(rng))};
}

std::vector<int> sortedIds(std::vector<int> ids) {
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::vector<int> overlapping(const LiveSet& live, const Aabb& q) {
  std::vector<int> ids;
  for (const Live& l : live)
    if (overlaps(l.box, q)) ids.push_back(l.id);
  return sortedIds(ids);
}

std::vector<int> within(const LiveSet& live, const Aabb& q, double cutoff) {
  std::vector<int> ids;
  for (const Live& l : live)
    if (boxDistance(l.box, q) <= cutoff) ids.push_back(l.id);
  return sortedIds(ids);
}

// The oriented form's per-item test, as the tree applies it to every node.
struct OrientedReference {
  OrientedReference(const Aabb& local, const Pose& pose, const Aabb& tree_bounds)
      : local(local),
        pose(pose),
        bounds(transformed(local, pose)),
        test(pose, 0.0, detail::treePairScale(tree_bounds, local, pose)),
        placed(test.place(local)) {}

  double lowerBound(const Aabb& b) const { return std::max(boxDistance(b, bounds), test.gap(b, placed)); }

  // True when the item's box certainly comes within `cutoff` of the oriented box: a point of it (centre
  // or corner) does, or GJK says so for boxes of ordinary size (GJK's tolerances are absolute).
  bool certainlyWithin(const Aabb& b, double cutoff) const {
    const Vec3 c = 0.5 * b.min + 0.5 * b.max;
    for (int k = 0; k < 9; ++k) {
      const Vec3 p = k == 8 ? c : Vec3(k & 1 ? b.max.x() : b.min.x(), k & 2 ? b.max.y() : b.min.y(), k & 4 ? b.max.z() : b.min.z());
      const Vec3 q = pose.R.transpose() * (p - pose.t) - local.center();
      if ((q.cwiseAbs() - local.halfExtents()).cwiseMax(0.0).norm() <= cutoff - 1e-9) return true;
    }
    if (b.min.cwiseAbs().maxCoeff() > 1e3 || b.max.cwiseAbs().maxCoeff() > 1e3) return false;
    const DistanceResult d = gjkDistance(Box(local.halfExtents()), Pose{pose.R, pose * local.center()}, Box(b.halfExtents()),
                                         Pose{Mat3::Identity(), c});
    return d.distance <= cutoff - 1e-9;
  }

  Aabb local;
  Pose pose;
  Aabb bounds;
  detail::OrientedBoxTest test;
  detail::OrientedBoxTest::PlacedB placed;
};

// Checks every query of `tree` against brute force over `live` on `queries` random query boxes and poses.
void checkAgainstBruteForce(const Tree& tree, const LiveSet& live, std::mt19937_64& rng, int queries,
                            const std::string& where) {
  SCOPED_TRACE(where);
  ASSERT_EQ(tree.size(), static_cast<int>(live.size()));
  ASSERT_EQ(tree.empty(), live.empty());
  ASSERT_LE(tree.height(), heightBound(tree.size()));
  Aabb all;
  for (const Live& l : live) all.merge(l.box);
  ASSERT_EQ(tree.bounds().min, all.min);
  ASSERT_EQ(tree.bounds().max, all.max);
  std::map<int, Aabb> box_of;
  for (const Live& l : live) {
    const int* v = tree.find(l.key);
    ASSERT_NE(v, nullptr);
    ASSERT_EQ(*v, l.id);
    box_of[l.id] = l.box;
  }
  // Every callback receives the item's own box.
  auto sameBox = [&](int id, const Aabb& box) { return box_of.count(id) && box_of[id].min == box.min && box_of[id].max == box.max; };

  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int q = 0; q < queries; ++q) {
    SCOPED_TRACE("query " + std::to_string(q));
    const Aabb query = q == 0 ? Aabb::fromMinMax(Vec3::Constant(-1e300), Vec3::Constant(1e300)) : randomQuery(rng);

    std::vector<int> found;
    bool boxes_ok = true;
    EXPECT_FALSE(tree.query(query, [&](const int& id, const Aabb& box) { found.push_back(id); boxes_ok &= sameBox(id, box); }));
    EXPECT_TRUE(boxes_ok);
    ASSERT_EQ(sortedIds(found), overlapping(live, query));

    // A fixed cutoff: exactly the items within it (box distance only grows from a subtree's box to an item's).
    const double fixed = 2.0 * unit(rng);
    double cutoff = fixed;
    found.clear();
    tree.forEachWithin(query, cutoff, [&](int id, const Aabb& box) { found.push_back(id); boxes_ok &= sameBox(id, box); });
    EXPECT_TRUE(boxes_ok);
    ASSERT_EQ(sortedIds(found), within(live, query, fixed));

    // A cutoff lowered to each item's distance ends at the nearest, with every item within it visited.
    double nearest = kInf;
    for (const Live& l : live) nearest = std::min(nearest, boxDistance(l.box, query));
    cutoff = kInf;
    found.clear();
    tree.forEachWithin(query, cutoff, [&](int id, const Aabb& box) {
      found.push_back(id);
      cutoff = std::min(cutoff, boxDistance(box, query));
    });
    ASSERT_EQ(cutoff, nearest);
    const std::vector<int> visited = sortedIds(found);
    ASSERT_EQ(std::adjacent_find(visited.begin(), visited.end()), visited.end()) << "an item visited twice";
    for (int id : within(live, query, cutoff)) ASSERT_TRUE(std::binary_search(visited.begin(), visited.end(), id)) << id;

    // The oriented form: what is visited passes the per-item test, and everything certainly within the
    // cutoff is visited; with a fixed cutoff and with one lowered as items come.
    const Aabb local = Aabb::fromCenterHalf(Vec3::Zero(), 2.0 * Vec3(unit(rng), unit(rng), 0.01 + unit(rng)));
    const OrientedReference ref(local, randomPose(rng), tree.bounds());
    for (const bool lower : {false, true}) {
      cutoff = lower ? 3.0 : fixed;
      found.clear();
      bool passes = true;
      tree.forEachWithin(local, ref.pose, cutoff, [&](int id, const Aabb& box) {
        found.push_back(id);
        boxes_ok &= sameBox(id, box);
        const double d = ref.lowerBound(box);
        passes &= d <= cutoff;
        if (lower) cutoff = std::min(cutoff, d + 0.25);
      });
      EXPECT_TRUE(boxes_ok);
      EXPECT_TRUE(passes) << "an item beyond the cutoff was visited";
      const std::vector<int> seen = sortedIds(found);
      ASSERT_EQ(std::adjacent_find(seen.begin(), seen.end()), seen.end()) << "an item visited twice";
      for (const Live& l : live)
        if (ref.certainlyWithin(l.box, cutoff))
          ASSERT_TRUE(std::binary_search(seen.begin(), seen.end(), l.id)) << "missed item " << l.id << " lower " << lower;
    }
  }
  std::vector<int> all_ids;
  tree.forEach([&](const int& id, const Aabb& box) {
    all_ids.push_back(id);
    EXPECT_TRUE(sameBox(id, box));
  });
  std::vector<int> live_ids;
  for (const Live& l : live) live_ids.push_back(l.id);
  ASSERT_EQ(sortedIds(all_ids), sortedIds(live_ids));
}

// Random inserts, erases and moves (erase, then insert the same value at a new box), applied to a tree
// and to its brute-force list alike.
struct Editor {
  explicit Editor(std::uint64_t seed, bool any_scale = true) : rng(seed), any_scale(any_scale) {}

  void step(double p_insert = 0.5, double p_erase = 0.25) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double r = unit(rng);
    if (live.empty() || r < p_insert) {
      insert(next_id++);
      return;
    }
    const std::size_t i = std::uniform_int_distribution<std::size_t>(0, live.size() - 1)(rng);
    const Live gone = live[i];
    bool found = false;
    tree = tree.erased(gone.key, &found);
    ASSERT_TRUE(found);
    live[i] = live.back();
    live.pop_back();
    if (r >= p_insert + p_erase) insert(gone.id);
  }

  void insert(int id) {
    const Aabb box = randomBox(rng, any_scale);
    Key key;
    tree = tree.inserted(box, id, &key);
    live.push_back({key, box, id});
  }

  std::mt19937_64 rng;
  bool any_scale;
  Tree tree;
  LiveSet live;
  int next_id = 0;
};

// ---- VersionedAabbTree -----------------------------------------------------------------------------------

TEST(VersionedAabbTree, RandomEditsMatchBruteForce) {
  for (const bool any_scale : {true, false}) {
    SCOPED_TRACE(any_scale ? "any scale" : "ordinary scale");
    Editor editor(1, any_scale);
    std::mt19937_64 rng(2);
    for (int edit = 1; edit <= 2000; ++edit) {
      ASSERT_NO_FATAL_FAILURE(editor.step());
      if (edit % 50 == 0)
        ASSERT_NO_FATAL_FAILURE(checkAgainstBruteForce(editor.tree, editor.live, rng, 8, "after edit " + std::to_string(edit)));
    }
    EXPECT_GT(editor.tree.size(), 300);
  }
}

TEST(VersionedAabbTree, OldVersionsAnswerAsTheyDid) {
  Editor editor(3);
  std::vector<std::pair<Tree, LiveSet>> versions;
  for (int edit = 1; edit <= 2000; ++edit) {
    ASSERT_NO_FATAL_FAILURE(editor.step());
    if (edit % 100 == 0) versions.push_back({editor.tree, editor.live});
  }
  ASSERT_EQ(versions.size(), 20u);
  std::mt19937_64 rng(4);
  for (std::size_t v = 0; v < versions.size(); ++v)
    ASSERT_NO_FATAL_FAILURE(checkAgainstBruteForce(versions[v].first, versions[v].second, rng, 6, "version " + std::to_string(v)));
}

TEST(VersionedAabbTree, ErasingAMissingKeyChangesNothing) {
  Editor editor(5);
  for (int i = 0; i < 200; ++i) editor.insert(editor.next_id++);
  const Key gone = editor.live[17].key;
  bool found = false;
  const Tree without = editor.tree.erased(gone, &found);
  ASSERT_TRUE(found);
  EXPECT_EQ(without.find(gone), nullptr);
  EXPECT_NE(editor.tree.find(gone), nullptr);  // the old version still has it
  for (const Key& missing : {gone, Key()}) {
    found = true;
    const Tree same = without.erased(missing, &found);
    EXPECT_FALSE(found);
    EXPECT_EQ(same.size(), without.size());
    EXPECT_EQ(same.height(), without.height());
    // The same nodes: the items are found at the same addresses.
    for (const Live& l : editor.live)
      if (l.key != gone) EXPECT_EQ(same.find(l.key), without.find(l.key));
  }
  EXPECT_EQ(Tree().erased(gone, &found).size(), 0);
  EXPECT_FALSE(found);
  EXPECT_EQ(Tree().find(gone), nullptr);
  EXPECT_TRUE(Tree().bounds().isEmpty());
  EXPECT_EQ(Tree().height(), 0);
}

TEST(VersionedAabbTree, BuildEqualsIncrementalInsertsAndRefusesBadBoxes) {
  std::mt19937_64 rng(6);
  std::vector<std::pair<Aabb, int>> items;
  for (int i = 0; i < 700; ++i) items.push_back({randomBox(rng), i});
  std::vector<Key> keys;
  const Tree built = Tree::build(items, &keys);
  ASSERT_EQ(keys.size(), items.size());
  Tree incremental;
  LiveSet live;
  for (const auto& [box, id] : items) {
    Key key;
    incremental = incremental.inserted(box, id, &key);
    live.push_back({key, box, id});
  }
  for (std::size_t i = 0; i < items.size(); ++i) {
    ASSERT_NE(built.find(keys[i]), nullptr);
    EXPECT_EQ(*built.find(keys[i]), items[i].second);
    EXPECT_EQ(keys[i], live[i].key) << "a build numbers items as inserting them in input order would";
  }
  std::vector<std::pair<int, Aabb>> a, b;
  built.forEach([&](int id, const Aabb& box) { a.push_back({id, box}); });
  incremental.forEach([&](int id, const Aabb& box) { b.push_back({id, box}); });
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {  // the same key order, so the same sequence
    EXPECT_EQ(a[i].first, b[i].first);
    EXPECT_EQ(a[i].second.min, b[i].second.min);
    EXPECT_EQ(a[i].second.max, b[i].second.max);
  }
  ASSERT_NO_FATAL_FAILURE(checkAgainstBruteForce(built, live, rng, 10, "built"));
  // A version derived from a built tree numbers its items after the built ones.
  Key next;
  const Tree more = built.inserted(Aabb::ofPoint(Vec3::Zero()), 700, &next);
  for (const Key& k : keys) EXPECT_NE(k, next);
  EXPECT_EQ(more.size(), 701);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Aabb bad[] = {Aabb(), Aabb::fromMinMax(Vec3(1, 0, 0), Vec3(0, 1, 1)), Aabb::fromMinMax(Vec3(0, 0, nan), Vec3(1, 1, 1)),
                      Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(kInf, 1, 1)), Aabb::fromMinMax(Vec3(-kInf, 0, 0), Vec3(1, 1, 1))};
  for (const Aabb& box : bad) {
    EXPECT_THROW(built.inserted(box, 1), std::invalid_argument);
    EXPECT_THROW(Tree::build({{Aabb::ofPoint(Vec3::Zero()), 0}, {box, 1}}), std::invalid_argument);
  }
  EXPECT_EQ(Tree::build({}).size(), 0);
}

// insertedAll adds a batch as inserted() one by one would (the same keys, items and key order), whether it
// inserts (a few items into many) or rebuilds (many into few); the version it came from is unchanged.
TEST(VersionedAabbTree, InsertingABatchEqualsInsertingOneByOne) {
  std::mt19937_64 rng(8);
  for (const auto& [before, batch] : {std::pair<int, int>{600, 3}, {600, 400}, {0, 250}, {40, 0}}) {
    SCOPED_TRACE(std::to_string(before) + " items, then " + std::to_string(batch));
    Tree base;
    LiveSet live;
    for (int i = 0; i < before; ++i) {
      Key key;
      const Aabb box = randomBox(rng);
      base = base.inserted(box, i, &key);
      live.push_back({key, box, i});
    }
    std::vector<std::pair<Aabb, int>> items;
    for (int i = 0; i < batch; ++i) items.push_back({randomBox(rng), before + i});
    Tree one_by_one = base;
    std::vector<Key> keys_one;
    for (const auto& [box, id] : items) {
      Key key;
      one_by_one = one_by_one.inserted(box, id, &key);
      keys_one.push_back(key);
    }
    std::vector<Key> keys;
    const Tree all = base.insertedAll(items, &keys);
    ASSERT_EQ(keys, keys_one);
    ASSERT_EQ(all.size(), before + batch);
    EXPECT_EQ(base.size(), before);
    EXPECT_LE(all.height(), heightBound(all.size()));
    std::vector<std::pair<int, Aabb>> a, b;
    all.forEach([&](int id, const Aabb& box) { a.push_back({id, box}); });
    one_by_one.forEach([&](int id, const Aabb& box) { b.push_back({id, box}); });
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].first, b[i].first);
      EXPECT_EQ(a[i].second.min, b[i].second.min);
      EXPECT_EQ(a[i].second.max, b[i].second.max);
    }
    for (int i = 0; i < batch; ++i) live.push_back({keys[i], items[i].first, items[i].second});
    ASSERT_NO_FATAL_FAILURE(checkAgainstBruteForce(all, live, rng, 6, "batch"));
    // Later versions number their items after the batch.
    Key next;
    all.inserted(Aabb::ofPoint(Vec3::Zero()), -1, &next);
    for (const Key& k : keys) EXPECT_NE(k, next);
  }
  // A bad box anywhere in the batch: refused, nothing added.
  const Tree one = Tree().inserted(Aabb::ofPoint(Vec3::Zero()), 0);
  EXPECT_THROW(one.insertedAll({{Aabb::ofPoint(Vec3::Ones()), 1}, {Aabb(), 2}}), std::invalid_argument);
  EXPECT_EQ(one.size(), 1);
}

TEST(VersionedAabbTree, KeysFollowTheCoordinateOrder) {
  // Along each axis, with the other coordinates equal, the Morton order is the order of the coordinate
  // (negative and positive, tiny and huge); −0.0 and +0.0 tie, and the serial breaks the tie.
  const std::vector<double> xs = {-1e300, -7.0, -1.0, -1e-300, -0.0, 0.0, 1e-300, 1.0, 7.0, 1e300};
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<int> order(xs.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::shuffle(order.begin(), order.end(), std::mt19937_64(axis));
    Tree tree;
    for (int i : order) {
      Vec3 p(0.5, 0.5, 0.5);
      p[axis] = xs[i];
      tree = tree.inserted(Aabb::ofPoint(p), i);
    }
    std::vector<double> seen;
    tree.forEach([&](int i, const Aabb&) { seen.push_back(xs[i]); });
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end())) << "axis " << axis;
  }
}

TEST(VersionedAabbTree, ReturningTrueStopsEveryQuery) {
  std::mt19937_64 rng(7);
  Tree tree;
  for (int i = 0; i < 300; ++i) tree = tree.inserted(Aabb::fromCenterHalf(Vec3::Random(), Vec3::Constant(0.3)), i);
  const Aabb everything = Aabb::fromCenterHalf(Vec3::Zero(), Vec3::Constant(5.0));
  int calls = 0;
  EXPECT_TRUE(tree.query(everything, [&](int, const Aabb&) { return ++calls == 3; }));
  EXPECT_EQ(calls, 3);
  calls = 0;
  double cutoff = 10.0;
  EXPECT_TRUE(tree.forEachWithin(everything, cutoff, [&](int, const Aabb&) { return ++calls == 3; }));
  EXPECT_EQ(calls, 3);
  calls = 0;
  EXPECT_TRUE(tree.forEachWithin(everything, randomPose(rng), cutoff, [&](int, const Aabb&) { return ++calls == 3; }));
  EXPECT_EQ(calls, 3);
  // Returning false visits everything and reports no stop.
  calls = 0;
  EXPECT_FALSE(tree.query(everything, [&](int, const Aabb&) { return ++calls < 0; }));
  EXPECT_EQ(calls, 300);
  calls = 0;
  EXPECT_FALSE(tree.forEachWithin(everything, Pose::identity(), cutoff, [&](int, const Aabb&) { return ++calls < 0; }));
  EXPECT_EQ(calls, 300);
}

TEST(VersionedAabbTree, TouchingCounts) {
  // Unit cubes in a row along x, each touching the next; a query touching the last one's far face, an
  // edge or a corner finds it, also at cutoff 0 and as an oriented box turned a quarter about z.
  std::vector<std::pair<Aabb, int>> items;
  for (int i = 0; i < 40; ++i) items.push_back({Aabb::fromMinMax(Vec3(i, 0, 0), Vec3(i + 1, 1, 1)), i});
  const Tree tree = Tree::build(items);
  const Aabb touching[] = {Aabb::fromMinMax(Vec3(40, 0.2, 0.2), Vec3(41, 0.8, 0.8)),   // face
                           Aabb::fromMinMax(Vec3(40, 1, 0.2), Vec3(41, 2, 0.8)),       // edge
                           Aabb::fromMinMax(Vec3(40, 1, 1), Vec3(41, 2, 2))};          // corner
  for (const Aabb& q : touching) {
    std::vector<int> found;
    tree.query(q, [&](int id, const Aabb&) { found.push_back(id); });
    EXPECT_EQ(found, std::vector<int>{39});
    double cutoff = 0.0;
    found.clear();
    tree.forEachWithin(q, cutoff, [&](int id, const Aabb&) { found.push_back(id); });
    EXPECT_EQ(found, std::vector<int>{39});
    // The same box, held in a frame turned a quarter about z (exact in floating point) at its centre.
    Pose quarter;
    quarter.R << 0, -1, 0, 1, 0, 0, 0, 0, 1;
    quarter.t = q.center();
    const Vec3 h = q.halfExtents();
    const Aabb local = Aabb::fromCenterHalf(Vec3::Zero(), Vec3(h.y(), h.x(), h.z()));
    found.clear();
    tree.forEachWithin(local, quarter, cutoff, [&](int id, const Aabb&) { found.push_back(id); });
    EXPECT_EQ(found, std::vector<int>{39});
  }
}

TEST(VersionedAabbTree, ReadersOnOtherThreadsSeeTheirVersions) {
  struct Snapshot {
    Tree tree;
    LiveSet live;
  };
  Editor editor(8);
  for (int i = 0; i < 300; ++i) editor.insert(editor.next_id++);
  const auto old = std::make_shared<const Snapshot>(Snapshot{editor.tree, editor.live});
  std::mutex mutex;
  std::shared_ptr<const Snapshot> current = old;
  std::atomic<bool> done{false};
  std::atomic<int> checks{0}, mismatches{0};

  auto check = [&](const Tree& tree, const LiveSet& live, std::mt19937_64& rng) {
    const Aabb q = randomQuery(rng);
    std::vector<int> found;
    tree.query(q, [&](int id, const Aabb&) { found.push_back(id); });
    if (sortedIds(found) != overlapping(live, q)) ++mismatches;
    double cutoff = 1.0;
    found.clear();
    tree.forEachWithin(q, cutoff, [&](int id, const Aabb&) { found.push_back(id); });
    if (sortedIds(found) != within(live, q, 1.0)) ++mismatches;
    if (tree.size() != static_cast<int>(live.size())) ++mismatches;
    for (std::size_t i = 0; i < live.size(); i += 37)
      if (!tree.find(live[i].key) || *tree.find(live[i].key) != live[i].id) ++mismatches;
    ++checks;
  };
  std::vector<std::thread> readers;
  for (int r = 0; r < 3; ++r)
    readers.emplace_back([&, r] {
      std::mt19937_64 rng(100 + r);
      bool last = false;
      while (!last) {
        last = done.load();
        std::shared_ptr<const Snapshot> s;
        {
          std::lock_guard<std::mutex> lock(mutex);
          s = current;
        }
        const Tree tree = s->tree;  // a copy shares the nodes the writer's versions share
        check(tree, s->live, rng);
        check(old->tree, old->live, rng);
      }
    });
  std::thread writer([&] {
    for (int edit = 0; edit < 5000; ++edit) {
      editor.step(1.0 / 3.0, 1.0 / 3.0);
      auto next = std::make_shared<const Snapshot>(Snapshot{editor.tree, editor.live});
      std::lock_guard<std::mutex> lock(mutex);
      current = std::move(next);
    }
    done = true;
  });
  writer.join();
  for (std::thread& t : readers) t.join();
  EXPECT_EQ(mismatches.load(), 0);
  EXPECT_GE(checks.load(), 6);
  std::mt19937_64 rng(9);
  ASSERT_NO_FATAL_FAILURE(checkAgainstBruteForce(editor.tree, editor.live, rng, 4, "after the writer"));
  ASSERT_NO_FATAL_FAILURE(checkAgainstBruteForce(old->tree, old->live, rng, 4, "the old version"));
}

// ---- The persistent AVL tree and PersistentMap -----------------------------------------------------------

// The summary of a subtree: its number of nodes.
struct CountSummary {
  using Summary = int;
  static int of(const int&, const int* left, const int* right) { return 1 + (left ? *left : 0) + (right ? *right : 0); }
};
using CountedAvl = detail::PersistentAvl<int, int, CountSummary>;

// Checks the AVL invariants of the subtree at n (balance, heights, summaries, key order within
// (lo, hi)); returns its node count.
int checkAvl(const CountedAvl::Node* n, long lo, long hi) {
  if (!n) return 0;
  EXPECT_LT(lo, n->key);
  EXPECT_LT(n->key, hi);
  const int hl = n->left ? n->left->height : 0, hr = n->right ? n->right->height : 0;
  EXPECT_LE(std::abs(hl - hr), 1) << "unbalanced at " << n->key;
  EXPECT_EQ(n->height, 1 + std::max(hl, hr));
  const int count = 1 + checkAvl(n->left.get(), lo, n->key) + checkAvl(n->right.get(), n->key, hi);
  EXPECT_EQ(n->summary, count);
  return count;
}

TEST(PersistentMap, AvlKeepsBalanceAndSummariesThroughEdits) {
  std::mt19937_64 rng(10);
  std::uniform_int_distribution<int> key(0, 999);
  CountedAvl tree;
  std::vector<CountedAvl> versions;
  std::vector<std::map<int, int>> contents;
  std::map<int, int> ref;
  for (int edit = 0; edit < 4000; ++edit) {
    const int k = key(rng);
    if (ref.count(k)) {
      bool found = false;
      tree = tree.erased(k, &found);
      EXPECT_TRUE(found);
      ref.erase(k);
    } else {
      tree = tree.inserted(k, edit);
      ref[k] = edit;
    }
    ASSERT_EQ(checkAvl(tree.root(), -1, 1000), tree.size());
    ASSERT_EQ(tree.size(), static_cast<int>(ref.size()));
    ASSERT_LE(tree.height(), heightBound(tree.size()));
    if (edit % 400 == 0) {
      versions.push_back(tree);
      contents.push_back(ref);
    }
  }
  for (std::size_t v = 0; v < versions.size(); ++v) {
    EXPECT_EQ(checkAvl(versions[v].root(), -1, 1000), static_cast<int>(contents[v].size()));
    std::vector<std::pair<int, int>> seen;
    versions[v].forEach([&](int k, int value) { seen.push_back({k, value}); });
    const std::vector<std::pair<int, int>> expected(contents[v].begin(), contents[v].end());
    EXPECT_EQ(seen, expected) << "version " << v;
  }
  // A balanced build from sorted keys, of every small size; unsorted or repeated keys are refused.
  for (int n = 0; n <= 100; ++n) {
    std::vector<std::pair<int, int>> items;
    for (int i = 0; i < n; ++i) items.push_back({2 * i, i});
    const CountedAvl built = CountedAvl::fromSorted(items);
    EXPECT_EQ(checkAvl(built.root(), -1, 2 * n), n);
    EXPECT_EQ(built.height(), n == 0 ? 0 : static_cast<int>(std::floor(std::log2(n))) + 1);
  }
  EXPECT_THROW(CountedAvl::fromSorted({{1, 0}, {1, 0}}), std::invalid_argument);
  EXPECT_THROW(CountedAvl::fromSorted({{2, 0}, {1, 0}}), std::invalid_argument);
  static_assert(detail::avlMaxHeight(0) == 0 && detail::avlMaxHeight(1) == 1 && detail::avlMaxHeight(2) == 2 &&
                detail::avlMaxHeight(3) == 2 && detail::avlMaxHeight(4) == 3 && detail::avlMaxHeight(7) == 4 &&
                detail::avlMaxHeight(11) == 4 && detail::avlMaxHeight(12) == 5);
}

TEST(PersistentMap, RandomEditsMatchStdMapAndOldVersionsStay) {
  using Map = detail::PersistentMap<std::string, int>;
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> name(0, 299), op(0, 3);
  Map map;
  std::map<std::string, int> ref;
  std::vector<std::pair<Map, std::map<std::string, int>>> versions;
  auto same = [](const Map& m, const std::map<std::string, int>& r) {
    if (m.size() != static_cast<int>(r.size()) || m.empty() != r.empty()) return false;
    for (int i = 0; i < 300; ++i) {
      const std::string k = "obstacle" + std::to_string(i);
      const int* v = m.find(k);
      const auto it = r.find(k);
      if ((v == nullptr) != (it == r.end()) || (v && *v != it->second)) return false;
    }
    std::vector<std::pair<std::string, int>> seen;
    m.forEach([&](const std::string& k, int v) { seen.push_back({k, v}); });
    return seen == std::vector<std::pair<std::string, int>>(r.begin(), r.end());
  };
  for (int edit = 1; edit <= 3000; ++edit) {
    const std::string k = "obstacle" + std::to_string(name(rng));
    const bool present = ref.count(k) > 0;
    switch (op(rng)) {
      case 0:
      case 1:
        if (present) {
          EXPECT_THROW(map.inserted(k, edit), std::invalid_argument);
        } else {
          map = map.inserted(k, edit);
          ref[k] = edit;
        }
        break;
      case 2: {
        bool found = !present;
        map = map.erased(k, &found);
        EXPECT_EQ(found, present);
        ref.erase(k);
        break;
      }
      default:
        map = map.assigned(k, -edit);
        ref[k] = -edit;
    }
    if (edit % 25 == 0) {
      ASSERT_TRUE(same(map, ref)) << "edit " << edit;
      ASSERT_LE(map.height(), heightBound(map.size()));
    }
    if (edit % 150 == 0) versions.push_back({map, ref});
  }
  for (std::size_t v = 0; v < versions.size(); ++v) EXPECT_TRUE(same(versions[v].first, versions[v].second)) << "version " << v;
  // Ascending inserts, the worst order for an unbalanced tree, keep the AVL height (and the destructor's
  // recursion) logarithmic.
  detail::PersistentMap<int, int> big;
  for (int i = 0; i < 100000; ++i) big = big.inserted(i, i);
  EXPECT_EQ(big.size(), 100000);
  EXPECT_LE(big.height(), heightBound(big.size()));
}

}  // namespace
}  // namespace clearway
