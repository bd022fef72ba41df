#include <clearway/scene/self_collision.h>

#include <clearway/serial.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace clearway {
namespace scene_detail {

// What SelfCollisionContext holds.
struct SelfScratch {
  std::vector<BodyPair> bodies;            // per checked pair: its two links' geometry and warm starts
  EnclosingBalls balls;                    // the links' enclosing balls at the current query's poses
  std::vector<int> dear;                   // pairs the cheap rungs left to the hulls (scratch of one query)
  std::vector<int> unsure;                 // pairs the hulls left to the triangles (scratch of one query)
  std::vector<std::uint8_t> table_free;    // per pair: its table called it Free at this query's q
  std::vector<std::uint8_t> bounds_apart;  // per pair: its bounding balls apart at this query's poses
  std::vector<std::pair<int, TrianglePair>> witnesses;  // pairs whose unsure cell has a witness, at this q
  // The tables' look-ups of tabledCollision, kept for the firstCollision at the same q that follows, up to
  // kTabledSlots states later (Scene::areFree asks the tables of a lane's states before their kinematics):
  // each slot's q (every variable), its table_free and witnesses (swapped in and out, never copied), and
  // whether it is still to be used; all by the checker of serial tabled_by.
  struct Tabled {
    std::vector<double> q;
    std::vector<std::uint8_t> table_free;
    std::vector<std::pair<int, TrianglePair>> witnesses;
    bool valid = false;
  };
  static constexpr int kTabledSlots = 8;  // (a power of two)
  std::vector<Tabled> tabled;             // kTabledSlots of them (none in a default context)
  int next_tabled = 0;
  std::uint64_t tabled_by = 0;
  bool slots_fit = false;                  // the slots are sized for tabled_by's robot and pairs
  int last_hit = -1;                       // the pair (index into pairs()) that last collided, tried first; -1: none
  long long pair_tests = 0;  // pairs that reached the narrow phase (bounding spheres not apart), cumulative
  std::uint64_t owner = 0;   // the serial of the checker that made it (its pairs are `bodies`' pairs)
};

}  // namespace scene_detail

namespace {
constexpr double kNoCutoff = std::numeric_limits<double>::infinity();

using scene_detail::SelfScratch;

// The scratch of a context; a default-made (or moved-from) one's is an empty scratch of this thread, which
// holds no warm starts, no balls and no room, so that its queries answer as a fresh context's.
[[gnu::noinline]] SelfScratch& emptyScratch() noexcept {  // (out of line: no thread-local look-up otherwise)
  thread_local SelfScratch none;
  none.last_hit = -1;
  return none;
}
SelfScratch& scratchOf(std::unique_ptr<SelfScratch>& s) noexcept { return s ? *s : emptyScratch(); }

}  // namespace

SelfCollisionContext::SelfCollisionContext() noexcept = default;
SelfCollisionContext::SelfCollisionContext(SelfCollisionContext&&) noexcept = default;
SelfCollisionContext& SelfCollisionContext::operator=(SelfCollisionContext&&) noexcept = default;
SelfCollisionContext::~SelfCollisionContext() = default;
SelfCollisionContext::SelfCollisionContext(std::unique_ptr<SelfScratch> scratch) noexcept
    : scratch_(std::move(scratch)) {}
long long SelfCollisionContext::pairTests() const noexcept { return scratch_ ? scratch_->pair_tests : 0; }

