// Outer balls (outer_balls.h), built on a grid in the link frame:
//  1. cells: every triangle is cut into pieces no longer than a step, and the cells of their corners
//     and centres are the surface; the cells no path of unmarked cells joins to the grid's rim are the
//     inside (a closed mesh's solid). The cover is first sought for the surface's items alone (balls deep
//     enough to reach the surface from within mostly hold the inside too, which the proof of step 4
//     checks), and only where that proof fails for the inside's cubes as well (which cost the Panda's links
//     more than half their build time);
//  2. a distance transform gives each cell its depth (to the nearest unmarked cell);
//  3. greedy set cover: a candidate ball at a cell reaches its depth plus half a step; the items it holds
//     whole (a piece's three corners, an inside cube's eight, a surface cell's corner inside the solid)
//     are its gain, and the candidate of most gain is taken until no item is left;
//  4. each ball shrinks to the farthest point it was given, and grows by the rounding and the margin the
//     proof of the inside needs; then LinkGeometry::ballsHoldSolids proves the inside.
// Deep balls reach the surface from within, so a long round link takes few balls a few millimetres
// looser than its surface (the UR5's forearm: 118 balls at 4.7 mm steps), where balls around clusters of
// triangles bulge by their own radius.
#include <clearway/body/outer_balls.h>

#include <clearway/detail/margins.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <queue>
#include <utility>

