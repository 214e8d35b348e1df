#pragma once
// Deterministic parallel loops: work is cut into fixed blocks of kBlock items, independent of the
// thread count, so any per-block partial result (an energy sum) is the same on 1 or 2 threads and
// is combined in block order. Loops of fewer than kMinParallelBlocks blocks run on the calling
// thread: below that the threads' barrier costs more than it saves, and on a loaded machine a
// barrier can wait a whole scheduler time slice.
#include <algorithm>
#include <cstddef>

namespace drape::sim {

inline constexpr size_t kBlock = 1024;
inline constexpr std::ptrdiff_t kMinParallelBlocks = 8;
inline size_t block_count(size_t n) { return (n + kBlock - 1) / kBlock; }

// body(block_index, begin, end) for each block, blocks spread statically over the threads.
template <class Body>
void parallel_blocks(size_t n, Body&& body) {
  const std::ptrdiff_t blocks = static_cast<std::ptrdiff_t>(block_count(n));
#pragma omp parallel for schedule(static) if (blocks >= kMinParallelBlocks)
  for (std::ptrdiff_t b = 0; b < blocks; ++b) {
    const size_t begin = static_cast<size_t>(b) * kBlock;
    body(static_cast<size_t>(b), begin, std::min(n, begin + kBlock));
  }
}

}  // namespace drape::sim
