#include "diagnose/report_text.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <fmt/core.h>

namespace driftless::diagnose::report_text {
namespace {

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) o += fmt::format("\\u{:04x}", c);
        else o += c;
    }
  }
  return o;
}

std::string json_number(double v) { return std::isfinite(v) ? fmt::format("{:.9g}", v) : "null"; }

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else o += c;
  }
  return o;
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  std::size_t i = 0;
  auto byte = [&](std::size_t k) { return static_cast<unsigned>(static_cast<unsigned char>(in[k])); };
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (byte(i) << 16) | (byte(i + 1) << 8) | byte(i + 2);
    o += t[(v >> 18) & 63], o += t[(v >> 12) & 63], o += t[(v >> 6) & 63], o += t[v & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = byte(i) << 16;
    o += t[(v >> 18) & 63], o += t[(v >> 12) & 63], o += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (byte(i) << 16) | (byte(i + 1) << 8);
    o += t[(v >> 18) & 63], o += t[(v >> 12) & 63], o += t[(v >> 6) & 63], o += '=';
  }
  return o;
}

std::string gnuplot_png(const std::filesystem::path& dir, const std::string& stem, const std::string& script,
                        int width_px, int height_px) {
  const auto gp = dir / (stem + ".gp");
  const auto png = dir / (stem + ".png");
  const auto log = dir / (stem + ".log");
  auto run = [&](const char* terminal) {
    std::filesystem::remove(png);
    {
      std::ofstream f(gp);
      f << "set terminal " << terminal << " size " << width_px << "," << height_px << "\nset output '" << png.string()
        << "'\n" << script;
    }
    const std::string cmd = fmt::format("gnuplot '{}' > '{}' 2>&1", gp.string(), log.string());
    return std::system(cmd.c_str()) == 0;
  };
  // pngcairo may be absent in gnuplot-nox: fall back to the plain png terminal
  if (!run("pngcairo font 'sans,9'") && !run("png")) return {};
  const std::string msgs = read_file(log);
  if (msgs.find("no valid points") != std::string::npos || msgs.find("all points") != std::string::npos) return {};
  return read_file(png);
}

}  // namespace driftless::diagnose::report_text
