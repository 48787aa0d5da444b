#include "report/gnuplot.hpp"

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/output_file.hpp"

namespace driftless::report {
namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// a terminal command for one output, pngcairo falling back to png (gnuplot-nox may lack cairo); the
// output is the variable png_out / svg_out, which the script defaults to <stem>.png / .svg
std::string terminal(const Figure& f, bool svg) {
  const std::string font = f.font.empty() ? "" : fmt::format(" font '{}'", f.font);
  const std::string size = fmt::format("size {},{}", f.width_px, f.height_px);
  if (svg) return fmt::format("set terminal svg {} noenhanced{}; set output svg_out", size, font);
  return fmt::format(
      "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {{ set terminal pngcairo {0} noenhanced{1} }} "
      "else {{ set terminal png {0}{1} }}; set output png_out",
      size, font);
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
  // the program renders under temporary names (gnuplot -e "png_out='...'"); a user's run writes these
  s += "if (!exists('png_out')) png_out = '" + f.stem + ".png'\n";
  if (f.svg) s += "if (!exists('svg_out')) svg_out = '" + f.stem + ".svg'\n";
  s += "do for [term in '" + std::string(f.svg ? "png svg" : "png") + "'] {\n";
  s += "  if (term eq 'png') { " + terminal(f, false) + " }";
  if (f.svg) s += " else { " + terminal(f, true) + " }";
  s += "\n" + f.body + "\n  unset output\n}\n";
  return s;
}

PlotStatus render(const std::filesystem::path& dir, const Figure& f) {
  const auto gp = dir / (f.stem + ".gp");
  const auto log = dir / (f.stem + ".gp.log");
  io::write_file(gp, gnuplot_script(f));
  // the figures are drawn under temporary names and renamed only after gnuplot exited 0 and wrote
  // them (a full disk leaves no empty PNG that looks drawn)
  io::ExternalOutput png(dir / (f.stem + ".png"));
  std::optional<io::ExternalOutput> svg;
  std::string vars = fmt::format("png_out='{}'", png.partial().filename().string());
  if (f.svg) {
    svg.emplace(dir / (f.stem + ".svg"));
    vars += fmt::format("; svg_out='{}'", svg->partial().filename().string());
  }
  const std::string cmd =
      fmt::format("cd '{}' && gnuplot -e \"{}\" '{}.gp' > '{}.gp.log' 2>&1", dir.string(), vars, f.stem, f.stem);
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
  // exit 0 but no figure (a full disk): io::OutputError "<png>: gnuplot wrote an empty file"
  png.commit("gnuplot");
  if (svg) svg->commit("gnuplot");
  std::filesystem::remove(log);
  return {true, {}};
}

}  // namespace driftless::report
