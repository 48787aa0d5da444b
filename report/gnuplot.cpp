#include "report/gnuplot.hpp"

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

namespace driftless::report {
namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// a terminal command for one output, pngcairo falling back to png (gnuplot-nox may lack cairo)
std::string terminal(const Figure& f, bool svg) {
  const std::string font = f.font.empty() ? "" : fmt::format(" font '{}'", f.font);
  const std::string size = fmt::format("size {},{}", f.width_px, f.height_px);
  if (svg) return fmt::format("set terminal svg {} noenhanced{}; set output '{}.svg'", size, font, f.stem);
  return fmt::format(
      "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {{ set terminal pngcairo {0} noenhanced{1} }} "
      "else {{ set terminal png {0}{1} }}; set output '{2}.png'",
      size, font, f.stem);
}

// the shell's exit status of a command run through std::system (127: not found)
int exit_status(int rc) {
  if (rc == -1) return -1;
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + (WIFSIGNALED(rc) ? WTERMSIG(rc) : 0);
}

}  // namespace

std::string gnuplot_script(const Figure& f) {
  std::string s = "# " + (f.title_comment.empty() ? f.stem + ": rendered by driftless" : f.title_comment) +
                  "; edit and run `gnuplot " + f.stem + ".gp` in this folder\n";
  if (f.csv_defaults) {
    s += "set datafile separator ','\nset datafile missing ''\nset key autotitle columnhead\n";
    s += "set grid\nset key outside right\n";
  }
  s += "do for [term in '" + std::string(f.svg ? "png svg" : "png") + "'] {\n";
  s += "  if (term eq 'png') { " + terminal(f, false) + " }";
  if (f.svg) s += " else { " + terminal(f, true) + " }";
  s += "\n" + f.body + "\n  unset output\n}\n";
  return s;
}

PlotStatus render(const std::filesystem::path& dir, const Figure& f) {
  const auto gp = dir / (f.stem + ".gp");
  const auto log = dir / (f.stem + ".gp.log");
  {
    std::ofstream out(gp, std::ios::binary);
    out << gnuplot_script(f);
    out.close();
    if (!out) throw std::runtime_error(gp.string() + ": cannot write the gnuplot script");
  }
  const std::string cmd = fmt::format("cd '{}' && gnuplot '{}.gp' > '{}.gp.log' 2>&1", dir.string(), f.stem, f.stem);
  const int status = exit_status(std::system(cmd.c_str()));
  if (status == 127) return {false, "gnuplot not found (install gnuplot); " + gp.string() + " and its data are kept"};
  // a plot without one valid point is "no data" whether gnuplot then fails ("x range is invalid")
  // or draws an empty frame
  const std::string msgs = f.empty_is_failure ? read_text(log) : std::string();
  if (msgs.find("no valid points") != std::string::npos || msgs.find("all points") != std::string::npos) {
    return {false, fmt::format("{}: no data to draw (messages in {})", gp.string(), log.string())};
  }
  if (status != 0) {
    return {false, fmt::format("gnuplot failed on {} (exit status {}, messages in {}); the script and data are kept",
                               gp.string(), status, log.string())};
  }
  std::filesystem::remove(log);
  return {true, {}};
}

}  // namespace driftless::report
