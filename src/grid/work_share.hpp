// How the parts of a distributed run share the tiles of a pass (docs/cluster.md):
// dealt by weight, from counts every part knows alike, so each part finds its own
// share without asking the others.
#pragma once

#include <algorithm>
#include <cstring>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "common/flat_hash_map.hpp"
#include "grid/grid_coord.hpp"
#include "grid/tile_grid.hpp"
#include "io/face_range.hpp"
#include "io/mesh_input.hpp"
#include "oocsimp/options.hpp"

namespace oocsimp {

/// `weights` dealt to `parts` processes: the heaviest first (ties in the list's
/// order), each to the process with the least weight so far (ties to the lower
/// number; a weight counts at least 1). Returns each item's process.
inline std::vector<std::uint32_t> deal_by_weight(const std::vector<std::uint64_t>& weights, std::uint32_t parts) {
  std::vector<std::size_t> order(weights.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return weights[a] > weights[b]; });
  std::vector<std::uint64_t> load(std::max<std::uint32_t>(parts, 1), 0);
  std::vector<std::uint32_t> owner(weights.size(), 0);
  for (std::size_t i : order) {
    const auto least = std::uint32_t(std::min_element(load.begin(), load.end()) - load.begin());
    owner[i] = least;
    load[least] += std::max<std::uint64_t>(weights[i], 1);
  }
  return owner;
}

/// Plain records as the bytes parts exchange.
template <class Record>
std::vector<unsigned char> record_bytes(const Record* records, std::size_t count) {
  static_assert(std::is_trivially_copyable<Record>::value, "records cross processes as bytes");
  std::vector<unsigned char> bytes(count * sizeof(Record));
  if (count) std::memcpy(bytes.data(), records, bytes.size());
  return bytes;
}

/// The whole records of bytes from record_bytes.
template <class Record>
std::vector<Record> records_of_bytes(const std::vector<unsigned char>& bytes) {
  static_assert(std::is_trivially_copyable<Record>::value, "records cross processes as bytes");
  std::vector<Record> records(bytes.size() / sizeof(Record));
  if (!records.empty()) std::memcpy(records.data(), bytes.data(), records.size() * sizeof(Record));
  return records;
}

/// The tiles one part runs, and how the parts that run at once exchange what they
/// decide about them.
struct TileShare {
  std::uint32_t part = 0, parts = 1;
  std::vector<char> owned;  ///< per tile, whether this part runs it; empty: every tile
  PartExchange exchange;    ///< empty when the parts run apart (each then decides alone)
  PartDelivery deliver;     ///< optional with `exchange` (see send)
  bool owns(std::uint32_t tile) const { return owned.empty() || owned[tile] != 0; }
  bool exchanging() const { return bool(exchange); }

  /// Sends `to_each[p]` to part p, every part at once, and returns what each part
  /// sent this one: through `deliver`, or packed into one `exchange` without it.
  std::vector<std::vector<unsigned char>> send(const std::vector<std::vector<unsigned char>>& to_each) const {
    if (deliver) return deliver(to_each);
    std::vector<unsigned char> packed(to_each.size() * sizeof(std::uint64_t));
    for (std::size_t p = 0; p < to_each.size(); ++p) {
      const std::uint64_t size = to_each[p].size();
      std::memcpy(packed.data() + p * sizeof size, &size, sizeof size);
      packed.insert(packed.end(), to_each[p].begin(), to_each[p].end());
    }
    const std::vector<std::vector<unsigned char>> all = exchange(packed);
    std::vector<std::vector<unsigned char>> mine(all.size());
    for (std::size_t q = 0; q < all.size(); ++q) {
      std::size_t at = to_each.size() * sizeof(std::uint64_t);
      if (all[q].size() < at) throw std::runtime_error("part " + std::to_string(q) + " sent a damaged message");
      for (std::size_t p = 0; p <= part; ++p) {
        std::uint64_t size = 0;
        std::memcpy(&size, all[q].data() + p * sizeof size, sizeof size);
        if (size > all[q].size() - at)
          throw std::runtime_error("part " + std::to_string(q) + " sent a damaged message");
        if (p == part) mine[q].assign(all[q].begin() + std::ptrdiff_t(at), all[q].begin() + std::ptrdiff_t(at + size));
        at += std::size_t(size);
      }
    }
    return mine;
  }
};