SelfCollision::SelfCollision(std::shared_ptr<const RobotGeometry> geometry, const CollisionFilter& filter,
                             SelfCollisionOptions options)
    : geometry_(std::move(geometry)), options_(std::move(options)), serial_(detail::nextSerial()) {
  if (!geometry_) throw std::invalid_argument("SelfCollision: null robot geometry");
  const int n = geometry_->model().linkCount();
  if (filter.linkCount() != n)
    throw std::invalid_argument("SelfCollision: the filter was made for a robot of " +
                                std::to_string(filter.linkCount()) + " links, not " + std::to_string(n));
  std::vector<double>& pad = options_.link_padding;
  if (pad.empty()) pad.assign(n, 0.0);
  if (static_cast<int>(pad.size()) != n)
    throw std::invalid_argument("SelfCollision: link_padding has " + std::to_string(pad.size()) +
                                " entries for " + std::to_string(n) + " links");
  for (int i = 0; i < n; ++i)
    if (!(pad[i] >= 0.0) || !std::isfinite(pad[i]))
      throw std::invalid_argument("SelfCollision: link_padding of link '" + geometry_->model().link(i).name +
                                  "' is " + std::to_string(pad[i]) + ": must be finite and >= 0");
  std::vector<std::int64_t> pair_a, pair_b;
  for (const auto& [a, b] : filter.enabledPairs()) {
    if (!geometry_->link(a) || !geometry_->link(b)) continue;
    pairs_.push_back({a, b});
    pair_padding_.push_back(pad[a] + pad[b]);
    pair_a.push_back(a);
    pair_b.push_back(b);
  }
  bounds_rows_ = BoundsRows(pair_a, pair_b, pair_padding_, n);
  if (options_.pair_tables) {
    const PairTableOptions table = options_.table_options.within(options_.table_seconds);
    std::vector<PairTable::Request> requests;
    for (std::size_t k = 0; k < pairs_.size(); ++k) requests.push_back({pairs_[k].a, pairs_[k].b, pair_padding_[k]});
    tables_ = PairTable::sharedMany(geometry_, requests, options_.mode, options_.tolerances, options_.held, table);
  }
  free_table_.assign(pairs_.size(), 0);
  for (std::size_t k = 0; k < tables_.size(); ++k) {
    if (!tables_[k]) continue;
    if (tables_[k]->freeOnly())
      free_table_[k] = 1;
    else
      with_table_.push_back(static_cast<int>(k));
  }
}

SelfCollisionContext SelfCollision::makeContext() const {
  auto scratch = std::make_unique<SelfScratch>();
  SelfScratch& c = *scratch;
  c.owner = serial_;
  c.bodies.reserve(pairs_.size());
  for (const LinkPair& p : pairs_) c.bodies.emplace_back(*geometry_->link(p.a), *geometry_->link(p.b));
  c.balls = EnclosingBalls(*geometry_);
  c.dear.reserve(pairs_.size());
  c.unsure.reserve(pairs_.size());
  c.table_free.assign(pairs_.size(), 0);
  c.bounds_apart.assign(pairs_.size() + BoundsRows::kSpare, 0);  // (the lanes' spare bytes past the last pair)
  c.witnesses.reserve(with_table_.size());
  c.tabled.resize(SelfScratch::kTabledSlots);
  for (SelfScratch::Tabled& t : c.tabled) {
    t.q.assign(geometry_->model().variableCount(), 0.0);
    t.table_free.assign(pairs_.size(), 0);
    t.witnesses.reserve(with_table_.size());
  }
  c.tabled_by = serial_;
  c.slots_fit = true;
  return SelfCollisionContext(std::move(scratch));
}

EnclosingBalls* SelfCollision::placeBalls(const Pose* poses, SelfScratch& ctx) const noexcept {
  if (!ctx.balls.madeFor(*geometry_)) return nullptr;  // a default context, or another robot's
  ctx.balls.place(poses);
  return &ctx.balls;
}

bool SelfCollision::pairCollides(int k, const Pose* poses, SelfCollisionContext& context) const noexcept {
  return pairHits(k, poses, scratchOf(context.scratch_), nullptr);
}

bool SelfCollision::pairHits(int k, const Pose* poses, SelfScratch& ctx, EnclosingBalls* balls) const noexcept {
  const Screen s = pairScreen(k, poses, ctx, balls);
  return s == Screen::Unsure ? pairExactly(k, poses, ctx) : s == Screen::Touching;
}

Screen SelfCollision::pairScreen(int k, const Pose* poses, SelfScratch& ctx, EnclosingBalls* balls) const noexcept {
  const Screen cheap = pairScreenCheap(k, poses, ctx, balls);
  return cheap != Screen::Unsure ? cheap : pairScreenDear(k, poses, ctx);
}

Screen SelfCollision::pairScreenCheap(int k, const Pose* poses, SelfScratch& ctx,
                                      EnclosingBalls* balls) const noexcept {
  const LinkPair& p = pairs_[k];
  ++ctx.pair_tests;
  if (balls && balls->apart(p.a, p.b, pair_padding_[k], options_.tolerances)) return Screen::Apart;
  const IntersectQuery q{pair_padding_[k], options_.mode};
  // (A context of another checker of the robot, whose pair k is another pair, asks a fresh pair.)
  if (ctx.owner == serial_ && k < static_cast<int>(ctx.bodies.size()))
    return ctx.bodies[k].screenCheap(poses[p.a], poses[p.b], options_.tolerances, q);
  return BodyPair(*geometry_->link(p.a), *geometry_->link(p.b))
      .screenCheap(poses[p.a], poses[p.b], options_.tolerances, q);
}

