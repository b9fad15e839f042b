// SPDX-License-Identifier: MIT
// VoxelHash: an exact incremental spatial index on a hashed voxel grid, tuned for the
// "nearest point within the association radius" query of contact fusion.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/assert.hpp"
#include "taxel/index/concepts.hpp"

namespace taxel::index {

/// Exact incremental spatial index over a hashed voxel grid.
///
/// Cells are cubes of side 2r for the radius r given at construction, so a ball of radius
/// <= r meets at most a 2x2x2 block of cells; the cell holding the query is read first and
/// the others only when they can still hold a closer point. Layout is flat: an open-addressing
/// table (multiplicative hashing, linear probing, 16-byte slots) maps a cell to a chain of
/// fixed-size 128-byte blocks in one pool; a block holds up to kBlockCapacity points (ids and
/// coordinates side by side). There are no per-cell heap containers, and `move` within a cell
/// rewrites the coordinates in place. Larger radii and k-NN queries work too (exactly), by
/// visiting more cells.
///
/// Complexity: nearest_within(q, r_cfg) reads <= 8 cells; insert/move/erase are O(1) amortised
/// (a move across cells touches two cells). Memory: see `memory_bytes()`; 110-140 bytes per
/// point for double, 70-90 for float, on the fused clouds of fusion_bench (growth slack of
/// the pools included). No allocation in `move` within a cell or in `nearest_within`.
/// Coordinates beyond 2^30 cells from the origin share the outermost cells (still exact,
/// slower). Const queries may run concurrently; writes may not.
/// Not thread-safe for concurrent writes; concurrent const queries are safe.
template <Scalar S>
class VoxelHash {
 public:
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Tuning knobs; defaults suit fusion.
  struct Config {
    /// Of the cell table, in (0, 0.9]. The default keeps probe runs short for the cells a
    /// query finds empty (half of the neighbours on a surface); 16-byte slots make it cheap.
    double max_load_factor = 0.25;
  };
  /// Points per block: a block (its chain link, cell and points) fills two 64-byte cache
  /// lines.
  static constexpr std::uint32_t kBlockCapacity = sizeof(S) == 8 ? 4 : 7;

  /// `radius` [m]: the query radius served by a 2x2x2 block of cells (the association radius).
  /// Throws std::invalid_argument when radius is not finite and > 0 or the load factor is out
  /// of range.
  explicit VoxelHash(S radius, const Config& config = {}) : config_(config) {
    if (!(radius > S(0)) || !std::isfinite(radius)) {
      throw std::invalid_argument("VoxelHash: radius must be finite and > 0, got " +
                                  std::to_string(radius));
    }
    if (!(config.max_load_factor > 0.0 && config.max_load_factor <= 0.9)) {
      throw std::invalid_argument("VoxelHash::Config::max_load_factor must be in (0, 0.9], got " +
                                  std::to_string(config.max_load_factor));
    }
    radius_ = radius;
    cell_ = S(2) * radius * (S(1) + kMargin);
    inv_cell_ = S(1) / cell_;
    if (!std::isfinite(cell_) || !std::isfinite(inv_cell_) || !(inv_cell_ > S(0))) {
      throw std::invalid_argument("VoxelHash: radius " + std::to_string(radius) +
                                  " is too small or too large for a cell of type S");
    }
    slots_.assign(16, Slot{});
  }

  /// Largest |coordinate| the hash separates exactly [m]: 2^30 - 2 cells from the origin.
  /// Farther points share clamped border cells (correct, but slow when many do), so
  /// ContactCloud rejects contacts beyond it.
  [[nodiscard]] S max_coordinate() const noexcept { return (kMaxCell - S(2)) * cell_; }
  /// Side of a cell [m].
  [[nodiscard]] S cell_size() const noexcept { return cell_; }

  /// Adds point `p` (finite) with a new `id`.
  void insert(PointId id, const Vec3<S>& p) {
    TAXEL_ASSERT(!contains(id), "VoxelHash::insert: id already stored");
    TAXEL_ASSERT(all_finite(p), "VoxelHash::insert: point is not finite");
    if (id >= loc_.size()) loc_.resize(std::size_t{id} + 1, Loc{});
    place(id, p, key_of(p));
    ++size_;
  }

