// Maps from packed cell keys (GridSpec::key) to per-cell records.
#pragma once

#include <cstdint>

#include "common/flat_hash_map.hpp"

namespace oocsimp {

/// Cell key -> record, records numbered in insertion order (the clusterers merge
/// and output cells in that order). Keys are packed integer coordinates; the table
/// spreads them itself (see FlatHashMap).
template <class Record>
using CellMap = FlatHashMap<std::uint64_t, Record>;

}  // namespace oocsimp
