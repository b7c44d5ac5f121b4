// Whitespace tokenising and number parsing shared by the text formats.
#pragma once

#include <charconv>
#include <cstdint>
#include <string_view>

namespace oocsimp {

/// Splits a line into whitespace-separated tokens.
class TokenScanner {
 public:
  explicit TokenScanner(std::string_view line) : s_(line) {}
  /// The next token, or an empty view at the end of the line.
  std::string_view next() {
    while (i_ < s_.size() && is_space(s_[i_])) ++i_;
    std::size_t b = i_;
    while (i_ < s_.size() && !is_space(s_[i_])) ++i_;
    return s_.substr(b, i_ - b);
  }
  /// The rest of the line after the current token, untrimmed.
  std::string_view rest() const { return s_.substr(i_); }
  bool at_end() {
    while (i_ < s_.size() && is_space(s_[i_])) ++i_;
    return i_ == s_.size();
  }
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

 private:
  std::string_view s_;
  std::size_t i_ = 0;
};

/// Parses a whole token as a floating-point number (a leading '+' is accepted; "nan"
/// and "inf" parse, so callers reject them with their own position).
inline bool parse_double(std::string_view t, double* v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  auto r = std::from_chars(t.data(), t.data() + t.size(), *v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

/// Parses a whole token as a signed 64-bit integer (a leading '+' is accepted).
inline bool parse_int(std::string_view t, std::int64_t* v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  auto r = std::from_chars(t.data(), t.data() + t.size(), *v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

/// Like parse_int but for an unsigned 64-bit count.
inline bool parse_uint(std::string_view t, std::uint64_t* v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  auto r = std::from_chars(t.data(), t.data() + t.size(), *v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

}  // namespace oocsimp