  /// Moves stored point `id` to `p` (finite).
  void move(PointId id, const Vec3<S>& p) {
    TAXEL_ASSERT(contains(id), "VoxelHash::move: id not stored");
    TAXEL_ASSERT(all_finite(p), "VoxelHash::move: point is not finite");
    const Loc at = loc_[id];
    Block& b = blocks_[at.block];
    const Key old_key = b.key;
    const Key new_key = key_of(p);
    if (old_key == new_key) {
      b.x[at.lane] = p.x();
      b.y[at.lane] = p.y();
      b.z[at.lane] = p.z();
      return;
    }
    unlink(id, old_key);
    place(id, p, new_key);
  }

  /// Removes stored point `id`.
  void erase(PointId id) {
    TAXEL_ASSERT(contains(id), "VoxelHash::erase: id not stored");
    const Loc at = loc_[id];
    unlink(id, blocks_[at.block].key);
    --size_;
  }

  /// Removes every point; keeps the allocated capacity.
  void clear() noexcept {
    std::fill(slots_.begin(), slots_.end(), Slot{});
    blocks_.clear();
    free_blocks_.clear();
    std::fill(loc_.begin(), loc_.end(), Loc{});
    cells_ = 0;
    size_ = 0;
  }

  /// Prepares for about `n` points without reallocation.
  void reserve(std::size_t n) {
    loc_.reserve(n);
    blocks_.reserve(n / 2 + 1);
    std::size_t want = slots_.size();
    while (static_cast<double>(n / 2 + 1) > config_.max_load_factor * static_cast<double>(want)) {
      want *= 2;
    }
    if (want != slots_.size()) rehash(want);
  }

  /// True when `id` is stored.
  [[nodiscard]] bool contains(PointId id) const noexcept {
    return id < loc_.size() && loc_[id].block != kNone;
  }
  /// Number of stored points.
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  /// Number of cells that ever held a point since the last clear.
  [[nodiscard]] std::size_t cell_count() const noexcept { return cells_; }
  /// Heap bytes held (table, block pool, per-id locations).
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return slots_.capacity() * sizeof(Slot) + blocks_.capacity() * sizeof(Block) +
           free_blocks_.capacity() * sizeof(std::uint32_t) + loc_.capacity() * sizeof(Loc);
  }

  /// The closest point within distance r of q (ties by id), if any. No allocation.
  [[nodiscard]] std::optional<Neighbor<S>> nearest_within(const Vec3<S>& q, S r) const {
    if (size_ == 0 || !all_finite(q) || !(r >= S(0))) return std::nullopt;
    const Vec3<S> t = q * inv_cell_;
    const S extent = std::max(std::max(std::abs(t.x()), std::abs(t.y())), std::abs(t.z()));
    if (r <= radius_ && extent < kMaxCell && extent * S(8) * kEps < kMargin) {
      return nearest_in_block(q, t, r);
    }
    const S rp = probe_radius(r);
    const Key lo = key_of(Vec3<S>(q.array() - rp));
    const Key hi = key_of(Vec3<S>(q.array() + rp));
    const Key home = key_of(q);
    Neighbor<S> best{0, r * r};
    bool found = false;
    auto visit = [&](const Block& b) { consider(b, q, best, found); };
    if (volume(lo, hi) > static_cast<double>(cells_)) {
      for (const Block& b : blocks_) visit(b);
      return found ? std::optional<Neighbor<S>>(best) : std::nullopt;
    }
    // The home cell first: in fusion it usually holds the answer, which prunes the others.
    visit_cell(home, visit);
    const S slack = cell_ * S(1e-4) + q.cwiseAbs().maxCoeff() * S(8) * kEps;
    for (std::int32_t x = lo.x; x <= hi.x; ++x) {
      const S dx = axis_gap(q.x(), x, slack);
      for (std::int32_t y = lo.y; y <= hi.y; ++y) {
        const S dy = axis_gap(q.y(), y, slack);
        for (std::int32_t z = lo.z; z <= hi.z; ++z) {
          const Key k{x, y, z};
          if (k == home) continue;
          const S dz = axis_gap(q.z(), z, slack);
          if (dx * dx + dy * dy + dz * dz > best.squared_distance) continue;
          visit_cell(k, visit);
        }
      }
    }
    return found ? std::optional<Neighbor<S>>(best) : std::nullopt;
  }

