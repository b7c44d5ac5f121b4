// The .4k file (docs/hierarchy.md, "The .4k file"): a 64-byte header, the levels, the
// finest mesh, the records (only the faces each replaces: the faces it makes follow
// from them, record_faces.hpp), the vertex attributes (from version 2), and an XXH64
// per MiB of all that.
#pragma once

#include <string>

#include "oocsimp/hierarchy.hpp"

namespace oocsimp {

/// The version written; version 1 (no attributes) is read too.
constexpr std::uint32_t kHierarchyFileVersion = 2;

/// The file's bytes.
std::string hierarchy_file_bytes(const MeshHierarchy& hierarchy);
/// A hierarchy from a file's bytes; `name` for the messages. InputError naming the
/// byte where the bytes are not a version 1 or 2 .4k file or are damaged.
MeshHierarchy parse_hierarchy_file(const std::string& bytes, const std::string& name);
/// Whether `bytes` start with the .4k magic.
bool has_hierarchy_magic(const std::string& bytes);
/// Whether the file can hold an attribute of this name: one that can stand in a PLY
/// header as a property's name (not empty, printable ASCII without blanks), since it
/// goes into the header of every mesh extracted. The reader refuses any other.
bool storable_attribute_name(const std::string& name);
/// Whether such a name may hold this byte: printable ASCII, not a blank.
inline bool storable_name_byte(char c) { return c > ' ' && c < 0x7f; }

}  // namespace oocsimp
