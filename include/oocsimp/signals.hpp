// oocsimp — clean-up of temporary files on signals, for programs that run long jobs.
#pragma once

namespace oocsimp {

/// Installs SIGINT, SIGTERM, SIGHUP and SIGQUIT handlers that delete all registered
/// temporary files and then terminate the process with the conventional status
/// (128 + signal), and ignores SIGXFSZ and SIGPIPE, so that a write beyond a file-size
/// limit (ulimit -f) fails with EFBIG, and one into a pipe or FIFO whose reader has gone
/// with EPIPE, and the run cleans up and exits 4 instead of being killed. A SIGBUS from reading a memory-mapped input
/// that shrank during the run (truncated by another process) deletes them too and exits 4 with "oocsimp: FILE: input
/// changed during the run"; any other SIGBUS is a crash after the clean-up.
void install_signal_cleanup();

}  // namespace oocsimp