/// Per tile, the part of `parts` that owns it: dealt by `records` per tile within
/// each class of `classes` (a tile's colour class), since the parts meet after every
/// class of a sweep and each class is best balanced on its own.
inline std::vector<std::uint32_t> tile_owner_deal(const std::vector<std::uint64_t>& records,
                                                  const std::vector<int>& classes, std::uint32_t parts) {
  std::vector<std::uint32_t> owners(records.size(), 0);
  const int class_count = classes.empty() ? 0 : *std::max_element(classes.begin(), classes.end()) + 1;
  for (int k = 0; k < class_count; ++k) {
    std::vector<std::size_t> tiles;
    std::vector<std::uint64_t> weights;
    for (std::size_t t = 0; t < records.size(); ++t)
      if (classes[t] == k) {
        tiles.push_back(t);
        weights.push_back(records[t]);
      }
    const std::vector<std::uint32_t> owner = deal_by_weight(weights, parts);
    for (std::size_t i = 0; i < tiles.size(); ++i) owners[tiles[i]] = owner[i];
  }
  return owners;
}

/// Per tile, whether part `part` of `parts` owns it (tile_owner_deal).
inline std::vector<char> owned_tiles(const std::vector<std::uint64_t>& records, const std::vector<int>& classes,
                                     std::uint32_t part, std::uint32_t parts) {
  const std::vector<std::uint32_t> owners = tile_owner_deal(records, classes, parts);
  std::vector<char> owned(records.size(), 0);
  for (std::size_t t = 0; t < owners.size(); ++t) owned[t] = owners[t] == part;
  return owned;
}

/// Each tile's part, for parts that run only their own tiles (tile_owners).
using TileOwners = std::unordered_map<GridCoord, std::uint32_t, GridCoordHash>;

/// The part that owns the tile at `c` (part 0 for a tile without positions, which
/// no triangle reaches).
inline std::uint32_t tile_owner(const TileOwners& owners, const GridCoord& c) {
  const auto it = owners.find(c);
  return it == owners.end() ? 0 : it->second;
}

/// Which of `parts` parts owns each tile, before any binning, for parts that run only
/// their own tiles: every occupied tile (one holding a finite position of `positions`
/// at tile side `side`) dealt by the positions in it within its colour class, as
/// owned_tiles deals. Every part computes the same deal from the input; with
/// `share` (parts that run at once), each counts its own range of the positions and
/// the parts exchange their counts.
inline TileOwners tile_owners(const PositionArray& positions, double side, std::uint32_t parts,
                              const TileShare* share = nullptr) {
  FlatHashMap<GridCoord, std::uint64_t, GridCoordHash> counts;
  const bool shared = share && share->exchanging();
  const std::uint64_t first = shared ? even_split_start(positions.count, share->part, share->parts) : 0;
  const std::uint64_t end = shared ? even_split_start(positions.count, share->part + 1, share->parts) : positions.count;
  for (std::uint64_t v = first; v < end; ++v) {
    const Vec3d p = positions.get(v);
    if (is_finite(p)) ++counts.value(counts.insert(GridCoord::of(p, side)));
  }
  if (shared) {
    struct TileCount {
      GridCoord tile;
      std::uint64_t count;
    };
    std::vector<TileCount> mine(counts.size());
    for (std::size_t i = 0; i < counts.size(); ++i) mine[i] = {counts.key(i), counts.value(i)};
    counts.clear();
    for (const std::vector<unsigned char>& theirs : share->exchange(record_bytes(mine.data(), mine.size())))
      for (const TileCount& c : records_of_bytes<TileCount>(theirs)) counts.value(counts.insert(c.tile)) += c.count;
  }
  std::vector<std::size_t> order(counts.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  // One order on every part.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return counts.key(a) < counts.key(b); });
  std::vector<std::uint64_t> records(order.size());
  std::vector<int> classes(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    records[i] = counts.value(order[i]);
    classes[i] = TileGrid::colour_of(counts.key(order[i]));
  }
  const std::vector<std::uint32_t> owner = tile_owner_deal(records, classes, parts);
  TileOwners owners;
  for (std::size_t i = 0; i < order.size(); ++i) owners.emplace(counts.key(order[i]), owner[i]);
  return owners;
}

}  // namespace oocsimp
