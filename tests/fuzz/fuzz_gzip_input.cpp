// libFuzzer target: gzip input. The input bytes are written as an .obj.gz file, so
// that the inflater meets them as they are (truncated members, bad headers, data after
// the last member, members one after another), then the OBJ reader what it inflates.
// The input is read as read_outcome reads any file: InputError and IoError are the
// clean outcomes, and nothing may be left in the scratch folder; see fuzz_common.hpp.
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  oocsimp_fuzz::init_process();
  const std::string name = "input.obj.gz";
  const std::string path = oocsimp_fuzz::Scratch::path() + "/" + name;
  oocsimp_fuzz::write_bytes(path, data, size);
  oocsimp_fuzz::read_outcome(path);
  oocsimp_fuzz::check_no_leftovers({name});
  ::unlink(path.c_str());
  return 0;
}
