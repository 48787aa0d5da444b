// The one gnuplot runner: every figure the program draws (estimate Fig. 4/5/9, allan, sweep plots,
// the compare/diagnose report) is a script next to its data, rendered to PNG (and SVG) by this
// function, so users can restyle and re-run it (`gnuplot fig.gp`). It checks gnuplot's exit
// status and never prints: the caller decides how loud a failed figure is.
#pragma once

#include <filesystem>
#include <string>
#include <utility>

namespace driftless::report {

/// One figure: the plot commands and how to render them.
struct Figure {
  Figure(std::string stem_, std::string body_) : stem(std::move(stem_)), body(std::move(body_)) {}
  std::string stem;             // files: <stem>.gp, <stem>.png, <stem>.svg, <stem>.gp.log
  std::string body;             // plot commands; data paths relative to the folder
  std::string title_comment;    // first line of the script ("" = "<stem>: rendered by driftless")
  int width_px = 1200;          // px
  int height_px = 800;          // px
  bool svg = true;              // also write <stem>.svg
  bool csv_defaults = true;     // separator ',', '' = missing, column heads as titles, grid, key outside right
  std::string font;             // terminal font, e.g. "sans,9" ("" = gnuplot's default)
  bool empty_is_failure = false;  // a plot where gnuplot found no valid points counts as failed
};

/// What rendering gave.
struct PlotStatus {
  bool ok = false;
  std::string message;  // when not ok: what failed, naming the script and gnuplot's log
};

/// The script render() writes for `f` (PNG through pngcairo when gnuplot has it, else png).
std::string gnuplot_script(const Figure& f);

/// Writes dir/<stem>.gp and runs gnuplot in `dir`. Not ok when gnuplot is missing, exits non-zero,
/// or (empty_is_failure) drew no points; its messages stay in <stem>.gp.log (removed on success). Throws
/// std::runtime_error naming the path when the script cannot be written.
PlotStatus render(const std::filesystem::path& dir, const Figure& f);

}  // namespace driftless::report
