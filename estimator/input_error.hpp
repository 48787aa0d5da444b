// Bad user input: the one exception type for everything a user hands the program (a scenario, a
// sensor block, an estimator config, a calibration or plan file, a sweep file, a log, an option, a
// device). It carries where the problem is (file, line, key) and what was expected, so the CLI
// prints one actionable line and exits non-zero. Standard library only: the lowest folder.
#pragma once

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>

namespace driftless {

/// Bad user input. what() reads "file:line: key: detail" (absent parts left out).
///
/// It derives from std::invalid_argument on purpose: the house style has every parameter struct's
/// validate() throw std::invalid_argument on a bad value (it knows the field, not the file), so a
/// caller that catches std::invalid_argument keeps working, and a loader turns such a message into
/// an InputError by adding the file and line of the block it read (see with_location()).
class InputError : public std::invalid_argument {
 public:
  /// `file`: a path, or an option or device name; `line`: 1-based, 0 when unknown or not a text
  /// file; `key`: the dotted key ("model.box.end_stop_deg"), empty when the problem is not one key.
  InputError(std::string file, std::size_t line, std::string key, std::string detail);

  const std::string& file() const noexcept { return where_->file; }
  std::size_t line() const noexcept { return where_->line; }
  const std::string& key() const noexcept { return where_->key; }
  /// What was wrong or expected, without the location.
  const std::string& detail() const noexcept { return where_->detail; }

 private:
  struct Where {
    std::string file;
    std::size_t line = 0;
    std::string key;
    std::string detail;
  };
  // shared: copying an exception must not throw
  std::shared_ptr<const Where> where_;
};

/// The text InputError::what() gives for these parts ("file:line: key: detail").
std::string input_error_text(const std::string& file, std::size_t line, const std::string& key,
                             const std::string& detail);

/// Calls `f()`; a std::invalid_argument it throws that is not yet an InputError (a validate()
/// message) is rethrown as InputError(file, line, key, message). InputErrors pass unchanged.
template <class F>
decltype(auto) with_location(const std::string& file, std::size_t line, const std::string& key, F&& f) {
  try {
    return f();
  } catch (const InputError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw InputError(file, line, key, e.what());
  }
}

}  // namespace driftless