Screen SelfCollision::pairScreenDear(int k, const Pose* poses, SelfScratch& ctx) const noexcept {
  const LinkPair& p = pairs_[k];
  const IntersectQuery q{pair_padding_[k], options_.mode};
  if (ctx.owner == serial_ && k < static_cast<int>(ctx.bodies.size()))  // (as in pairScreenCheap)
    return ctx.bodies[k].screenDear(poses[p.a], poses[p.b], options_.tolerances, q);
  return BodyPair(*geometry_->link(p.a), *geometry_->link(p.b))
      .screenDear(poses[p.a], poses[p.b], options_.tolerances, q);
}

bool SelfCollision::pairExactly(int k, const Pose* poses, SelfScratch& ctx) const noexcept {
  const LinkPair& p = pairs_[k];
  if (ctx.owner == serial_ && k < static_cast<int>(ctx.bodies.size()))  // (as in pairScreen)
    return ctx.bodies[k].intersectsExactly(poses[p.a], poses[p.b], options_.tolerances, pair_padding_[k]);
  return BodyPair(*geometry_->link(p.a), *geometry_->link(p.b))
      .intersectsExactly(poses[p.a], poses[p.b], options_.tolerances, pair_padding_[k]);
}

const LinkPair* SelfCollision::firstCollision(const Pose* poses, SelfCollisionContext& context, const double* q,
                                              EnclosingBalls* placed) const noexcept {
  SelfScratch& ctx = scratchOf(context.scratch_);
  const int n = static_cast<int>(pairs_.size());
  // The tables first: a pair they prove colliding ends the query before any geometry is placed (unless
  // tabledCollision looked them up at this q already). A witness (two triangles that touched at the centre
  // of the pair's unsure cell) proves a collision with one triangle test where the search would spend hundreds.
  // Each verdict is kept for the pass below (a context of another checker looks the tables up again).
  const bool kept = ctx.table_free.size() == pairs_.size();
  bool looked_up = false;
  if (q && ctx.tabled_by == serial_ && ctx.slots_fit)
    for (int i = 1; i <= SelfScratch::kTabledSlots; ++i) {  // (the latest first: checkState asks it right before)
      SelfScratch::Tabled& t = ctx.tabled[(ctx.next_tabled - i) & (SelfScratch::kTabledSlots - 1)];
      if (t.valid && std::equal(t.q.begin(), t.q.end(), q)) {
        std::swap(ctx.table_free, t.table_free);
        std::swap(ctx.witnesses, t.witnesses);
        t.valid = false;
        looked_up = true;
        break;
      }
    }
  if (!q) {
    if (kept) std::fill(ctx.table_free.begin(), ctx.table_free.end(), std::uint8_t{0});
    ctx.witnesses.clear();
  } else if (!looked_up) {
    if (const LinkPair* p = lookUp(q, ctx)) return p;
  }
  for (const auto& [k, w] : ctx.witnesses) {
    const LinkPair& p = pairs_[k];
    if (trianglesTouch(*geometry_->link(p.a), poses[p.a], *geometry_->link(p.b), poses[p.b], w, options_.tolerances,
                       pair_padding_[k]))
      return hit(k, ctx);
  }
  EnclosingBalls* balls = placed ? placed : placeBalls(poses, ctx);
  // The enclosing layer's first rung for every pair at once (SIMD lanes): most pairs end here.
  const bool bounds = balls && ctx.bounds_apart.size() == pairs_.size() + BoundsRows::kSpare;
  if (bounds) balls->boundsApart(bounds_rows_, options_.tolerances, ctx.bounds_apart.data());
  // A pair that collided a moment ago probably still does: trying it first ends most colliding queries
  // of a planner exploring near an obstacle after one pair test.
  // (A free-only table, of a wrist's turning link, never ends a query: it is asked after the balls, only for
  // the pairs they leave, where its lookup costs less than the screen it saves.)
  const auto tableFree = [&](int k) {
    if (free_table_[k]) return tabled(k, q) == PairTable::Verdict::Free;
    return kept ? ctx.table_free[k] != 0 : tabled(k, q) == PairTable::Verdict::Free;
  };
  if (ctx.last_hit >= 0 && ctx.last_hit < n && !tableFree(ctx.last_hit) &&
      pairHits(ctx.last_hit, poses, ctx, balls))
    return &pairs_[ctx.last_hit];
  // Three passes, each rung for every pair before the next: the cheap rungs (overlapping cores settle most
  // collisions), then the hulls' GJK of the pairs they left, then the triangles of the pairs the hulls left
  // unsure. A collision an earlier pass settles costs none of the later passes' work on other pairs.
  // (Without room for every pair, pushing would allocate: each pair in full then.)
  const bool passes = static_cast<int>(std::min(ctx.unsure.capacity(), ctx.dear.capacity())) >= n;
  if (passes) ctx.unsure.clear(), ctx.dear.clear();
  // Pair k after the look-ups and the balls: true when it collides (pass one: unless left to the hulls).
  const auto screened = [&](int k) {
    if (free_table_[k] && tableFree(k)) return false;
    if (!passes) return pairHits(k, poses, ctx, balls);
    const Screen s = pairScreenCheap(k, poses, ctx, balls);
    if (s == Screen::Unsure) ctx.dear.push_back(k);
    return s == Screen::Touching;
  };
  bool visited = false;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  if (bounds && kept) {
    // The loop below, eight pairs per step: a table's Free (never a free-only table's: those are asked in
    // screened()) and the balls' apart are bytes of 0 or 1, so the pairs left are the zero bytes of both, and
    // the apart pairs it would count are those not also table-free. Most steps leave none (the UR5's hundred-odd
    // pairs at a free state leave a few), and the pairs left are visited in the same order.
    constexpr std::uint64_t kOnes = 0x0101010101010101ull;
    const auto count = [](std::uint64_t bytes) {  // bytes of 0 or 1: their sum lands in the top byte
      return static_cast<long long>((bytes * kOnes) >> 56);
    };
    for (int base = 0; base < n; base += 8) {
      const int m = std::min(8, n - base);
      std::uint64_t table = 0, apart = 0;
      std::memcpy(&table, ctx.table_free.data() + base, static_cast<std::size_t>(m));
      std::memcpy(&apart, ctx.bounds_apart.data() + base, static_cast<std::size_t>(m));
      const std::uint64_t in = m == 8 ? kOnes : kOnes & ((std::uint64_t{1} << (8 * m)) - 1);
      std::uint64_t left = ~(table | apart) & in;
      apart &= ~table & in;
      if (ctx.last_hit >= base && ctx.last_hit < base + m) {  // (asked above already: not again, not counted)
        const std::uint64_t mine = std::uint64_t{1} << (8 * (ctx.last_hit - base));
        left &= ~mine, apart &= ~mine;
      }
      for (; left != 0; left &= left - 1) {
        const int j = __builtin_ctzll(left) / 8;
        if (screened(base + j)) {
          ctx.pair_tests += count(apart & ((std::uint64_t{1} << (8 * j)) - 1));
          return hit(base + j, ctx);
        }
      }
      ctx.pair_tests += count(apart);
    }
    visited = true;
  }
#endif
  for (int k = 0; k < n && !visited; ++k) {
    if (k == ctx.last_hit || (!free_table_[k] && tableFree(k))) continue;
    if (bounds && ctx.bounds_apart[k]) {  // as pairScreen would have found it: counted, apart
      ++ctx.pair_tests;
      continue;
    }
    if (screened(k)) return hit(k, ctx);
  }
  if (passes) {
    for (int k : ctx.dear) {
      const Screen s = pairScreenDear(k, poses, ctx);
      if (s == Screen::Touching) return hit(k, ctx);
      if (s == Screen::Unsure) ctx.unsure.push_back(k);
    }
    for (int k : ctx.unsure)
      if (pairExactly(k, poses, ctx)) return hit(k, ctx);
  }
  ctx.last_hit = -1;
  return nullptr;
}

