// The log writer: header first with 'complete: false', rows in whole-row chunks, the header
// patched to 'complete: true ' only after the last row reached the file (docs/log-format.md).
#include <cmath>

#include "estimator/fixed_decimal.hpp"
#include "estimator/log.hpp"
#include "estimator/log_columns.hpp"

namespace driftless::log {

namespace {
constexpr std::size_t kChunkBytes = 1u << 20;
}

LogWriter::LogWriter(const std::filesystem::path& path, const Metadata& meta, std::uint32_t fields)
    : path_(path) {
  validate_metadata(meta, path.string() + " (metadata given to the writer)");
  const std::uint32_t layout = (fields & (detail::kAllFields | kLayoutSingleSensor)) |
                               (meta.sensors() == 1 ? kLayoutSingleSensor : 0u);
  file_ = io::CheckedFile(path, "wb", path.string());
  // metadata: format first, 'complete' second (patched in place on a clean finish)
  std::string head = "# format: " + std::string(kFormatId) + "\n";
  head += "# complete: ";
  complete_offset_ = static_cast<std::int64_t>(head.size());
  head += "false\n";
  if ((layout & kLayoutSingleSensor) != 0) head += "# sensors: 1\n";
  for (const auto& [k, v] : meta.entries()) {
    if (k == "format" || k == "complete" || k == "sensors") continue;
    head += "# " + k + ": " + v + "\n";
  }
  for (std::size_t i = 0; i < detail::kColumns.size(); ++i) {
    if (!detail::column_in_layout(i, layout)) continue;
    if (!columns_.empty()) head += ",";
    head += detail::kColumns[i].name;
    columns_.emplace_back(static_cast<int>(i), detail::kColumns[i].decimals);
  }
  head += "\n";
  buffer_.reserve(kChunkBytes);
  buffer_ = head;
  flush();
}

LogWriter::~LogWriter() {
  if (finished_ || !file_.is_open()) return;
  try {
    finish(false, "writer closed before the run finished");
  } catch (...) {
    // a destructor must not throw; the header already says complete: false
  }
}

void LogWriter::append_row(const Sample& s) {
  // the row is formatted on the stack (room for every column at its widest: 330 chars for any
  // double), then appended in one piece
  char row[detail::kColumns.size() * 331 + 1];
  char* p = row;
  Sample& sample = const_cast<Sample&>(s);  // column_slot() only reads here
  for (const auto& [index, decimals] : columns_) {
    const double v = detail::column_slot(sample, static_cast<std::size_t>(index));
    if (!std::isnan(v)) p = io::write_fixed(p, v, decimals);  // NaN: an empty field
    *p++ = ',';
  }
  p[-1] = '\n';
  buffer_.append(row, p);
}

void LogWriter::write(const Sample& s) {
  append_row(s);
  ++rows_;
  if (buffer_.size() >= kChunkBytes) flush();
}

void LogWriter::event(double t_s, std::string_view text) {
  char tmp[400];
  char* end = io::write_fixed(tmp, t_s, 6);
  buffer_ += "# event: t=";
  buffer_.append(tmp, end);
  buffer_ += " ";
  for (char c : text) buffer_.push_back(c == '\n' || c == '\r' ? ' ' : c);
  buffer_ += "\n";
}

void LogWriter::flush() {
  if (!file_.is_open() || buffer_.empty()) return;
  // whole rows only: a failed write leaves the buffer for the trailer attempt in finish()
  file_.write(buffer_);
  file_.flush();
  buffer_.clear();
}

void LogWriter::finish(bool complete, std::string_view reason) {
  if (finished_) return;
  finished_ = true;
  if (!complete) {
    buffer_ += "# incomplete: ";
    for (char c : reason.empty() ? std::string_view("run did not finish") : reason) {
      buffer_.push_back(c == '\n' || c == '\r' ? ' ' : c);
    }
    buffer_ += "\n";
  }
  try {
    flush();
    // 'false' -> 'true ' keeps the byte length, so the rows do not move
    if (complete) file_.overwrite_at(complete_offset_, "true ");
    file_.close();
  } catch (...) {
    file_ = io::CheckedFile();  // closed without a check; the header still says complete: false
    throw;
  }
}

}  // namespace driftless::log
