#!/usr/bin/env bash
# What writing fresh anonymous memory costs on this machine: 256 MiB copied in 32 KiB
# blocks into 8 MiB mappings, each mapping new, as the spill fills its slabs and a tile
# its arrays. Three ways: pages faulted in as written (4 KiB faults), faulted in by
# MADV_POPULATE_WRITE a MiB ahead (what MemorySlabs does on small budgets), and over
# 2 MiB pages (mappings aligned to 2 MiB, MADV_HUGEPAGE, populated ahead). Each is run
# three times; the first run of a kind can pay for memory the host has not backed yet.
# In a virtual machine a fault is dear: compare the GB/s (docs/benchmarks.md, "Fresh
# memory").
#
#   scripts/probe-fresh-memory.sh
set -euo pipefail
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
cat >"$dir/probe.cpp" <<'EOF'
#include <sys/mman.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

int main() {
  const std::size_t slab = std::size_t(8) << 20, total = std::size_t(256) << 20, block = 32 << 10;
  const std::size_t huge = std::size_t(2) << 20, ahead = std::size_t(1) << 20;
  const char* names[] = {"4 KiB pages, faulted as written", "4 KiB pages, populated ahead", "2 MiB pages"};
  std::vector<char> source(block, 7);
  for (int kind = 0; kind < 3; ++kind)
    for (int run = 0; run < 3; ++run) {
      double seconds = 0;
      std::vector<std::pair<void*, std::size_t>> maps;
      for (std::size_t done = 0; done < total; done += slab) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::size_t length = kind == 2 ? slab + huge : slab;
        void* raw = mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (raw == MAP_FAILED) return 1;
        maps.push_back({raw, length});
        char* p = static_cast<char*>(raw);
        if (kind == 2) {
          p = reinterpret_cast<char*>((reinterpret_cast<std::uintptr_t>(raw) + huge - 1) & ~(huge - 1));
          madvise(p, slab, MADV_HUGEPAGE);
        }
        for (std::size_t at = 0; at < slab; at += block) {
          if (kind > 0 && at % ahead == 0) madvise(p + at, ahead, MADV_POPULATE_WRITE);
          std::memcpy(p + at, source.data(), block);
        }
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      }
      for (const auto& m : maps) munmap(m.first, m.second);
      std::printf("%-34s run %d: %7.1f ms, %6.2f GB/s\n", names[kind], run + 1, 1e3 * seconds,
                  double(total) / 1e9 / seconds);
    }
}
EOF
g++ -O2 -std=c++17 "$dir/probe.cpp" -o "$dir/probe"
"$dir/probe"
