// The MPI side of a distributed simplify (mpi_run.hpp), built as a module of its own
// that the CLI loads only when an MPI launcher started it: every other run starts
// without loading Open MPI's libraries.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "mpi_run.hpp"

namespace oocsimp_cli {

namespace {

// MPI_Init and MPI_Finalize around the job.
class MpiSession {
 public:
  MpiSession() { MPI_Init(nullptr, nullptr); }
  ~MpiSession() { MPI_Finalize(); }
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const {
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
  }
  int size() const {
    int s = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
  }
};

// Rank 0's string on every rank.
std::string broadcast(const std::string& text, int rank) {
  unsigned long long n = text.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string out = rank == 0 ? text : std::string(std::size_t(n), '\0');
  MPI_Bcast(out.data(), int(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  return out;
}

// Waits for `request` without spinning. MPI's blocking calls poll at full speed, so a
// rank waiting for rank 0's merge (or for its whole run) would take a core from the
// ranks at work where they share the machine; naps of at most 250 us cost little.
// The naps grow from 20 us, so that the ranks' short exchanges (a floating run's
// sweeps meet 8 times a sweep) are not held up by them.
void wait_idle(MPI_Request* request) {
  std::chrono::microseconds nap(20);
  for (;;) {
    int done = 0;
    MPI_Test(request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(nap);
    nap = std::min(2 * nap, std::chrono::microseconds(250));
  }
}

// Rank 0's `value` on every rank, waited for idly.
void broadcast_idle(int* value) {
  MPI_Request request;
  MPI_Ibcast(value, 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
  wait_idle(&request);
}

// The exchange of parts that run at once (PartOptions::exchange): every rank's bytes
// to every rank, the sizes first (MPI_Iallgather), then the bytes (MPI_Iallgatherv),
// waited for idly. Every rank makes the same exchanges in the same order, so a rank
// whose part failed must not leave the others waiting in one: after its part, each
// rank joins size rounds (finish) with a size that says whether it failed or is
// done, until every rank says one or the other; a rank at an exchange that meets a
// failed rank's size stops its part (throws), and comes to finish too.
class RankExchange {
 public:
  std::vector<std::vector<unsigned char>> all_gather(const std::vector<unsigned char>& mine) {
    const std::vector<unsigned long long> sizes = gather_working_sizes(mine.size());
    unsigned long long total = 0;
    for (unsigned long long s : sizes) total += s;
    if (total > (1ull << 31) - 1)
      throw std::runtime_error("the ranks' exchange exceeds 2 GiB: give more ranks or a coarser --grid");
    std::vector<int> counts(sizes.size()), displacements(sizes.size());
    int at = 0;
    for (std::size_t r = 0; r < sizes.size(); ++r) {
      counts[r] = int(sizes[r]);
      displacements[r] = at;
      at += counts[r];
    }
    std::vector<unsigned char> all(std::size_t(total) + 1);
    MPI_Request request;
    MPI_Iallgatherv(mine.data(), int(mine.size()), MPI_BYTE, all.data(), counts.data(), displacements.data(), MPI_BYTE,
                    MPI_COMM_WORLD, &request);
    wait_idle(&request);
    std::vector<std::vector<unsigned char>> out(sizes.size());
    for (std::size_t r = 0; r < sizes.size(); ++r)
      out[r].assign(all.begin() + displacements[r], all.begin() + displacements[r] + counts[r]);
    return out;
  }

  // Each rank's message for each rank (PartOptions::deliver): the sizes of what every
  // rank sends in all first (a failed rank's size says so, as for all_gather), then
  // each pair's sizes (MPI_Ialltoall), then the messages point to point, straight
  // from and into their own buffers.
  std::vector<std::vector<unsigned char>> all_to_all(const std::vector<std::vector<unsigned char>>& to_each) {
    unsigned long long total = 0;
    for (const auto& m : to_each) total += m.size();
    const std::vector<unsigned long long> sizes = gather_working_sizes(total);
    const std::size_t ranks = sizes.size();
    if (to_each.size() != ranks) throw std::logic_error("a message for each rank expected");
    // Checked on every rank alike, before any message moves: a pair's message is at
    // most its sender's total.
    for (unsigned long long s : sizes)
      if (s > (1ull << 31) - 1)
        throw std::runtime_error("a rank's messages exceed 2 GiB: give a smaller --mem or more ranks");
    int me = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &me);
    std::vector<unsigned long long> send_sizes(ranks), receive_sizes(ranks);
    for (std::size_t r = 0; r < ranks; ++r) send_sizes[r] = to_each[r].size();
    MPI_Request request;
    MPI_Ialltoall(send_sizes.data(), 1, MPI_UNSIGNED_LONG_LONG, receive_sizes.data(), 1, MPI_UNSIGNED_LONG_LONG,
                  MPI_COMM_WORLD, &request);
    wait_idle(&request);
    std::vector<std::vector<unsigned char>> out(ranks);
    std::vector<MPI_Request> requests;
    requests.reserve(2 * ranks);
    constexpr int kTag = 7;
    for (std::size_t r = 0; r < ranks; ++r) {
      if (int(r) == me) {
        out[r] = to_each[r];
        continue;
      }
      out[r].resize(std::size_t(receive_sizes[r]));
      if (receive_sizes[r]) {
        requests.emplace_back();
        MPI_Irecv(out[r].data(), int(receive_sizes[r]), MPI_BYTE, int(r), kTag, MPI_COMM_WORLD, &requests.back());
      }
      if (send_sizes[r]) {
        requests.emplace_back();
        MPI_Isend(to_each[r].data(), int(send_sizes[r]), MPI_BYTE, int(r), kTag, MPI_COMM_WORLD, &requests.back());
      }
    }
    for (MPI_Request& r : requests) wait_idle(&r);
    return out;
  }

  // After the part, whatever became of it: size rounds until every rank has ended.
  void finish(bool failed) {
    for (;;) {
      const std::vector<unsigned long long> sizes = gather_sizes(failed ? kFailed : kDone);
      bool all_ended = true;
      for (unsigned long long s : sizes) all_ended = all_ended && (s == kFailed || s == kDone);
      if (all_ended) return;
    }
  }

  // Whether this rank's part stopped because another's failed (not a failure of its own).
  bool stopped() const { return stopped_; }

 private:
  static constexpr unsigned long long kFailed = ~0ull, kDone = ~0ull - 1;

  // Every rank's size, once every rank is still at work: a rank whose size says it
  // failed or is done stops this one's part (throws).
  std::vector<unsigned long long> gather_working_sizes(unsigned long long mine) {
    std::vector<unsigned long long> sizes = gather_sizes(mine);
    for (std::size_t r = 0; r < sizes.size(); ++r)
      if (sizes[r] == kFailed || sizes[r] == kDone) {
        stopped_ = true;
        throw std::runtime_error("rank " + std::to_string(r) + " failed; this rank stops too");
      }
    return sizes;
  }

  std::vector<unsigned long long> gather_sizes(unsigned long long mine) {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    std::vector<unsigned long long> sizes(std::size_t(size), 0);
    MPI_Request request;
    MPI_Iallgather(&mine, 1, MPI_UNSIGNED_LONG_LONG, sizes.data(), 1, MPI_UNSIGNED_LONG_LONG, MPI_COMM_WORLD, &request);
    wait_idle(&request);
    return sizes;
  }

  bool stopped_ = false;
};

// A rank's status when its part stopped because another rank's failed.
constexpr int kStoppedByOtherRank = -2;

}  // namespace

static int run_ranks(const MpiJob& job) {
  MpiSession mpi;
  const int rank = mpi.rank(), size = mpi.size();
  if (size < 2) return -1;  // one rank: an ordinary run (MPI_Finalize on the way out)
  if (!job.run_part) {
    int result = rank == 0 ? job.whole() : 0;
    broadcast_idle(&result);
    return result;
  }
  // The shared folder: the one given, or one rank 0 makes under the temp folder.
  int status = 0;
  std::string dir = job.work_dir;
  const bool own_dir = dir.empty();
  if (own_dir) {
    if (rank == 0) {
      const std::string& base = job.temp_dir;
      std::string pattern = base + "/oocsimp-mpi-XXXXXX";
      if (!::mkdtemp(pattern.data())) {
        std::fprintf(stderr, "oocsimp: %s: cannot make the ranks' work folder\n", base.c_str());
        pattern.clear();
      }
      dir = pattern;
    }
    dir = broadcast(dir, rank);
    if (dir.empty()) status = 4;
  }
  if (status == 0) {
    RankExchange exchange;
    oocsimp::PartOptions part;
    part.index = std::uint32_t(rank);
    part.count = std::uint32_t(size);
    part.work_dir = dir;
    part.exchange = [&exchange](const std::vector<unsigned char>& mine) { return exchange.all_gather(mine); };
    part.deliver = [&exchange](const std::vector<std::vector<unsigned char>>& to_each) {
      return exchange.all_to_all(to_each);
    };
    status = job.run_part(part);
    exchange.finish(status != 0);
    if (status != 0 && exchange.stopped()) status = kStoppedByOtherRank;
  } else {
    RankExchange().finish(true);
  }
  // Every rank's status at rank 0, which names the failed ones and merges otherwise.
  std::vector<int> statuses(std::size_t(size), 0);
  MPI_Request gathered;
  MPI_Igather(&status, 1, MPI_INT, statuses.data(), 1, MPI_INT, 0, MPI_COMM_WORLD, &gathered);
  wait_idle(&gathered);
  int result = 0;
  if (rank == 0) {
    for (int r = 0; r < size; ++r)
      if (statuses[std::size_t(r)] != 0 && statuses[std::size_t(r)] != kStoppedByOtherRank) {
        std::fprintf(stderr, "oocsimp: rank %d of %d failed (exit %d); no output written\n", r, size,
                     statuses[std::size_t(r)]);
        if (result == 0) result = statuses[std::size_t(r)];
      }
    if (result == 0) result = job.merge(dir);
    if (own_dir) {
      std::error_code ignored;
      std::filesystem::remove_all(dir, ignored);
    }
  }
  broadcast_idle(&result);
  return result;
}

}  // namespace oocsimp_cli

/// The module's one entry point (kMpiEntryPoint): run_mpi_job() on this process's
/// rank, `job->temp_dir` already resolved.
extern "C" __attribute__((visibility("default"))) int oocsimp_mpi_run_job(const oocsimp_cli::MpiJob* job) {
  return oocsimp_cli::run_ranks(*job);
}
