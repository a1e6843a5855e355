#pragma once
// body(a, b) over [0, n) split into contiguous chunks on up to `threads` threads (at least 256
// items a thread; 1 thread: called inline). Returns when every chunk is done. Private to offline/.
#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace studio::offline::detail {

void parallel_for(std::size_t n, int threads, const auto& body) {
  threads = std::max(1, std::min<int>(threads, int(n / 256) + 1));
  if (threads == 1) {
    body(std::size_t{0}, n);
    return;
  }
  std::vector<std::jthread> pool;
  const std::size_t chunk = (n + std::size_t(threads) - 1) / std::size_t(threads);
  for (int w = 0; w < threads; ++w) {
    const std::size_t a = std::min(n, w * chunk), b = std::min(n, a + chunk);
    pool.emplace_back([&body, a, b] { body(a, b); });
  }
}

}  // namespace studio::offline::detail