  /// Every point within distance r of q, ordered by `closer`.
  [[nodiscard]] std::vector<Neighbor<S>> within(const Vec3<S>& q, S r) const {
    std::vector<Neighbor<S>> out;
    if (size_ == 0 || !all_finite(q) || !(r >= S(0))) return out;
    const S r2 = r * r;
    auto visit = [&](const Block& b) {
      for (std::uint32_t l = 0; l < kBlockCapacity; ++l) {
        const S d2 = squared_distance(Vec3<S>(b.x[l], b.y[l], b.z[l]), q);
        if (d2 <= r2) out.push_back({b.ids[l], d2});
      }
    };
    const S rp = probe_radius(r);
    const Key lo = key_of(Vec3<S>(q.array() - rp));
    const Key hi = key_of(Vec3<S>(q.array() + rp));
    if (volume(lo, hi) > static_cast<double>(cells_)) {
      for (const Block& b : blocks_) visit(b);  // freed blocks are empty
    } else {
      for (std::int32_t x = lo.x; x <= hi.x; ++x) {
        for (std::int32_t y = lo.y; y <= hi.y; ++y) {
          for (std::int32_t z = lo.z; z <= hi.z; ++z) {
            visit_cell(Key{x, y, z}, visit);
          }
        }
      }
    }
    std::sort(out.begin(), out.end(), closer<S>);
    return out;
  }

  /// The min(k, size()) closest points, ordered by `closer`: radius searches that double the
  /// radius until k points are inside (a ball holding k points holds the k nearest).
  [[nodiscard]] std::vector<Neighbor<S>> knn(const Vec3<S>& q, std::size_t k) const {
    const std::size_t want = std::min(k, size_);
    if (want == 0 || !all_finite(q)) return {};
    for (S r = cell_ / 2;; r *= 2) {
      std::vector<Neighbor<S>> found = within(q, r);
      if (found.size() >= want || !std::isfinite(r)) {
        found.resize(std::min(want, found.size()));
        return found;
      }
    }
  }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  static constexpr S kEps = std::numeric_limits<S>::epsilon();
  // Cell coordinates are clamped so they fit int32 and are exactly representable in float.
  static constexpr S kMaxCell = S(1 << 30);
  // Cells are 2 r (1 + kMargin) wide, so a ball of radius r around q reaches at most one
  // neighbour cell per axis, the one on the side of q's cell centre, with kMargin of cell
  // width to spare for rounding (used while |q / cell| * 8 eps < kMargin).
  static constexpr S kMargin = S(1e-4);

  struct Key {
    std::int32_t x = 0, y = 0, z = 0;
    friend bool operator==(const Key&, const Key&) = default;
  };
  struct Slot {
    Key key;
    std::uint32_t head = kNone;  // kNone: never used (ends a probe run)
  };
  // Unused lanes hold +inf coordinates, so a scan over all lanes needs no count check and
  // an unused lane is never within any radius; the used lanes are a prefix. A block knows its
  // cell, so a move needs no floor of the old position. 128 bytes, on cache-line boundaries.
  struct alignas(64) Block {
    std::uint32_t next = kNone;
    Key key;
    PointId ids[kBlockCapacity] = {};
    S x[kBlockCapacity], y[kBlockCapacity], z[kBlockCapacity];
    Block() noexcept { clear_lanes(0); }
    void clear_lanes(std::uint32_t from) noexcept {
      for (std::uint32_t l = from; l < kBlockCapacity; ++l) {
        x[l] = y[l] = z[l] = std::numeric_limits<S>::infinity();
      }
    }
  };
  static_assert(sizeof(Block) == 128);
  struct Loc {
    std::uint32_t block = kNone;
    std::uint32_t lane = 0;
  };

  // A point whose computed distance is <= r lies within r (1 + 3 eps) of q on every axis;
  // probing cells over q +- r (1 + 16 eps) therefore finds it, because rounding is monotone
  // and the stored coordinate is representable (cell_of(fl(q - rp)) <= cell_of(p)).
  static S probe_radius(S r) noexcept { return r * (S(1) + S(16) * kEps); }

  // floor(v / cell), clamped to +-2^30; without a libm call (x86-64 baseline has no roundsd).
  std::int32_t cell_of(S v) const noexcept {
    const S t = std::min(std::max(v * inv_cell_, -kMaxCell), kMaxCell);
    const auto i = static_cast<std::int32_t>(t);
    return i - static_cast<std::int32_t>(t < static_cast<S>(i));
  }
  Key key_of(const Vec3<S>& p) const noexcept {
    return {cell_of(p.x()), cell_of(p.y()), cell_of(p.z())};
  }
  static double volume(const Key& lo, const Key& hi) noexcept {
    return (double(hi.x) - lo.x + 1) * (double(hi.y) - lo.y + 1) * (double(hi.z) - lo.z + 1);
  }
  // Lower bound on |v - (any coordinate stored in cell i)|, shrunk by `slack` for rounding.
  S axis_gap(S v, std::int32_t i, S slack) const noexcept {
    const S lo = static_cast<S>(i) * cell_;
    const S hi = lo + cell_;
    const S gap = v < lo ? lo - v : (v > hi ? v - hi : S(0));
    return std::max(S(0), gap - slack);
  }

