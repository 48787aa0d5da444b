#include "estimator/input_error.hpp"

#include <utility>

namespace driftless {

std::string input_error_text(const std::string& file, std::size_t line, const std::string& key,
                             const std::string& detail) {
  std::string s = file;
  if (line > 0) s += (s.empty() ? "line " : ":") + std::to_string(line);
  if (!key.empty()) s += (s.empty() ? "" : ": ") + key;
  if (!detail.empty()) s += (s.empty() ? "" : ": ") + detail;
  return s;
}

InputError::InputError(std::string file, std::size_t line, std::string key, std::string detail)
    : std::invalid_argument(input_error_text(file, line, key, detail)),
      where_(std::make_shared<const Where>(Where{std::move(file), line, std::move(key), std::move(detail)})) {}

}  // namespace driftless
