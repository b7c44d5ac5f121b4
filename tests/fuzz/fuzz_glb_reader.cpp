// libFuzzer target: the binary glTF reader. The input bytes are written as a .glb file (and,
// for about half the inputs, also zstd-compressed as .glb.zst), opened with
// open_mesh_input, every position read once and the triangle stream drained twice;
// both copies must give the same mesh or both be rejected. InputError and IoError are
// the clean outcomes; see fuzz_common.hpp for the rest.
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  oocsimp_fuzz::fuzz_reader(data, size, ".glb");
  return 0;
}
