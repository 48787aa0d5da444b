// Large arrays written once from front to back (a 5 M-sample record is 40 MB a channel) fault in
// 4 kB at a time: some 10 000 page faults each. Asking the kernel for transparent huge pages there
// makes it 2 MB at a time. A hint only: where THP is off (or "never") nothing changes, and the
// contents are the same either way.
#pragma once

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>

namespace driftless::est {

/// Advises THP for the whole 2 MB pages inside [p, p + bytes); nothing for less than 4 MB.
inline void advise_huge_pages(const void* p, std::size_t bytes) {
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  if (p == nullptr || bytes < 2 * kHuge) return;
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t b = (at + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t e = (at + bytes) & ~(kHuge - 1);
  if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
}

/// The same for a vector's reserved storage (call it after reserve(), before the writes).
template <class Vector>
void advise_huge_pages(const Vector& v) {
  advise_huge_pages(v.data(), v.capacity() * sizeof(typename Vector::value_type));
}

}  // namespace driftless::est
