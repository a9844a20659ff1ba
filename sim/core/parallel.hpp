// The one place that says "#pragma omp". Loops gather: iteration i writes only entries of i, so results never
// depend on the thread count. Reductions sum fixed-size blocks, then combine the block results in block
// order: the same bits for 1 or 32 threads (the pattern Box2D's determinism test relies on).
#pragma once

#include <omp.h>

#include <cstddef>
#include <vector>

namespace aortasph {

template <class F>
void parallel_for(std::size_t n, F&& f) {
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
}

// Same, with dynamic scheduling in chunks: for loops whose cost per item varies (neighbour loops).
template <class F>
void parallel_for_dynamic(std::size_t n, F&& f) {
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(dynamic, 512)
  for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
}

// One item at a time to whichever thread is free: for a few large, uneven work items.
template <class F>
void parallel_for_dynamic_chunks(std::size_t n, F&& f) {
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
}

inline constexpr std::size_t kReduceBlock = 4096;

// value(i) -> T; combine(T, T) -> T. Blocks of kReduceBlock items are folded left to right, then the block
// results are folded in block order.
template <class T, class Value, class Combine>
T parallel_reduce(std::size_t n, T identity, Value&& value, Combine&& combine) {
  const std::size_t blocks = (n + kReduceBlock - 1) / kReduceBlock;
  std::vector<T> partial(blocks, identity);
  parallel_for(blocks, [&](std::size_t b) {
    T acc = identity;
    const std::size_t end = std::min(n, (b + 1) * kReduceBlock);
    for (std::size_t i = b * kReduceBlock; i < end; ++i) acc = combine(acc, value(i));
    partial[b] = acc;
  });
  T total = identity;
  for (const T& p : partial) total = combine(total, p);
  return total;
}

inline int max_threads() {
  return omp_get_max_threads();
}
inline void set_threads(int n) {
  omp_set_num_threads(n);
}

}  // namespace aortasph
