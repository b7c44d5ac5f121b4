// A parallel pipeline whose results are merged in input order.
#pragma once

#include <tbb/concurrent_queue.h>
#include <tbb/parallel_pipeline.h>

#include <memory>
#include <vector>

namespace oocsimp {

/// Runs produce → work → merge over chunks: `produce(Chunk&)` (serial, in order) fills
/// the next chunk and returns false when the input is exhausted; `work(Chunk&)` runs
/// in parallel; `merge(Chunk&)` runs serially in the order the chunks were produced.
/// Chunk objects are recycled (at most `tokens` exist), so buffers inside them are
/// allocated once. Because chunk boundaries come from the input alone and merges
/// happen in input order, the result does not depend on the number of threads.
template <class Chunk, class Produce, class Work, class Merge>
void run_ordered_pipeline(std::size_t tokens, Produce produce, Work work, Merge merge) {
  std::vector<std::unique_ptr<Chunk>> pool;
  tbb::concurrent_queue<Chunk*> free_chunks;
  for (std::size_t i = 0; i < tokens; ++i) {
    pool.push_back(std::make_unique<Chunk>());
    free_chunks.push(pool.back().get());
  }
  tbb::parallel_pipeline(
      tokens, tbb::make_filter<void, Chunk*>(tbb::filter_mode::serial_in_order, [&](tbb::flow_control& fc) -> Chunk* {
                Chunk* c = nullptr;
                free_chunks.try_pop(c);  // never empty: tokens bound the chunks in flight
                if (!produce(*c)) {
                  free_chunks.push(c);
                  fc.stop();
                  return nullptr;
                }
                return c;
              }) & tbb::make_filter<Chunk*, Chunk*>(tbb::filter_mode::parallel, [&](Chunk* c) {
                work(*c);
                return c;
              }) & tbb::make_filter<Chunk*, void>(tbb::filter_mode::serial_in_order, [&](Chunk* c) {
                merge(*c);
                free_chunks.push(c);
              }));
}

}  // namespace oocsimp
