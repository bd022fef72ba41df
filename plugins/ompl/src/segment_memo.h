#pragma once
// The answers to a thread's last few segment checks, each kept under its exact ends. OMPL's path simplifier
// asks the same segment again and again (reduceVertices draws pairs of a path's vertices at random, and a
// pass that changes nothing draws them again): on the shared problems a fifth of its motion checks repeat
// one it made, and they take a fifth to a third of its time. A certified answer depends on nothing but the
// segment's ends and the world's snapshot (the owner makes a new memo with each snapshot), so an answer
// kept is the answer that would be computed.
#include <clearway/motion/motion.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace clearway::ompl_detail {

/// A small table of the last segments checked (direct-mapped: a new segment replaces the one in its slot).
class SegmentMemo {
 public:
  static constexpr int kSlots = 64;  // (a power of two)

  /// None: it keeps nothing and finds nothing.
  SegmentMemo() = default;
  /// For segments between states of `dimension` entries (≥ 1).
  explicit SegmentMemo(int dimension)
      : dim_(dimension), ends_(static_cast<std::size_t>(kSlots) * 2 * dimension), slots_(kSlots) {}

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

  int dim_ = 0;
  std::vector<double> ends_;  // per slot: q0 then q1
  std::vector<Slot> slots_;
};

}  // namespace clearway::ompl_detail
