#include "cli/plot.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#include <fmt/core.h>
#include <fmt/os.h>

namespace driftless::cli {

std::string render_gnuplot(const std::filesystem::path& dir, const std::string& stem, const std::string& body) {
  const auto gp = dir / (stem + ".gp");
  {
    std::ofstream f(gp);
    if (!f) throw std::runtime_error("cannot write " + gp.string());
    f << "# " << stem << ": rendered by driftless; edit and run `gnuplot " << stem << ".gp` in this folder\n";
    f << "set datafile separator ','\nset datafile missing ''\nset key autotitle columnhead\n";
    f << "set grid\nset key outside right\n";
    f << "do for [term in 'png svg'] {\n";
    f << "  if (term eq 'png') { set terminal pngcairo size 1200,800 noenhanced; set output '" << stem
      << ".png' } else { set terminal svg size 1200,800 noenhanced; set output '" << stem << ".svg' }\n";
    f << body << "\n";
    f << "  unset output\n}\n";
  }
  const std::string cmd = fmt::format("cd '{}' && gnuplot '{}.gp' 2> '{}.gp.log'", dir.string(), stem, stem);
  const int rc = std::system(cmd.c_str());
  if (rc != 0) {
    return fmt::format("gnuplot failed on {} (see {}.gp.log); the script and data are kept", gp.string(), stem);
  }
  std::filesystem::remove(dir / (stem + ".gp.log"));
  return {};
}

void write_allan_table(const std::filesystem::path& path, const std::vector<AllanTableColumn>& cols) {
  auto out = fmt::output_file(path.string());
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
}

}  // namespace driftless::cli