const LinkPair* SelfCollision::lookUp(const double* q, SelfScratch& ctx) const noexcept {
  const bool kept = ctx.table_free.size() == pairs_.size();
  if (kept) std::fill(ctx.table_free.begin(), ctx.table_free.end(), std::uint8_t{0});
  ctx.witnesses.clear();
  const bool room = ctx.witnesses.capacity() >= with_table_.size();  // (else keeping one would allocate)
  for (int k : with_table_) {
    TrianglePair w;
    const PairTable::Verdict v = tables_[k]->lookup(q, room ? &w : nullptr);
    if (v == PairTable::Verdict::Colliding) return hit(k, ctx);
    if (kept) ctx.table_free[k] = v == PairTable::Verdict::Free;
    if (w.valid()) ctx.witnesses.emplace_back(k, w);
  }
  return nullptr;
}

const LinkPair* SelfCollision::tabledCollision(const double* q, SelfCollisionContext& context) const noexcept {
  SelfScratch& ctx = scratchOf(context.scratch_);
  if (ctx.tabled_by != serial_) {  // (another checker's verdicts, for its pairs: dropped; its slots' sizes checked)
    ctx.slots_fit = ctx.tabled.size() == SelfScratch::kTabledSlots;
    for (SelfScratch::Tabled& t : ctx.tabled) {
      t.valid = false;
      ctx.slots_fit = ctx.slots_fit && t.q.size() == static_cast<std::size_t>(geometry_->model().variableCount()) &&
                      t.table_free.size() == pairs_.size() && t.witnesses.capacity() >= with_table_.size();
    }
    ctx.tabled_by = serial_;
  }
  if (const LinkPair* p = lookUp(q, ctx)) return p;
  // (Kept only where the context holds this checker's verdicts and room for q and them: else asked again.)
  if (!ctx.slots_fit || ctx.table_free.size() != pairs_.size()) return nullptr;
  SelfScratch::Tabled& t = ctx.tabled[ctx.next_tabled];
  ctx.next_tabled = (ctx.next_tabled + 1) & (SelfScratch::kTabledSlots - 1);
  std::copy(q, q + t.q.size(), t.q.begin());
  std::swap(ctx.table_free, t.table_free);
  std::swap(ctx.witnesses, t.witnesses);
  t.valid = true;
  return nullptr;
}

