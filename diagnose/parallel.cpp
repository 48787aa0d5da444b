#include "diagnose/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace driftless::diagnose {

namespace {

// glibc gives every new thread a heap (arena) of its own, which keeps the multi-MB blocks a
// worker frees for that thread alone: 19 MB of an hour's diagnosis peak. The workers here are
// few and allocate rarely, so they share the main heap (no lock contention worth measuring)
void share_one_heap() {
#if defined(__GLIBC__)
  static const bool once = [] { return mallopt(M_ARENA_MAX, 1) == 1; }();
  (void)once;
#endif
}

}  // namespace

void for_each_index(int n, const std::function<void(int)>& fn) {
  if (n <= 0) return;
  share_one_heap();
  const int workers = std::min(n, static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n));
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i = next++; i < n; i = next++) {
      try {
        fn(i);
      } catch (...) {
        errors[static_cast<std::size_t>(i)] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work);
  work();  // the calling thread takes its share
  for (auto& t : pool) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace driftless::diagnose
