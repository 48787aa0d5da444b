// Option checks with readable messages, and the free-space warning before a long run.
#include <cmath>
#include <cstdint>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "estimator/output_file.hpp"

namespace driftless::cli {
namespace {

// the option's text as a finite number, or NaN
double number_of(const std::string& text) {
  std::size_t used = 0;
  try {
    const double v = std::stod(text, &used);
    return used == text.size() && std::isfinite(v) ? v : NAN;
  } catch (const std::exception&) {
    return NAN;
  }
}

CLI::Validator number_check(const std::string& what, const std::string& unit, bool (*ok)(double)) {
  const std::string expected = "a number " + what + (unit.empty() ? "" : " (" + unit + ")");
  return CLI::Validator(
      [expected, ok](std::string& text) -> std::string {
        const double v = number_of(text);
        if (std::isnan(v) || !ok(v)) return "expected " + expected + ", got '" + text + "'";
        return {};
      },
      expected);
}

std::string human_bytes(double b) {
  if (b >= 1e12) return fmt::format("{:.1f} TB", b / 1e12);
  if (b >= 1e9) return fmt::format("{:.1f} GB", b / 1e9);
  return fmt::format("{:.0f} MB", b / 1e6);
}

}  // namespace

CLI::Validator positive_number(const std::string& unit) {
  return number_check("> 0", unit, [](double v) { return v > 0.0; });
}

CLI::Validator non_negative_number(const std::string& unit) {
  return number_check(">= 0", unit, [](double v) { return v >= 0.0; });
}

CLI::Validator seed_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const std::string expected = "a whole number 0 .. 18446744073709551615";
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || text.size() > 20) {
          return "expected " + expected + ", got '" + text + "'";
        }
        try {
          (void)std::stoull(text);
        } catch (const std::exception&) {
          return "expected " + expected + ", got '" + text + "'";
        }
        return {};
      },
      "SEED");
}

CLI::Validator count_number(std::uint64_t lo, std::uint64_t hi) {
  const std::string expected = fmt::format("a whole number {} .. {}", lo, hi);
  return CLI::Validator(
      [expected, lo, hi](std::string& text) -> std::string {
        if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos) {
          return "expected " + expected + ", got '" + text + "'";
        }
        const std::uint64_t v = std::stoull(text);
        if (v < lo || v > hi) return "expected " + expected + ", got '" + text + "'";
        return {};
      },
      expected);
}

bool warn_if_disk_too_small(const std::string& command, const std::filesystem::path& dir, double bytes,
                            const std::string& what) {
  const std::int64_t free = io::free_bytes(dir);
  if (free < 0 || bytes <= static_cast<double>(free)) return false;
  fmt::print(stderr,
             "driftless {}: warning: {} will take about {} but {} has {} free; the run stops with "
             "'No space left on device' when the disk is full\n",
             command, what, human_bytes(bytes), dir.string(), human_bytes(static_cast<double>(free)));
  return true;
}

}  // namespace driftless::cli
