#pragma once
// The answers to a thread's last few segment checks, each kept under its exact ends. OMPL's path simplifier
// asks the same segment again and again (reduceVertices draws pairs of a path's vertices at random, and a
// pass that changes nothing draws them again): on the shared problems a fifth of its motion checks repeat
// one it made, and they take a fifth to a third of its time. A certified answer depends on nothing but the
// segment's ends and the world's snapshot (the owner makes a new memo with each snapshot), so an answer
// kept is the answer that would be computed.
//
// It also keeps the thread's segments certified free, with their margins. The simplifier subdivides a
// path's segments and then asks for segments between their points, which lie on the segments it was given
// (a third of its segments on the shared Panda problems, not counting repeats): such a segment is free
// (MotionChecker::within), an answer sound but not always the one its own check would give (that check
// could stop within the contact distance, where the longer segment's check measured no contact).
#include <clearway/motion/motion.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace clearway::ompl_detail {

/// A small table of the last segments checked (direct-mapped: a new segment replaces the one in its slot),
/// and up to 1,024 segments certified free, in sets by direction.
class SegmentMemo {
 public:
  static constexpr int kSlots = 64;  // (a power of two)

  /// None: it keeps nothing and finds nothing.
  SegmentMemo() = default;
  /// For segments between states of `dimension` entries (≥ 1).
  explicit SegmentMemo(int dimension)
      : dim_(dimension),
        ends_(static_cast<std::size_t>(kSlots) * 2 * dimension),
        slots_(kSlots),
        free_ends_(static_cast<std::size_t>(kFreeSets) * kFreeWays * 2 * dimension),
        free_(static_cast<std::size_t>(kFreeSets) * kFreeWays) {}

  /// The answer kept for q0 → q1 (the same bits), or null. A verdict alone (a contact, not the first) does
  /// not answer a call that locates the first contact; a free segment answers both.
  const MotionResult* find(const double* q0, const double* q1, bool locate) const noexcept {
    if (dim_ <= 0) return nullptr;
    const std::uint64_t h = hash(q0, q1);
    const Slot& s = slots_[slotOf(h)];
    if (!s.used || s.hash != h || (locate && !s.located && !s.result.free)) return nullptr;
    const double* kept = ends(slotOf(h));
    if (std::memcmp(kept, q0, bytes()) != 0 || std::memcmp(kept + dim_, q1, bytes()) != 0) return nullptr;
    return &s.result;
  }

  /// Keeps r as the answer for q0 → q1 (located: r's contact is the first one, as check(.., true) finds it).
  void keep(const double* q0, const double* q1, bool located, const MotionResult& r) noexcept {
    if (dim_ <= 0) return;
    const std::uint64_t h = hash(q0, q1);
    const int k = slotOf(h);
    double* kept = ends(k);
    std::memcpy(kept, q0, bytes());
    std::memcpy(kept + dim_, q1, bytes());
    slots_[k] = Slot{true, located, h, r};
    if (r.free && r.margin > 0.0) keepFree(q0, q1, r.margin);
  }

  /// True when within(p0, p1, margin) holds for one of the segments certified free kept (ends p0, p1, their
  /// margin) that q0 → q1 may lie in: those along the same direction (a set of kFreeWays, found by the
  /// direction's key) whose box of ends holds q0 and q1, with room for roundings far above within()'s. A
  /// segment within one certified free is free (MotionChecker::within), however long ago that one was checked.
  template <class Within>
  bool inFree(const double* q0, const double* q1, Within&& within) const {
    if (dim_ <= 0) return false;
    const std::uint64_t key = directionKey(q0, q1);
    if (key == 0) return false;
    const std::size_t set = static_cast<std::size_t>(key % kFreeSets) * kFreeWays;
    for (std::size_t k = set; k < set + kFreeWays; ++k) {
      const FreeSegment& f = free_[k];
      if (f.key != key) continue;
      const double* p = free_ends_.data() + k * 2 * dim_;
      bool inside = true;
      for (int i = 0; i < dim_ && inside; ++i) {
        const double lo = std::min(p[i], p[dim_ + i]), hi = std::max(p[i], p[dim_ + i]);
        const double room = kBoxRoom * (1.0 + std::abs(lo) + std::abs(hi));
        inside = q0[i] >= lo - room && q0[i] <= hi + room && q1[i] >= lo - room && q1[i] <= hi + room;
      }
      if (inside && within(p, p + dim_, f.margin)) return true;
    }
    return false;
  }

