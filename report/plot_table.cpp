#include "report/plot_table.hpp"

#include <algorithm>

#include <fmt/core.h>

#include "report/text_file.hpp"

namespace driftless::report {

void write_allan_table(const std::filesystem::path& path, const std::vector<AllanTableColumn>& cols) {
  TextFile out(path);
  std::size_t rows = 0;
  out.print("tau_s");
  for (const auto& c : cols) {
    out.print(",{0},{0}_lo,{0}_hi", c.name);
    rows = std::max(rows, c.tau_s.size());
  }
  out.print("\n");
  for (std::size_t i = 0; i < rows; ++i) {
    double tau = 0.0;
    for (const auto& c : cols) {
      if (i < c.tau_s.size()) tau = c.tau_s[i];
    }
    out.print("{:.6g}", tau);
    for (const auto& c : cols) {
      if (i < c.adev.size()) out.print(",{:.6e},{:.6e},{:.6e}", c.adev[i], c.lo[i], c.hi[i]);
      else out.print(",,,");
    }
    out.print("\n");
  }
  out.commit();
}

}  // namespace driftless::report
