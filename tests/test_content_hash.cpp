// The content checksum behind --keep-tmp (src/io/content_hash.hpp).
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>

#include "io/content_hash.hpp"
#include "test_support.hpp"

using namespace oocsimp;
using namespace oocsimp_test;

namespace {
// 256 bytes 0..255 four times, then "xyz": every code path (stripes, 8-, 4- and
// 1-byte tails).
std::string sample() {
  std::string s;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 256; ++i) s.push_back(char(i));
  return s + "xyz";
}
}  // namespace

TEST_CASE("the content hash is XXH64", "[hash]") {
  // Values from the reference implementation (libxxhash 0.8.1, XXH64 with seed 0).
  CHECK(content_hash("", 0) == 0xEF46DB3751D8E999ull);
  CHECK(content_hash("a", 1) == 0xD24EC4F1A98C6E5Bull);
  CHECK(content_hash("abc", 3) == 0x44BC2CF5AD770999ull);
  std::string s = sample();
  CHECK(content_hash(s.data(), s.size()) == 0xE146CB31B65BC21Aull);
}

TEST_CASE("the content hash does not depend on how the bytes are split", "[hash]") {
  const std::string s = sample();
  const std::uint64_t whole = content_hash(s.data(), s.size());
  for (std::size_t piece : {1u, 3u, 7u, 31u, 32u, 33u, 100u}) {
    CAPTURE(piece);
    ContentHash h;
    for (std::size_t at = 0; at < s.size(); at += piece) h.add(s.data() + at, std::min(piece, s.size() - at));
    CHECK(h.digest() == whole);
  }
  ScratchDir d;
  write_file(d.file("f"), s);
  FileDigest f = file_digest(d.file("f"));
  CHECK(f.size == s.size());
  CHECK(f.hash == whole);
}
