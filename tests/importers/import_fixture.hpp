// Shared helpers of the importer tests: the real recordings, temporary files, reading a whole stream.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "importers/imu_reader.hpp"

namespace driftless::importers::test {

inline std::filesystem::path realdata() { return std::filesystem::path(DRIFTLESS_SOURCE_DIR) / ".." / "shared" / "realdata"; }
inline std::filesystem::path sunsided_10min() {
  return realdata() / "mpu6050-sunsided" / "unmoved-with-x-pointing-forward-10min" / "mpu6050.csv";
}
inline std::filesystem::path tomisuarez_static() { return realdata() / "mpu6050-tomisuarez2" / "imu_static_test.csv"; }

/// A fresh folder in the test's temporary folder (under CTest, one of the test's own that is removed
/// when it passes: tests/run_in_scratch.sh; the pid keeps two processes apart without it).
inline std::filesystem::path scratch(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() /
                 ("importers_" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

inline void write_text(const std::filesystem::path& p, const std::string& s) {
  std::ofstream f(p, std::ios::binary);
  f << s;
}

/// Every row of a reader: t (s), then the channels.
struct Table {
  std::vector<double> t;
  std::vector<std::vector<double>> ch;
  std::vector<std::uint64_t> loc;
};

/// bare: ImuBlock::bare_untimed (an unstamped source then gives no t and no loc)
inline Table read_all(ImuReader& r, std::size_t block = 1000, bool bare = false) {
  Table out;
  out.ch.resize(r.info().channels.size());
  ImuBlock b;
  b.bare_untimed = bare;
  while (r.read(b, block)) {
    EXPECT_EQ(b.rows(), b.values.empty() ? b.t_s.size() : b.values.front().size());
    out.t.insert(out.t.end(), b.t_s.begin(), b.t_s.end());
    out.loc.insert(out.loc.end(), b.loc.begin(), b.loc.end());
    for (std::size_t c = 0; c < out.ch.size(); ++c) out.ch[c].insert(out.ch[c].end(), b.values[c].begin(), b.values[c].end());
  }
  return out;
}

/// The real sunsided 10-min recording read as plain CSV (columns as in its header).
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
};
inline Csv plain_csv(const std::filesystem::path& p) {
  Csv c;
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  for (std::size_t b = 0;;) {
    const auto e = line.find(',', b);
    c.header.push_back(line.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  while (std::getline(in, line)) {
    std::vector<double> r;
    for (std::size_t b = 0;;) {
      const auto e = line.find(',', b);
      r.push_back(std::stod(line.substr(b, e == std::string::npos ? std::string::npos : e - b)));
      if (e == std::string::npos) break;
      b = e + 1;
    }
    c.rows.push_back(std::move(r));
  }
  return c;
}

#define DRIFTLESS_NEED_REALDATA()                                                    \
  if (!std::filesystem::exists(::driftless::importers::test::sunsided_10min())) {    \
    GTEST_SKIP() << "real data not present at " << ::driftless::importers::test::realdata(); \
  }

}  // namespace driftless::importers::test
