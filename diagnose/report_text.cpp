#include "diagnose/report_text.hpp"

#include <fstream>
#include <sstream>

#include "report/gnuplot.hpp"

namespace driftless::diagnose::report_text {
namespace {

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

// through the one gnuplot runner (report/gnuplot.hpp), which runs gnuplot inside `dir`
std::string gnuplot_png(const std::filesystem::path& dir, const std::string& stem, const std::string& script,
                        int width_px, int height_px) {
  report::Figure f(stem, script);
  f.width_px = width_px;
  f.height_px = height_px;
  f.svg = false;
  f.csv_defaults = false;
  f.font = "sans,9";
  f.empty_is_failure = true;
  std::filesystem::remove(dir / (stem + ".png"));
  if (!report::render(dir, f).ok) return {};
  return read_file(dir / (stem + ".png"));
}

}  // namespace driftless::diagnose::report_text
