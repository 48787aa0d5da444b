// A result file written with fmt through the one output helper (estimator/output_file.hpp): print()
// formats into its buffer, commit() renames the finished file into place. A TextFile that is not
// committed (an exception, a stop) leaves nothing behind; its destructor never throws.
#pragma once

#include <filesystem>
#include <iterator>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "estimator/output_file.hpp"

namespace driftless::report {

class TextFile {
 public:
  /// Starts `target` under its partial name (throws io::OutputError "<target>: <reason>").
  explicit TextFile(const std::filesystem::path& target) : file_(target) {}

  template <class... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(file_.buffer()), format, std::forward<Args>(args)...);
    file_.maybe_drain();
  }
  void write(std::string_view text) { file_.write(text); }
  /// Checks every write, closes and renames the file over its target (io::OutputError on failure).
  void commit() { file_.commit(); }

 private:
  io::OutputFile file_;
};

}  // namespace driftless::report