 private:
  struct Slot {
    bool used = false;
    bool located = false;
    std::uint64_t hash = 0;
    MotionResult result;
  };
  std::size_t bytes() const noexcept { return static_cast<std::size_t>(dim_) * sizeof(double); }
  double* ends(int k) noexcept { return ends_.data() + static_cast<std::size_t>(k) * 2 * dim_; }
  const double* ends(int k) const noexcept { return ends_.data() + static_cast<std::size_t>(k) * 2 * dim_; }
  static int slotOf(std::uint64_t h) noexcept { return static_cast<int>(h >> 58); }  // (the top 6 bits)
  // The entries' bit patterns, mixed (each multiplied by an odd constant and folded): equal ends, equal hash.
  std::uint64_t hash(const double* q0, const double* q1) const noexcept {
    std::uint64_t h = 0x243f6a8885a308d3ULL;
    const auto mix = [&](const double* q) {
      for (int i = 0; i < dim_; ++i) {
        std::uint64_t bits;
        std::memcpy(&bits, q + i, sizeof bits);
        h = (h ^ bits) * 0x9e3779b97f4a7c15ULL;
        h ^= h >> 29;
      }
    };
    mix(q0);
    mix(q1);
    return h * 0xbf58476d1ce4e5b9ULL;
  }

  // The segments certified free kept: kFreeSets sets of kFreeWays, a segment in the set of its direction (a
  // segment within another runs along it), the set's oldest replaced. The simplifier asks about a path's
  // segments while it works on it, up to a few hundred segments later on the shared problems (64 sets kept
  // 1432 of the 1756 answers 256 sets give on bookshelf_small_panda's 30 runs).
  static constexpr int kFreeSets = 256, kFreeWays = 4;
  // The room a box of ends leaves, per unit of its coordinates: ends OMPL interpolates on a segment lie
  // within a few roundings (1e-16) of it, far inside this.
  static constexpr double kBoxRoom = 1e-9;
  struct FreeSegment {
    std::uint64_t key = 0;  // its direction's (0: none kept)
    double margin = 0.0;
    std::uint64_t when = 0;  // keepFree calls before it was kept
  };
  // A key of the segment's direction, its unit vector (sign chosen by its first entry of magnitude 1/32 or
  // more) cut to steps of 1/1024 and mixed: parallel segments get the same key unless an entry lies within
  // rounding of a step (a miss, which costs only a check). 0 for a segment of length 0 or not finite.
  std::uint64_t directionKey(const double* q0, const double* q1) const noexcept {
    double norm2 = 0.0;
    for (int i = 0; i < dim_; ++i) norm2 += (q1[i] - q0[i]) * (q1[i] - q0[i]);
    if (!(norm2 > 0.0 && norm2 < INFINITY)) return 0;
    const double norm = std::sqrt(norm2);
    double scale = 1024.0 / norm;
    for (int i = 0; i < dim_; ++i)
      if (std::abs(q1[i] - q0[i]) * 32.0 >= norm) {
        if (q1[i] < q0[i]) scale = -scale;
        break;
      }
    std::uint64_t h = 0x243f6a8885a308d3ULL;
    for (int i = 0; i < dim_; ++i) {
      const auto step = static_cast<std::int64_t>(std::floor((q1[i] - q0[i]) * scale));
      h = (h ^ static_cast<std::uint64_t>(step)) * 0x9e3779b97f4a7c15ULL;
      h ^= h >> 29;
    }
    return h | 1u;  // (never 0)
  }
  void keepFree(const double* q0, const double* q1, double margin) {
    const std::uint64_t key = directionKey(q0, q1);
    if (key == 0) return;
    const std::size_t set = static_cast<std::size_t>(key % kFreeSets) * kFreeWays;
    std::size_t k = set;
    for (std::size_t w = set + 1; w < set + kFreeWays; ++w)
      if (free_[w].when < free_[k].when) k = w;
    std::memcpy(free_ends_.data() + k * 2 * dim_, q0, bytes());
    std::memcpy(free_ends_.data() + k * 2 * dim_ + dim_, q1, bytes());
    free_[k] = FreeSegment{key, margin, ++free_clock_};
  }

  int dim_ = 0;
  std::vector<double> ends_;  // per slot: q0 then q1
  std::vector<Slot> slots_;
  std::vector<double> free_ends_;  // per free segment kept: q0 then q1
  std::vector<FreeSegment> free_;  // per free segment kept: its key and margin
  std::uint64_t free_clock_ = 0;
};

}  // namespace clearway::ompl_detail
