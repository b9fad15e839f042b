// SPDX-License-Identifier: MIT
// The reference peer for contact fusion: the plainest fast hash grid a robotics programmer would
// write for "fuse each contact into the nearest point within r". Cells of side 2r in a
// tsl::robin_map (open addressing, robin-hood probing), a std::vector of point ids per cell;
// a query reads the 2x2x2 block of cells on the sides of the query's cell nearest to it (the
// ball of radius r meets no other), and a fused point that leaves its cell is moved by
// swap-and-pop. It validates each contact and fuses with the same policy object as ContactCloud, so the two do exactly the
// same arithmetic and build the same cloud; only the index differs.
#pragma once

#include <tsl/robin_map.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <taxel/core/contact.hpp>
#include <vector>

namespace taxel_bench {

template <class Policy>
class ReferenceGrid {
 public:
  using S = typename Policy::Scalar;
  explicit ReferenceGrid(S radius) : r_(radius), inv_cell_(S(1) / (S(2) * radius)) {}

  // Validates like ContactCloud (a NaN must not enter the grid), then fuses or adds.
  void insert(const taxel::Contact<S>& c) {
    if (taxel::check_contact(c) != taxel::ContactDefect::ok) return;
    const taxel::Vec3<S> t = c.position * inv_cell_;
    std::int64_t k[3], n[3];
    for (int a = 0; a < 3; ++a) {
      k[a] = static_cast<std::int64_t>(std::floor(t[a]));
      n[a] = t[a] - S(k[a]) < S(0.5) ? k[a] - 1 : k[a] + 1;
    }
    std::uint32_t best = kNone;
    S best_d2 = r_ * r_;
    for (int i = 0; i < 8; ++i) {
      const auto it =
          cells_.find(pack((i & 1) ? n[0] : k[0], (i & 2) ? n[1] : k[1], (i & 4) ? n[2] : k[2]));
      if (it == cells_.end()) continue;
      for (const std::uint32_t id : it->second) {
        const S d2 = (means_[id] - c.position).squaredNorm();
        if (d2 <= best_d2 && (d2 < best_d2 || id < best)) {
          best_d2 = d2;
          best = id;
        }
      }
    }
    if (best != kNone) {
      if (policy_.fuse(states_[best], c, observations_[best])) {
        ++observations_[best];
        const taxel::Vec3<S> m = policy_.mean(states_[best]);
        const std::uint64_t from = key_of(means_[best]), to = key_of(m);
        means_[best] = m;
        if (from != to) {
          auto& v = cells_.find(from).value();
          for (auto& id : v) {
            if (id == best) {
              id = v.back();
              break;
            }
          }
          v.pop_back();
          cells_[to].push_back(best);
        }
        return;
      }
    }
    const auto id = static_cast<std::uint32_t>(states_.size());
    states_.push_back(policy_.init(c));
    observations_.push_back(1);
    means_.push_back(c.position);
    cells_[key_of(c.position)].push_back(id);
  }

  std::size_t size() const { return states_.size(); }
  const taxel::Vec3<S>& mean(std::uint32_t id) const { return means_[id]; }

 private:
  static constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  static std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
    constexpr std::int64_t kBias = std::int64_t{1} << 20;
    return (std::uint64_t(x + kBias) << 42) | (std::uint64_t(y + kBias) << 21) |
           std::uint64_t(z + kBias);
  }
  std::uint64_t key_of(const taxel::Vec3<S>& p) const {
    const taxel::Vec3<S> t = p * inv_cell_;
    return pack(static_cast<std::int64_t>(std::floor(t.x())),
                static_cast<std::int64_t>(std::floor(t.y())),
                static_cast<std::int64_t>(std::floor(t.z())));
  }

  // robin_map masks the low bits of the hash and std::hash of an integer is the identity, so
  // the packed key is mixed first (MurmurHash3's 64-bit finaliser); without it every cell in a
  // column of z collides.
  struct Mix {
    std::size_t operator()(std::uint64_t k) const noexcept {
      k ^= k >> 33;
      k *= 0xff51afd7ed558ccdULL;
      k ^= k >> 33;
      k *= 0xc4ceb9fe1a85ec53ULL;
      k ^= k >> 33;
      return static_cast<std::size_t>(k);
    }
  };

  S r_, inv_cell_;
  Policy policy_{};
  tsl::robin_map<std::uint64_t, std::vector<std::uint32_t>, Mix> cells_;
  std::vector<typename Policy::State> states_;
  std::vector<std::uint32_t> observations_;
  std::vector<taxel::Vec3<S>> means_;
};

}  // namespace taxel_bench
