// The one-line messages of the library's errors: "FILE: byte N: WHAT" and the like.
#pragma once

#include <cstdint>
#include <string>

namespace oocsimp {

/// Builds "FILE: byte OFFSET: WHAT" for an InputError in a binary section.
std::string at_byte(const std::string& file, std::uint64_t offset, const std::string& what);
/// Builds "FILE: line LINE: WHAT" for an InputError in a text section.
std::string at_line(const std::string& file, std::uint64_t line, const std::string& what);
/// Builds "FILE: WHAT: strerror(errno)" for an IoError after a failed system call.
std::string system_error_text(const std::string& file, const std::string& what, int errnum);

}  // namespace oocsimp
