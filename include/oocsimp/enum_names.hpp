// oocsimp — how option values are spelled: one table per enum (oocsimp/oocsimp.hpp,
// generate.hpp, render.hpp), which the *_name() functions, the stats JSON and the
// command line's flags all read, so that each spelling is written once.
#pragma once

#include <string>
#include <vector>

namespace oocsimp {

/// An enum value and its spelling ("floating", "cube", "auto").
template <class E>
struct EnumName {
  E value;
  const char* name;
};

/// Every value of an enum with its spelling, in the order the command line lists them
/// (the default first).
template <class E>
using EnumNames = std::vector<EnumName<E>>;

/// The spelling of `value`; nullptr when the table has none.
template <class E>
const char* name_of(const EnumNames<E>& names, E value) {
  for (const EnumName<E>& n : names)
    if (n.value == value) return n.name;
  return nullptr;
}

/// Sets `*value` to the value spelled `name` and returns true; false when none is.
template <class E>
bool value_named(const EnumNames<E>& names, const std::string& name, E* value) {
  for (const EnumName<E>& n : names)
    if (name == n.name) {
      *value = n.value;
      return true;
    }
  return false;
}

}  // namespace oocsimp
