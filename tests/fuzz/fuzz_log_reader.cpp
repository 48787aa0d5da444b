// libFuzzer harness: the log reader (metadata, header, rows, validation) on arbitrary bytes.
// Any exception that is not a LogError, a crash or a sanitizer report is a finding.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "estimator/log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // a file in memory where there is a RAM disk: the reader reads files
  static const std::string path = std::string(::access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp") +
                                  "/driftless_fuzz_log_" + std::to_string(::getpid()) + ".csv";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  for (const bool single : {false, true}) {
    driftless::log::ReaderOptions opts;
    opts.accept_single_sensor = single;
    opts.fields = size % 2 == 0 ? driftless::log::kAllFieldGroups : driftless::kFieldRefQ;
    try {
      driftless::log::LogReader reader(path, opts);
      driftless::Sample s;
      while (reader.next(s)) {
        if (!(s.t_s == s.t_s)) __builtin_trap();  // a returned row always has a finite time
      }
      (void)reader.metadata().hinge1_axis();
      (void)reader.metadata().sample_rate_hz();
    } catch (const driftless::log::LogError&) {
    }
  }
  return 0;
}