namespace clearway {
namespace {

// The proof of the inside grows the balls by this fraction of the link's bounding ball, as the parts'
// balls do (part_cover.cpp).
constexpr double kMarginFraction = 1.0 / 1024.0;
// More pieces than this (a few large triangles on a fine grid cost n² each) and the link is not served.
constexpr long kMaxPieces = 1L << 19;  // (about 50 MB of points at most)

// The squared distance transform of one row (Felzenszwalb and Huttenlocher's lower envelope of
// parabolas): d[q] = min_p (q − p)² + f[p].
void distanceRow(const double* f, double* d, int n, std::vector<int>& v, std::vector<double>& z) {
  v.assign(n, 0);
  z.assign(n + 1, 0.0);
  const double inf = std::numeric_limits<double>::infinity();
  const auto meet = [&](int q, int p) {
    return ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * q - 2.0 * p);
  };
  int k = 0;
  z[0] = -inf;
  z[1] = inf;
  for (int q = 1; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;  // (an unreachable parabola never forms the envelope)
    if (!std::isfinite(f[v[k]])) {       // the envelope so far is empty: q starts it
      v[k] = q;
      continue;
    }
    double s = meet(q, v[k]);
    while (k > 0 && s <= z[k]) s = meet(q, v[--k]);
    v[++k] = q;
    z[k] = s;
    z[k + 1] = inf;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    d[q] = std::isfinite(f[v[k]]) ? (q - v[k]) * double(q - v[k]) + f[v[k]] : inf;
  }
}

struct Grid {
  Vec3 origin;
  double step = 0.0;
  int nx = 0, ny = 0, nz = 0;
  int index(int x, int y, int z) const noexcept { return (z * ny + y) * nx + x; }
  int cellOf(const Vec3& p) const noexcept {
    const Vec3 u = (p - origin) / step;
    const auto clamp = [](double v, int n) { return std::clamp(static_cast<int>(std::floor(v)), 0, n - 1); };
    return index(clamp(u.x(), nx), clamp(u.y(), ny), clamp(u.z(), nz));
  }
  struct Cell {
    int x, y, z;
  };
  Cell coordinates(int c) const noexcept { return {c % nx, (c / nx) % ny, c / (nx * ny)}; }
  Vec3 corner(int x, int y, int z) const noexcept { return origin + Vec3(x, y, z) * step; }
  Vec3 center(int c) const noexcept {
    const auto [x, y, z] = coordinates(c);
    return origin + (Vec3(x, y, z) + Vec3::Constant(0.5)) * step;
  }
};

// Groups of at most kGroupSize balls, neighbours together (median splits on the widest axis).
void groupBalls(std::vector<LinkGeometry::Ball>& balls, std::vector<OuterBalls::Group>& groups, double size) {
  std::vector<LinkGeometry::Ball> sorted;
  sorted.reserve(balls.size());
  std::vector<std::pair<int, int>> stack{{0, static_cast<int>(balls.size())}};
  while (!stack.empty()) {
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    if (hi - lo <= OuterBalls::kGroupSize) {
      OuterBalls::Group g{Vec3::Zero(), 0.0, static_cast<int>(sorted.size()), hi - lo};
      for (int i = lo; i < hi; ++i) g.center += balls[i].center;
      g.center /= hi - lo;
      for (int i = lo; i < hi; ++i) {
        g.radius = std::max(g.radius, (balls[i].center - g.center).norm() + balls[i].radius);
        sorted.push_back(balls[i]);
      }
      g.radius = margins::roundedUp(g.radius, size);
      groups.push_back(g);
      continue;
    }
    Aabb box;
    for (int i = lo; i < hi; ++i) box.grow(balls[i].center);
    int axis = 0;
    (box.max - box.min).maxCoeff(&axis);
    const int mid = lo + (hi - lo) / 2;
    std::nth_element(balls.begin() + lo, balls.begin() + mid, balls.begin() + hi,
                     [axis](const auto& a, const auto& b) { return a.center[axis] < b.center[axis]; });
    stack.push_back({mid, hi});
    stack.push_back({lo, mid});
  }
  balls = std::move(sorted);
}

// The balls of buildOuterBalls, covering the items of the surface and, when `inside_items`, of the inside
// cells too; empty when the inside is not proven held.
OuterBalls coverLink(const LinkGeometry& link, const OuterBallOptions& options, bool inside_items) {
  OuterBalls out;
  const std::vector<Triangle>& triangles = link.triangles();
  if (triangles.empty() || !link.primitives().empty() || !(options.step > 0.0) || options.max_cells < 27) return out;
  const Aabb& bounds = link.bounds();
  const Vec3 extent = (bounds.max - bounds.min).cwiseMax(Vec3::Zero());
  double step = std::max(options.step, std::cbrt(extent.prod() / static_cast<double>(options.max_cells)));
  if (!(step > 0.0) || !std::isfinite(step)) return out;
  if (!(extent.maxCoeff() / step <= 1e6)) return out;  // (a flat link metres wide: too many cells, and ints)
  Grid grid;
  grid.step = step;
  grid.origin = bounds.min - Vec3::Constant(1.5 * step);
  const auto cellsAlong = [&](double e) { return static_cast<int>(std::ceil(e / step)) + 3; };
  grid.nx = cellsAlong(extent.x());
  grid.ny = cellsAlong(extent.y());
  grid.nz = cellsAlong(extent.z());
  const long cells = static_cast<long>(grid.nx) * grid.ny * grid.nz;
  if (cells > 4 * options.max_cells) return out;  // (a flat link: its thin sides still get 3 cells)
  const int n = static_cast<int>(cells);

  // 1. The contents of the cells: the pieces of the cut triangles (which the proof needs), and for the
  //    solids the inside cells' cubes and the surface cells' corners inside.
  enum : std::uint8_t { kEmpty = 0, kSurface = 1, kInside = 2 };
  std::vector<std::uint8_t> mark(n, kEmpty);
  // (cell, first point of its item): an item is the points a ball must hold together (a piece's three
  // corners, an inside cube's eight, one corner inside the solid); they follow each other in `points`.
  std::vector<std::pair<int, Vec3>> points;  // (cell, point)
  std::vector<std::pair<int, int>> items;    // (cell, first point); an item ends where the next begins
  double size = 0.0;                         // bounds the coordinates: the rounding's scale
  for (const Triangle& t : triangles)
    for (const Vec3& v : t.v) size = std::max(size, v.norm());
  long piece_count = 0;
  for (const Triangle& t : triangles) {
    const double longest = std::max({(t.v[1] - t.v[0]).norm(), (t.v[2] - t.v[1]).norm(), (t.v[0] - t.v[2]).norm()});
    const int cuts = std::max(1, static_cast<int>(std::ceil(longest / step)));
    piece_count += static_cast<long>(cuts) * cuts;
    if (piece_count > kMaxPieces) return out;
    const Vec3 e1 = t.v[1] - t.v[0], e2 = t.v[2] - t.v[0];
    const auto at = [&](int i, int j) -> Vec3 { return t.v[0] + e1 * (double(i) / cuts) + e2 * (double(j) / cuts); };
    const auto piece = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
      const int cell = grid.cellOf((a + b + c) / 3.0);
      mark[cell] = kSurface;
      mark[grid.cellOf(a)] = mark[grid.cellOf(b)] = mark[grid.cellOf(c)] = kSurface;
      items.push_back({cell, static_cast<int>(points.size())});
      points.push_back({cell, a});
      points.push_back({cell, b});
      points.push_back({cell, c});
    };
    for (int i = 0; i < cuts; ++i)
      for (int j = 0; i + j < cuts; ++j) {
        piece(at(i, j), at(i + 1, j), at(i, j + 1));
        if (i + j + 1 < cuts) piece(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
  }
  if (link.solidCount() > 0) {
    // The outside: unmarked cells joined to the rim through faces. The rest holds the solids' inside.
    std::vector<std::uint8_t> outside(n, 0);
    std::vector<int> stack;
    const auto visit = [&](int x, int y, int z) {
      const int c = grid.index(x, y, z);
      if (mark[c] != kEmpty || outside[c]) return;
      outside[c] = 1;
      stack.push_back(c);
    };
    for (int z = 0; z < grid.nz; ++z)
      for (int y = 0; y < grid.ny; ++y)
        for (int x = 0; x < grid.nx; ++x)
          if (x == 0 || y == 0 || z == 0 || x == grid.nx - 1 || y == grid.ny - 1 || z == grid.nz - 1) visit(x, y, z);
    while (!stack.empty()) {
      const int c = stack.back();
      stack.pop_back();
      const auto [x, y, z] = grid.coordinates(c);
      if (x > 0) visit(x - 1, y, z);
      if (x + 1 < grid.nx) visit(x + 1, y, z);
      if (y > 0) visit(x, y - 1, z);
      if (y + 1 < grid.ny) visit(x, y + 1, z);
      if (z > 0) visit(x, y, z - 1);
      if (z + 1 < grid.nz) visit(x, y, z + 1);
    }
    // Corners inside the solid, asked once per grid vertex.
    const int vx = grid.nx + 1, vy = grid.ny + 1;
    std::vector<std::int8_t> inside_corner(static_cast<std::size_t>(vx) * vy * (grid.nz + 1), -1);
    const auto cornerInside = [&](int x, int y, int z) {
      std::int8_t& known = inside_corner[(static_cast<std::size_t>(z) * vy + y) * vx + x];
      if (known < 0) known = link.containsPoint(grid.corner(x, y, z)) ? 1 : 0;
      return known == 1;
    };
    for (int z = 0; z < grid.nz; ++z)
      for (int y = 0; y < grid.ny; ++y)
        for (int x = 0; x < grid.nx; ++x) {
          const int c = grid.index(x, y, z);
          if (mark[c] == kEmpty && outside[c]) continue;
          if (mark[c] == kEmpty) mark[c] = kInside;
          if (mark[c] == kInside && !inside_items) continue;  // (it still counts for the depth)
          if (mark[c] == kInside) items.push_back({c, static_cast<int>(points.size())});
          for (int k = 0; k < 8; ++k) {
            const int X = x + (k & 1), Y = y + ((k >> 1) & 1), Z = z + ((k >> 2) & 1);
            if (mark[c] == kSurface && !cornerInside(X, Y, Z)) continue;
            if (mark[c] == kSurface) items.push_back({c, static_cast<int>(points.size())});
            points.push_back({c, grid.corner(X, Y, Z)});
          }
        }
  }
  const int item_count = static_cast<int>(items.size());
  items.push_back({-1, static_cast<int>(points.size())});  // (the end of the last item)
  // The items of cell c: order[first[c]], ..., order[first[c + 1] − 1] (then renumbered first[c], ...).
  std::vector<int> first(n + 1, 0), order(item_count);
  for (int i = 0; i < item_count; ++i) ++first[items[i].first + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  {
    std::vector<int> at(first.begin(), first.end() - 1);
    for (int i = 0; i < item_count; ++i) order[at[items[i].first]++] = i;
  }
  {  // Items and their points renumbered in cell order: a cell's items lie together in memory.
    std::vector<std::pair<int, int>> by_cell;
    std::vector<std::pair<int, Vec3>> cell_points;
    by_cell.reserve(items.size());
    cell_points.reserve(points.size());
    for (int k = 0; k < item_count; ++k) {
      const int i = order[k];
      by_cell.push_back({items[i].first, static_cast<int>(cell_points.size())});
      cell_points.insert(cell_points.end(), points.begin() + items[i].second, points.begin() + items[i + 1].second);
    }
    by_cell.push_back({-1, static_cast<int>(cell_points.size())});
    items.swap(by_cell);
    points.swap(cell_points);
  }
  std::vector<double> reach(n, 0.0);  // how far a cell's points lie from its centre
  for (const auto& [c, p] : points) reach[c] = std::max(reach[c], (p - grid.center(c)).norm());
  // (A cell whose centre lies farther than a ball's radius and this from its centre holds none of its items.)
  const double max_reach = *std::max_element(reach.begin(), reach.end());

  // 2. Depth: the squared distance, in steps, from each marked cell to the nearest unmarked one.
  std::vector<double> depth(n);
  const double inf = std::numeric_limits<double>::infinity();
  for (int c = 0; c < n; ++c) depth[c] = mark[c] == kEmpty ? 0.0 : inf;
  {
    std::vector<double> f, d, z;
    std::vector<int> v;
    const auto pass = [&](int count, int stride, int lines, auto&& start) {
      f.resize(count);
      d.resize(count);
      for (int l = 0; l < lines; ++l) {
        const int s = start(l);
        for (int i = 0; i < count; ++i) f[i] = depth[s + i * stride];
        distanceRow(f.data(), d.data(), count, v, z);
        for (int i = 0; i < count; ++i) depth[s + i * stride] = d[i];
      }
    };
    const int nx = grid.nx, ny = grid.ny, nz = grid.nz;
    pass(nx, 1, ny * nz, [&](int l) { return l * nx; });
    pass(ny, nx, nx * nz, [&](int l) { return (l / nx) * nx * ny + l % nx; });
    pass(nz, nx * ny, nx * ny, [&](int l) { return l; });
  }

  // 3. Greedy cover of the items by candidate balls.
  std::vector<int> candidates;
  for (int z = 0; z < grid.nz; ++z)
    for (int y = 0; y < grid.ny; ++y)
      for (int x = 0; x < grid.nx; ++x) {
        const int c = grid.index(x, y, z);
        if (mark[c] == kEmpty) continue;
        bool ridge = true;  // no neighbour deeper: the discrete medial axis
        for (int k = 0; k < 27 && ridge; ++k) {
          const int X = x + k % 3 - 1, Y = y + (k / 3) % 3 - 1, Z = z + k / 9 - 1;
          if (X >= 0 && Y >= 0 && Z >= 0 && X < grid.nx && Y < grid.ny && Z < grid.nz)
            ridge = depth[grid.index(X, Y, Z)] <= depth[c];
        }
        if (ridge || depth[c] <= 2.0 || (x % 2 == 0 && y % 2 == 0 && z % 2 == 0)) candidates.push_back(c);
      }
  std::vector<std::uint8_t> held(item_count, 0);  // per item: a chosen ball holds it
  std::vector<int> open(n);                       // per cell: how many of its items no ball holds yet
  std::vector<int> row_open(static_cast<std::size_t>(grid.ny) * grid.nz, 0);  // per row of cells along x
  for (int c = 0; c < n; ++c) {
    open[c] = first[c + 1] - first[c];
    row_open[c / grid.nx] += open[c];
  }
  const double slack = 0.5 * step;
  const auto radiusAt = [&](int c) { return std::sqrt(depth[c]) * step + slack; };
  // Calls f(y, z, xa, xb) for each row of cells whose centres [xa, xb] may lie within `within` (metres) of
  // cell c's centre: the ball's cube cut to its rows' chords (in cells, rounded outwards).
  const auto forRows = [&](int c, double within, auto&& f) {
    const auto [x0, y0, z0] = grid.coordinates(c);
    const double w = within / step;
    const int span = static_cast<int>(std::ceil(w)) + 1;
    for (int z = std::max(0, z0 - span); z <= std::min(grid.nz - 1, z0 + span); ++z)
      for (int y = std::max(0, y0 - span); y <= std::min(grid.ny - 1, y0 + span); ++y) {
        const double dy = y - y0, dz = z - z0, chord = w * w - dy * dy - dz * dz;
        if (chord < 0.0) continue;
        const int half = static_cast<int>(std::sqrt(chord)) + 1;
        f(y, z, std::max(0, x0 - half), std::min(grid.nx - 1, x0 + half));
      }
  };
  // The items a candidate would newly hold (into `take` when given): whole cells where the cell's reach
  // settles it, else item by item.
  const auto gain = [&](int c, std::vector<int>* take) {
    const Vec3 o = grid.center(c);
    const double r = radiusAt(c);
    int count = 0;
    forRows(c, r + max_reach, [&](int y, int z, int xa, int xb) {
      if (row_open[z * grid.ny + y] == 0) return;
      for (int x = xa; x <= xb; ++x) {
        const int e = grid.index(x, y, z);
        if (open[e] == 0) continue;
        const double d = (grid.center(e) - o).norm();
        if (d - reach[e] > r) continue;
        const bool whole = d + reach[e] <= r;
        for (int i = first[e]; i < first[e + 1]; ++i) {  // (items are numbered in cell order)
          if (held[i]) continue;
          bool in = whole;
          if (!in) {
            in = true;
            for (int p = items[i].second; p < items[i + 1].second && in; ++p)
              in = (points[p].second - o).squaredNorm() <= r * r;
          }
          if (!in) continue;
          ++count;
          if (take) take->push_back(i);
        }
      }
    });
    return count;
  };
  // Lazy greedy: a candidate's key bounds its gain from above, at first the items of the cells its ball
  // may reach (prefix sums along each row), later its gain when last counted (gains only fall as items are
  // held).
  const std::size_t row_length = static_cast<std::size_t>(grid.nx) + 1;
  std::vector<int> row_sum(row_length * grid.ny * grid.nz, 0);  // items of a row's first x cells
  for (int c = 0; c < n; ++c) {
    const std::size_t at = static_cast<std::size_t>(c / grid.nx) * row_length + c % grid.nx;
    row_sum[at + 1] = row_sum[at] + first[c + 1] - first[c];
  }
  const auto bound = [&](int c) {
    int total = 0;
    forRows(c, radiusAt(c) + max_reach, [&](int y, int z, int xa, int xb) {
      const std::size_t row = static_cast<std::size_t>(z * grid.ny + y) * row_length;
      total += row_sum[row + xb + 1] - row_sum[row + xa];
    });
    return total;
  };
  std::priority_queue<std::pair<int, int>> queue;  // (key, cell)
  for (int c : candidates) queue.push({bound(c), c});
  // A candidate's items, kept from its first count: a recount drops those held since, without geometry
  // (the items a ball holds never change; only which are held). Long lists, and lists past a total of
  // 8 million items (32 MB), are counted again instead.
  constexpr std::size_t kKeptItems = 4096;
  constexpr std::size_t kKeptTotal = 8u << 20;
  std::size_t kept_total = 0;
  std::vector<std::vector<int>> kept(n);
  std::vector<std::uint8_t> counted(n, 0);
  std::vector<int> take;
  const auto count = [&](int c) -> std::vector<int>& {
    std::vector<int>& list = kept[c];
    if (counted[c] == 1) {  // (2: its list was too long to keep)
      list.erase(std::remove_if(list.begin(), list.end(), [&](int i) { return held[i] != 0; }), list.end());
      return list;
    }
    take.clear();
    gain(c, &take);
    counted[c] = take.size() > kKeptItems || kept_total + take.size() > kKeptTotal ? 2 : 1;
    if (counted[c] == 2) return take;
    kept_total += take.size();
    list = take;
    return list;
  };
  std::vector<std::pair<Vec3, std::vector<int>>> chosen;  // centre, items
  while (!queue.empty()) {
    const auto [was, c] = queue.top();
    queue.pop();
    if (was == 0) break;
    const std::vector<int>& now = count(c);
    const int gained = static_cast<int>(now.size());
    if (!queue.empty() && gained < queue.top().first) {  // gains only fall: recount, take it when still best
      queue.push({gained, c});
      continue;
    }
    const std::vector<int> taken = now;
    kept[c].clear();
    kept[c].shrink_to_fit();
    for (int i : taken) {
      held[i] = 1;
      --open[items[i].first];
      --row_open[items[i].first / grid.nx];
    }
    chosen.push_back({grid.center(c), taken});
  }
  for (int i = 0; i < item_count; ++i)  // items no candidate held: their own balls
    if (!held[i]) chosen.push_back({points[items[i].second].second, {i}});

  // 4. Shrink to the points given, grow by the rounding of the cut and the margin, prove the inside.
  for (const auto& [o, given] : chosen) {
    double r = 0.0;
    for (int i : given)
      for (int p = items[i].second; p < items[i + 1].second; ++p) r = std::max(r, (points[p].second - o).norm());
    // (The cut's corners err by a few ε of the coordinates; kRounding of 4·size is far above them.)
    out.balls.push_back({o, margins::roundedUp(r, 4.0 * (size + o.norm()))});
  }
  // The points a ball was given include every corner of its cells inside a solid, but a sliver of the
  // solid in a surface cell may hold no corner: where the proof finds one uncovered, the balls grow by a
  // quarter step at a time (a step covers any sliver of its cell).
  const double margin = kMarginFraction * link.sphereRadius();
  for (int grown = 0;; ++grown) {
    if (link.ballsHoldSolids(out.balls, margin)) break;
    // (A cover of the surface alone grows none: the cover with the inside is tighter than one grown.)
    if (grown == (inside_items ? 4 : 0)) return OuterBalls{};
    for (LinkGeometry::Ball& b : out.balls) b.radius += 0.25 * step;
  }
  for (LinkGeometry::Ball& b : out.balls) b.radius += margin;
  out.cell = step;
  groupBalls(out.balls, out.groups, size);
  return out;
}

}  // namespace

OuterBalls buildOuterBalls(const LinkGeometry& link, const OuterBallOptions& options) {
  if (link.solidCount() > 0) {
    OuterBalls surface = coverLink(link, options, false);
    if (surface.proven()) return surface;
  }
  return coverLink(link, options, true);
}

}  // namespace clearway
