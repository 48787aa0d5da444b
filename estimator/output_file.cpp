#include "estimator/output_file.hpp"

#include <cerrno>
#include <cstring>
#include <system_error>
#include <utility>

#include <unistd.h>

namespace driftless::io {
namespace fs = std::filesystem;

namespace {

std::string reason_from_errno(int err) { return err != 0 ? std::strerror(err) : "write failed"; }

// removes a file, ignoring every error (cleanup paths must not throw)
void remove_quietly(const fs::path& p) noexcept {
  std::error_code ec;
  fs::remove(p, ec);
}

}  // namespace

fs::path partial_path(const fs::path& target) {
  const fs::path name = target.filename();
  return target.parent_path() /
         (name.stem().string() + ".partial-" + std::to_string(::getpid()) + name.extension().string());
}

void rename_over(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) throw OutputError(to.string() + ": cannot rename the finished file into place: " + ec.message());
}

std::int64_t free_bytes(const fs::path& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) return -1;
  while (!p.empty() && !fs::exists(p, ec)) {
    if (p == p.parent_path()) return -1;
    p = p.parent_path();
  }
  const fs::space_info s = fs::space(p, ec);
  if (ec || s.available == static_cast<std::uintmax_t>(-1)) return -1;
  return static_cast<std::int64_t>(s.available);
}

// ---------------------------------------------------------------------------------------------
// CheckedFile

CheckedFile::CheckedFile(const fs::path& path, const char* mode, std::string shown)
    : shown_(std::move(shown)) {
  errno = 0;
  file_.reset(std::fopen(path.c_str(), mode));
  if (!file_) {
    const bool reading = mode[0] == 'r';
    fail(std::string(reading ? "cannot open for reading: " : "cannot open for writing: ") +
         reason_from_errno(errno));
  }
}

void CheckedFile::fail(std::string_view what) const { throw OutputError(shown_ + ": " + std::string(what)); }

void CheckedFile::write(std::string_view bytes) {
  if (bytes.empty()) return;
  errno = 0;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_.get()) != bytes.size()) {
    fail(reason_from_errno(errno));
  }
}

void CheckedFile::flush() {
  errno = 0;
  if (std::fflush(file_.get()) != 0) fail(reason_from_errno(errno));
}

void CheckedFile::overwrite_at(std::int64_t offset, std::string_view bytes) {
  flush();
  errno = 0;
  if (std::fseek(file_.get(), static_cast<long>(offset), SEEK_SET) != 0) fail(reason_from_errno(errno));
  write(bytes);
  flush();
  if (std::fseek(file_.get(), 0, SEEK_END) != 0) fail(reason_from_errno(errno));
}

void CheckedFile::close() {
  if (!file_) return;
  std::FILE* f = file_.release();
  errno = 0;
  // a write through get() (libpng) that failed earlier leaves the error flag set
  const bool flushed = std::fflush(f) == 0 && std::ferror(f) == 0;
  const int flush_errno = errno;
  errno = 0;
  const bool closed = std::fclose(f) == 0;
  if (!flushed) fail(reason_from_errno(flush_errno));
  if (!closed) fail(reason_from_errno(errno));
}

// ---------------------------------------------------------------------------------------------
// OutputFile

OutputFile::OutputFile(fs::path target) : target_(std::move(target)), partial_(partial_path(target_)) {
  // a result of an earlier run under the same name must not pass for this run's
  remove_quietly(target_);
  file_ = CheckedFile(partial_, "wb", target_.string());
  buffer_.reserve(kBufferBytes);
}

OutputFile::OutputFile(OutputFile&& other) noexcept
    : target_(std::move(other.target_)),
      partial_(std::move(other.partial_)),
      file_(std::move(other.file_)),
      buffer_(std::move(other.buffer_)),
      committed_(std::exchange(other.committed_, true)) {}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  if (this != &other) {
    discard();
    target_ = std::move(other.target_);
    partial_ = std::move(other.partial_);
    file_ = std::move(other.file_);
    buffer_ = std::move(other.buffer_);
    committed_ = std::exchange(other.committed_, true);  // the moved-from owns nothing now
  }
  return *this;
}

OutputFile::~OutputFile() {
  if (!committed_) discard();
}

void OutputFile::drain() {
  try {
    file_.write(buffer_);
  } catch (...) {
    discard();
    throw;
  }
  buffer_.clear();
}

void OutputFile::commit() {
  if (committed_) return;
  try {
    drain();
    file_.close();
    rename_over(partial_, target_);
  } catch (...) {
    discard();
    throw;
  }
  committed_ = true;
}

void OutputFile::discard() noexcept {
  if (committed_ || partial_.empty()) return;
  file_ = CheckedFile();  // closes without a check
  remove_quietly(partial_);
  buffer_.clear();
  committed_ = true;
}

void write_file(const fs::path& target, std::string_view content) {
  OutputFile f(target);
  f.write(content);
  f.commit();
}

// ---------------------------------------------------------------------------------------------
// ExternalOutput

ExternalOutput::ExternalOutput(fs::path target) : target_(std::move(target)), partial_(partial_path(target_)) {
  remove_quietly(target_);
  remove_quietly(partial_);
}

ExternalOutput::ExternalOutput(ExternalOutput&& other) noexcept
    : target_(std::move(other.target_)),
      partial_(std::move(other.partial_)),
      done_(std::exchange(other.done_, true)) {}

ExternalOutput::~ExternalOutput() {
  if (!done_) discard();
}

void ExternalOutput::commit(std::string_view producer) {
  if (done_) return;
  std::error_code ec;
  const auto size = fs::file_size(partial_, ec);
  if (ec || size == 0) {
    discard();
    throw OutputError(target_.string() + ": " + std::string(producer) + " wrote " +
                      (ec ? "nothing" : "an empty file"));
  }
  try {
    rename_over(partial_, target_);
  } catch (...) {
    discard();
    throw;
  }
  done_ = true;
}

void ExternalOutput::discard() noexcept {
  if (done_ || partial_.empty()) return;
  remove_quietly(partial_);
  done_ = true;
}

}  // namespace driftless::io