  // Multiplicative (Fibonacci) hashing: the slot is the top bits of a 64-bit product sum.
  std::size_t home_slot(const Key& k) const noexcept {
    const std::uint64_t h = std::uint64_t(std::uint32_t(k.x)) * 0x9E3779B97F4A7C15ULL +
                            std::uint64_t(std::uint32_t(k.y)) * 0xC2B2AE3D27D4EB4FULL +
                            std::uint64_t(std::uint32_t(k.z)) * 0x165667B19E3779F9ULL;
    return static_cast<std::size_t>(h >> shift_);
  }

  // Head block of cell `k`, or kNone.
  std::uint32_t find(const Key& k) const noexcept {
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = home_slot(k);; i = (i + 1) & mask) {
      const Slot& s = slots_[i];
      if (s.head == kNone) return kNone;
      if (s.key == k) return s.head;
    }
  }
  // Slot of cell `k`, created (with an empty block) when missing.
  Slot& find_or_add(const Key& k) {
    if (static_cast<double>(cells_ + 1) > config_.max_load_factor * double(slots_.size())) {
      rehash(slots_.size() * 2);
    }
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = home_slot(k);; i = (i + 1) & mask) {
      Slot& s = slots_[i];
      if (s.head == kNone) {
        s.key = k;
        s.head = new_block();
        blocks_[s.head].key = k;
        ++cells_;
        return s;
      }
      if (s.key == k) return s;
    }
  }
  void rehash(std::size_t capacity) {
    std::vector<Slot> old = std::move(slots_);
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c >>= 1) --shift_;
    slots_.assign(capacity, Slot{});
    const std::size_t mask = capacity - 1;
    for (const Slot& s : old) {
      if (s.head == kNone) continue;
      std::size_t i = home_slot(s.key);
      while (slots_[i].head != kNone) i = (i + 1) & mask;
      slots_[i] = s;
    }
  }
  std::uint32_t new_block() {
    if (!free_blocks_.empty()) {
      const std::uint32_t b = free_blocks_.back();
      free_blocks_.pop_back();
      blocks_[b].next = kNone;
      blocks_[b].clear_lanes(0);
      return b;
    }
    blocks_.emplace_back();
    return static_cast<std::uint32_t>(blocks_.size() - 1);
  }

  void place(PointId id, const Vec3<S>& p, const Key& key) {
    // Invariant: in a cell's chain only the head block may be partly filled.
    Slot* slot = &find_or_add(key);
    std::uint32_t bi = slot->head;
    if (count_of(blocks_[bi]) == kBlockCapacity) {
      bi = new_block();  // may reallocate blocks_, never slots_
      blocks_[bi].next = slot->head;
      blocks_[bi].key = key;
      slot->head = bi;
    }
    Block& b = blocks_[bi];
    const std::uint32_t l = count_of(b);
    b.ids[l] = id;
    b.x[l] = p.x();
    b.y[l] = p.y();
    b.z[l] = p.z();
    loc_[id] = {bi, l};
  }

  // Points in a block: its filled lanes are a prefix, the others hold +inf.
  static std::uint32_t count_of(const Block& b) noexcept {
    std::uint32_t n = 0;
    while (n < kBlockCapacity && b.x[n] != std::numeric_limits<S>::infinity()) ++n;
    return n;
  }
  // Takes `id` out of cell `key`, filling its lane with the last point of the cell's head
  // block (keeping only the head partly filled); frees the head when it empties and is not
  // the cell's only block.
  void unlink(PointId id, const Key& key) {
    const std::size_t mask = slots_.size() - 1;
    std::size_t i = home_slot(key);
    while (!(slots_[i].key == key) || slots_[i].head == kNone) i = (i + 1) & mask;
    Slot& slot = slots_[i];
    const Loc at = loc_[id];
    Block& head = blocks_[slot.head];
    const std::uint32_t last = count_of(head) - 1;
    if (slot.head != at.block || at.lane != last) {
      Block& b = blocks_[at.block];
      b.ids[at.lane] = head.ids[last];
      b.x[at.lane] = head.x[last];
      b.y[at.lane] = head.y[last];
      b.z[at.lane] = head.z[last];
      loc_[b.ids[at.lane]] = at;
    }
    head.clear_lanes(last);
    loc_[id] = Loc{};
    if (last == 0 && head.next != kNone) {
      const std::uint32_t freed = slot.head;
      slot.head = head.next;
      head.next = kNone;
      free_blocks_.push_back(freed);
    }
  }

  // nearest_within for r <= radius_: the query's cell, then those of its 7 neighbours on the
  // sides of the cell centre it is closest to, skipping any that lie farther than the best.
  std::optional<Neighbor<S>> nearest_in_block(const Vec3<S>& q, const Vec3<S>& t, S r) const {
    Neighbor<S> best{0, r * r};
    bool found = false;
    auto visit = [&](const Block& b) { consider(b, q, best, found); };
    // |t| < 2^30 here (the caller checks), so floor needs no clamp; t = q / cell as key_of
    // computes it, hence the same cell.
    auto floor_of = [](S v) {
      const auto i = static_cast<std::int32_t>(v);
      return i - static_cast<std::int32_t>(v < static_cast<S>(i));
    };
    const Key home{floor_of(t.x()), floor_of(t.y()), floor_of(t.z())};
    std::int32_t step[3];
    S gap2[3];
    for (int a = 0; a < 3; ++a) {
      const S frac = t[a] - static_cast<S>((&home.x)[a]);
      // Branch-free: the neighbour on the side of the nearer face, and the distance to it
      // less kMargin of a cell for rounding.
      step[a] = 2 * static_cast<std::int32_t>(frac >= S(0.5)) - 1;
      const S gap = std::max(S(0), std::min(frac, S(1) - frac) - kMargin) * cell_;
      gap2[a] = gap * gap;
    }
    const S g[8] = {S(0),    gap2[0],           gap2[1],           gap2[0] + gap2[1],
                    gap2[2], gap2[0] + gap2[2], gap2[1] + gap2[2], gap2[0] + gap2[1] + gap2[2]};
    visit_cell(home, visit);
    // Unrolled, nearest faces first; the selections above are branch-free. Data-dependent
    // branches there were a large share of the query's mispredictions.
    auto neighbour = [&](int m) {
      if (g[m] > best.squared_distance) return;
      visit_cell(Key{home.x + ((m & 1) ? step[0] : 0), home.y + ((m & 2) ? step[1] : 0),
                     home.z + ((m & 4) ? step[2] : 0)},
                 visit);
    };
    neighbour(1);
    neighbour(2);
    neighbour(4);
    neighbour(3);
    neighbour(5);
    neighbour(6);
    neighbour(7);
    return found ? std::optional<Neighbor<S>>(best) : std::nullopt;
  }

  // Updates (best, found) with the points of `b`: closer, or as close with a smaller id.
  // All lanes are scanned (unused ones are at infinity): a fixed trip count vectorises.
  static void consider(const Block& b, const Vec3<S>& q, Neighbor<S>& best, bool& found) {
    S d2[kBlockCapacity];
    for (std::uint32_t l = 0; l < kBlockCapacity; ++l) {
      d2[l] = squared_distance(Vec3<S>(b.x[l], b.y[l], b.z[l]), q);
    }
    for (std::uint32_t l = 0; l < kBlockCapacity; ++l) {
      if (d2[l] < best.squared_distance ||
          (d2[l] == best.squared_distance && (!found || b.ids[l] < best.id))) {
        best = {b.ids[l], d2[l]};
        found = true;
      }
    }
  }

  template <class Visit>
  void visit_cell(const Key& k, Visit& visit) const {
    for (std::uint32_t bi = find(k); bi != kNone; bi = blocks_[bi].next) visit(blocks_[bi]);
  }

  Config config_;
  S radius_ = S(1);
  S cell_ = S(1);
  S inv_cell_ = S(1);
  std::vector<Slot> slots_;
  unsigned shift_ = 60;  // 64 - log2(slots_.size())
  std::vector<Block> blocks_;
  std::vector<std::uint32_t> free_blocks_;
  std::vector<Loc> loc_;
  std::size_t cells_ = 0;
  std::size_t size_ = 0;
};

}  // namespace taxel::index
