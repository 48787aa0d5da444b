// The six gyro channels are independent in the noise-density searches (build, refit, noise
// model): they run on the machine's cores. Each index writes only its own slot, so the result
// is the same, bit for bit, whatever the number of threads (docs/compare.md "Speed").
#pragma once

#include <functional>

namespace driftless::diagnose {

/// Calls fn(i) once for every i in [0, n), on up to min(n, hardware threads) threads. After all
/// have finished, rethrows the exception of the lowest index that threw, if any.
void for_each_index(int n, const std::function<void(int)>& fn);

}  // namespace driftless::diagnose
