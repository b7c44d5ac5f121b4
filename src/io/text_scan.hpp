// Whitespace tokenising and number parsing shared by the text formats.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
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

/// Whether a decimal number (as std::from_chars accepts it, sign stripped or not) that
/// from_chars found out of range is tiny rather than huge: its first nonzero digit
/// times 10 to its exponent is below 1. Out of range happens only near 1e-324 and 1e308,
/// so the digit's position decides.
inline bool decimal_underflows(std::string_view t) {
  std::size_t i = t.size() > 0 && t[0] == '-' ? 1 : 0;
  bool point = false, nonzero = false;
  std::int64_t lead = 0, frac_pos = 0;  // decimal exponent of the first nonzero digit
  for (; i < t.size(); ++i) {
    const char c = t[i];
    if (c == '.') {
      point = true;
      continue;
    }
    if (c < '0' || c > '9') break;
    if (point) ++frac_pos;
    if (!nonzero && c != '0') {
      nonzero = true;
      lead = point ? -frac_pos : 0;
    } else if (nonzero && !point) {
      ++lead;
    }
  }
  std::int64_t exp = 0;
  if (i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    ++i;
    const bool negative = i < t.size() && t[i] == '-';
    if (i < t.size() && (t[i] == '-' || t[i] == '+')) ++i;
    for (; i < t.size() && t[i] >= '0' && t[i] <= '9'; ++i)
      if (exp < 1000000000) exp = exp * 10 + (t[i] - '0');  // saturates: only the sign matters
    if (negative) exp = -exp;
  }
  return !nonzero || lead + exp < 0;
}

/// Parses a whole token as a floating-point number (a leading '+' is accepted; "nan"
/// and "inf" parse, so callers reject them with their own position). A number too
/// small for a double becomes zero of its sign, as strtod rounds it (values in the
/// denormal range keep their denormal); one too large is rejected.
inline bool parse_double(std::string_view t, double* v) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  auto r = std::from_chars(t.data(), t.data() + t.size(), *v);
  if (r.ptr != t.data() + t.size()) return false;
  if (r.ec == std::errc()) return true;
  if (r.ec != std::errc::result_out_of_range || !decimal_underflows(t)) return false;
  *v = t[0] == '-' ? -0.0 : 0.0;
  return true;
}

/// True when `v`, parsed from the decimal `token`, is told apart from the float nearest to
/// it only below the token's last written digit: that float, printed with as many digits,
/// gives the token back, so the text carries no more than float precision ("0.1",
/// "12.345678", a float written with %.9g), while "451234.567" (a UTM coordinate, which
/// a float would round to 451234.5625) carries more. A gap of half a digit counts as
/// fitting, with a little slack for the rounding of the gap itself: the shortest text of
/// a float can lie there ("178616.12" for 178616.125f).
inline bool decimal_fits_float(std::string_view token, double v) {
  const double gap = std::abs(double(float(v)) - v);
  if (gap == 0) return true;
  std::size_t i = 0;
  if (i < token.size() && (token[i] == '+' || token[i] == '-')) ++i;
  long digits_after_point = 0;
  bool point = false;
  for (; i < token.size(); ++i) {
    const char c = token[i];
    if (c == '.')
      point = true;
    else if (c >= '0' && c <= '9')
      digits_after_point += point ? 1 : 0;
    else
      break;
  }
  long exponent = 0;
  if (i < token.size() && (token[i] == 'e' || token[i] == 'E')) {
    const std::string_view e = token.substr(i + 1);
    std::int64_t parsed = 0;
    auto r = std::from_chars(e.data() + (!e.empty() && e[0] == '+'), e.data() + e.size(), parsed);
    if (r.ec != std::errc()) return false;  // a huge exponent: the value is not near a float anyway
    exponent = long(std::max<std::int64_t>(-400, std::min<std::int64_t>(400, parsed)));
  }
  const double half_last_digit = 0.5 * std::pow(10.0, double(exponent - digits_after_point));
  return gap <= half_last_digit * (1 + 1e-6);
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

/// `token` in double quotes for a message, at most 64 bytes of it (then "..."), with
/// every byte outside printable ASCII written as \xNN: a NUL would cut the message short,
/// and control bytes would garble the terminal.
inline std::string quoted(std::string_view token) {
  constexpr std::size_t kMaxShown = 64;
  static const char kHex[] = "0123456789ABCDEF";
  std::string s = "\"";
  for (std::size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7F && c != '\\' && c != '"') {
      s += char(c);
    } else {
      s += "\\x";
      s += kHex[c >> 4];
      s += kHex[c & 15];
    }
  }
  if (token.size() > kMaxShown) s += "...";
  return s + "\"";
}

}  // namespace oocsimp
