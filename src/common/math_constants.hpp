// The constants of the project's formulas, in one place.
#pragma once

namespace oocsimp {

/// pi, to the last digit a double holds.
constexpr double kPi = 3.14159265358979323846;

}  // namespace oocsimp