const LinkPair* SelfCollision::hit(int k, SelfScratch& ctx) const noexcept {
  ctx.last_hit = k;
  return &pairs_[k];
}

void SelfCollision::allCollisions(const Pose* poses, SelfCollisionContext& context, std::vector<LinkPair>& out) const {
  SelfScratch& ctx = scratchOf(context.scratch_);
  EnclosingBalls* balls = placeBalls(poses, ctx);
  for (int k = 0; k < static_cast<int>(pairs_.size()); ++k)
    if (pairHits(k, poses, ctx, balls)) out.push_back(pairs_[k]);
}

DistanceResult SelfCollision::minimumDistance(const Pose* poses, LinkPair* pair, double relative_error) const {
  DistanceResult best;
  best.distance = best.lower_bound = std::numeric_limits<double>::infinity();
  best.status = Status::Separated;
  double lower = best.lower_bound;  // the minimum's lower bound is the least of all pairs' lower bounds
  for (int k = 0; k < static_cast<int>(pairs_.size()); ++k) {
    const LinkPair& p = pairs_[k];
    DistanceResult r = BodyPair(*geometry_->link(p.a), *geometry_->link(p.b))
                           .distance(poses[p.a], poses[p.b], options_.tolerances, {kNoCutoff, relative_error});
    if (isFailure(r.status)) return r;
    r.distance = std::max(0.0, r.distance - pair_padding_[k]);
    r.lower_bound = std::max(0.0, r.lower_bound - pair_padding_[k]);
    lower = std::min(lower, r.lower_bound);
    if (r.distance < best.distance) {
      best = r;
      if (pair) *pair = p;
    }
  }
  best.lower_bound = lower;
  return best;
}

double SelfCollision::penetration(const Pose* poses, SelfCollisionContext& context, LinkPair* pair) const {
  SelfScratch& ctx = scratchOf(context.scratch_);
  double deepest = 0.0;
  EnclosingBalls* balls = placeBalls(poses, ctx);
  for (int k = 0; k < static_cast<int>(pairs_.size()); ++k) {
    if (!pairHits(k, poses, ctx, balls)) continue;
    const LinkPair& p = pairs_[k];
    const double depth = BodyPair(*geometry_->link(p.a), *geometry_->link(p.b))
                             .penetration(poses[p.a], poses[p.b], options_.tolerances, pair_padding_[k]);
    if (std::isnan(depth)) return depth;
    if (depth > deepest) {
      deepest = depth;
      if (pair) *pair = p;
    }
  }
  return deepest;
}

}  // namespace clearway
