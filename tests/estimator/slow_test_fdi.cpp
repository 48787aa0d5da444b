// The FDI tests with more seeds: 3 per planted fault, 40 fault-free 10 min runs (about 4 s in
// RelWithDebInfo, too slow for the sanitizer pass). Same tests as test_fdi.cpp.
#define DRIFTLESS_FDI_SEEDS 3
#define DRIFTLESS_FDI_CLEAN_SEEDS 40
#include "tests/estimator/test_fdi.cpp"  // NOLINT(bugprone-suspicious-include): same tests, more seeds
