#include "io/error_text.hpp"

#include <cstring>

namespace oocsimp {

std::string at_byte(const std::string& file, std::uint64_t offset, const std::string& what) {
  return file + ": byte " + std::to_string(offset) + ": " + what;
}

std::string at_line(const std::string& file, std::uint64_t line, const std::string& what) {
  return file + ": line " + std::to_string(line) + ": " + what;
}

std::string system_error_text(const std::string& file, const std::string& what, int errnum) {
  return file + ": " + what + ": " + std::strerror(errnum);
}

}  // namespace oocsimp
