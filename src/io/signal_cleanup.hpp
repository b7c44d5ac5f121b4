// What the clean-up signal handlers (temp_file.cpp, install_signal_cleanup) know
// besides the temporary files: the memory-mapped files, so that a SIGBUS from a
// mapped input that shrank during the run is told from a crash.
#pragma once

#include <cstddef>
#include <string>

namespace oocsimp {

/// Records that [base, base + size) maps `path`; returns a slot for
/// unregister_mapping, or -1 when the table is full (a SIGBUS there is then a crash).
int register_mapping(const void* base, std::size_t size, const std::string& path);
void unregister_mapping(int slot);

}  // namespace oocsimp
