// The one gnuplot runner: a figure renders to PNG and SVG; a failing script, a missing gnuplot and
// an empty plot are reported (never printed, never silent).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "report/gnuplot.hpp"

namespace driftless::report {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("driftless_test_gnuplot_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

bool have_gnuplot() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

TEST(Gnuplot, RendersPngAndSvgFromCsvData) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path d = fresh_dir("ok");
  std::ofstream(d / "data.csv") << "t_s,y\n0,1\n1,2\n2,4\n";
  Figure f("fig", "plot 'data.csv' using 1:2 with lines");
  f.width_px = 320;
  f.height_px = 200;
  const PlotStatus s = render(d, f);
  EXPECT_TRUE(s.ok) << s.message;
  EXPECT_GT(fs::file_size(d / "fig.png"), 100u);
  EXPECT_GT(fs::file_size(d / "fig.svg"), 100u);
  EXPECT_TRUE(fs::exists(d / "fig.gp"));
  EXPECT_FALSE(fs::exists(d / "fig.gp.log"));  // removed on success
}

TEST(Gnuplot, AFailingScriptIsReportedWithItsLog) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path d = fresh_dir("fail");
  Figure f("bad", "plot 'missing.csv' using 1:2 with lines\nthis is not gnuplot");
  f.svg = false;
  const PlotStatus s = render(d, f);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("gnuplot failed on"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("bad.gp"), std::string::npos) << s.message;
  EXPECT_NE(s.message.find("exit status"), std::string::npos) << s.message;
  EXPECT_TRUE(fs::exists(d / "bad.gp.log"));
}

TEST(Gnuplot, AnEmptyPlotFailsWhenAsked) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const fs::path d = fresh_dir("empty");
  std::ofstream(d / "e.dat") << "1 nan\n2 nan\n";
  Figure f("empty", "set datafile missing 'nan'\nplot 'e.dat' using 1:2");
  f.csv_defaults = false;
  f.svg = false;
  f.empty_is_failure = true;
  const PlotStatus s = render(d, f);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("no data to draw"), std::string::npos) << s.message;
}

TEST(Gnuplot, AMissingGnuplotIsAStatusNotACrash) {
  const fs::path d = fresh_dir("nognuplot");
  const char* old = std::getenv("PATH");
  const std::string saved = old ? old : "";
  ::setenv("PATH", d.c_str(), 1);  // a PATH without gnuplot (sh itself is found by absolute path)
  const PlotStatus s = render(d, Figure("x", "plot x"));
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("gnuplot not found"), std::string::npos) << s.message;
  EXPECT_TRUE(fs::exists(d / "x.gp"));  // the script is kept for a later run
}

TEST(Gnuplot, ScriptWrapsTheBodyWithTerminals) {
  Figure f("fig4_bias", "plot x");
  const std::string s = gnuplot_script(f);
  EXPECT_EQ(s.rfind("# fig4_bias: rendered by driftless; edit and run `gnuplot fig4_bias.gp`", 0), 0u) << s;
  EXPECT_NE(s.find("set datafile separator ','"), std::string::npos);
  EXPECT_NE(s.find("pngcairo size 1200,800"), std::string::npos);
  // the outputs are variables defaulting to the final names (the program renders under temporary ones)
  EXPECT_NE(s.find("if (!exists('svg_out')) svg_out = 'fig4_bias.svg'"), std::string::npos) << s;
  EXPECT_NE(s.find("set output png_out"), std::string::npos) << s;
  EXPECT_NE(s.find("plot x\n  unset output\n}"), std::string::npos) << s;
}

}  // namespace
}  // namespace driftless::report
