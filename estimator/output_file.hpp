// Every file the driftless program writes goes through this header (docs/log-format.md, "Output
// files"): logs, CSV, JSON, YAML, HTML, and the PNG/SVG/MP4 that gnuplot and ffmpeg write for it.
//
// - OutputFile: a whole result file. It is written under a temporary name beside the target
//   ("<stem>.partial-<pid><ext>"), every write is checked, and commit() flushes, closes and renames
//   it over the target. A failure throws OutputError("<target>: <reason>") and removes the
//   temporary, so nothing is left that looks complete. Never throws from its destructor.
// - ExternalOutput: the same for a file another program writes (gnuplot, ffmpeg): it is given the
//   temporary name, and commit() renames it only after the caller checked the program's exit
//   status and the file is non-empty.
// - CheckedFile: the RAII FILE handle with checked writes that both use, and that the log writer
//   uses to stream a log in place (a log marks itself 'complete: false' until it is finished).
// Standard library only (this folder also runs on hardware).
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace driftless::io {

/// An output file that could not be written; what() is one line "<file>: <reason>".
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The temporary name a target is written under until it is committed: "<stem>.partial-<pid><ext>"
/// in the target's folder (same file system, so the rename is atomic; the extension is kept for
/// programs that choose a format by it).
std::filesystem::path partial_path(const std::filesystem::path& target);

/// RAII owner of a FILE* with checked operations; errors throw OutputError naming `shown`.
class CheckedFile {
 public:
  CheckedFile() = default;
  /// Opens `path` with fopen `mode` ("wb", "rb", ...); `shown` is the name used in messages.
  CheckedFile(const std::filesystem::path& path, const char* mode, std::string shown);
  CheckedFile(CheckedFile&&) noexcept = default;
  CheckedFile& operator=(CheckedFile&&) noexcept = default;
  ~CheckedFile() = default;  // an open file is closed without a check (the unique_ptr deleter)

  bool is_open() const { return file_ != nullptr; }
  /// Writes all bytes or throws ("<shown>: No space left on device", ...).
  void write(std::string_view bytes);
  /// Pushes the C library's buffer to the OS.
  void flush();
  /// Overwrites bytes at `offset` from the start, then returns to the end.
  void overwrite_at(std::int64_t offset, std::string_view bytes);
  /// Flushes and closes; a failure (a delayed write error) throws.
  void close();
  std::FILE* get() const { return file_.get(); }
  const std::string& shown_name() const { return shown_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
  };
  [[noreturn]] void fail(std::string_view what) const;
  std::unique_ptr<std::FILE, Closer> file_;
  std::string shown_;
};

/// A result file written under its partial name and renamed over the target by commit().
/// Buffered: write() collects up to `kBufferBytes` before one checked fwrite.
class OutputFile {
 public:
  static constexpr std::size_t kBufferBytes = 1u << 20;

  /// Creates the partial file (throws OutputError naming `target` when its folder is not writable).
  explicit OutputFile(std::filesystem::path target);
  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&& other) noexcept;
  /// Not committed: closes and removes the partial file; never throws.
  ~OutputFile();

  void write(std::string_view text) {
    if (buffer_.size() + text.size() > kBufferBytes) drain();
    buffer_.append(text);
  }
  void put(char c) {
    if (buffer_.size() >= kBufferBytes) drain();
    buffer_.push_back(c);
  }
  /// The pending buffer, for formatters that append in place; call maybe_drain() after.
  std::string& buffer() { return buffer_; }
  void maybe_drain() {
    if (buffer_.size() >= kBufferBytes) drain();
  }
  /// Flushes, closes and renames the partial file over the target; throws OutputError on failure
  /// (the partial file is removed). Committing twice is a no-op.
  void commit();
  /// Drops the output: removes the partial file (never throws).
  void discard() noexcept;

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& partial() const { return partial_; }
  bool committed() const { return committed_; }

 private:
  void drain();
  std::filesystem::path target_, partial_;
  CheckedFile file_;
  std::string buffer_;
  bool committed_ = false;
};

/// Writes `content` to `target` through an OutputFile (temporary name, checked, renamed).
void write_file(const std::filesystem::path& target, std::string_view content);

/// A file another program writes for us (gnuplot, ffmpeg). Hand it partial() as the output name;
/// after the program exited 0, commit() checks that the file is there and non-empty and renames it
/// over the target. Not committed: the partial file is removed; never throws from the destructor.
class ExternalOutput {
 public:
  explicit ExternalOutput(std::filesystem::path target);
  ExternalOutput(ExternalOutput&& other) noexcept;
  ExternalOutput& operator=(ExternalOutput&&) = delete;
  ~ExternalOutput();

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& partial() const { return partial_; }
  /// `producer` names the program in the message ("<target>: gnuplot wrote nothing").
  void commit(std::string_view producer);
  void discard() noexcept;

 private:
  std::filesystem::path target_, partial_;
  bool done_ = false;
};

/// Renames `from` over `to`; throws OutputError naming `to` on failure.
void rename_over(const std::filesystem::path& from, const std::filesystem::path& to);

/// Free bytes on the file system holding `path` (or its nearest existing parent); -1 if unknown.
std::int64_t free_bytes(const std::filesystem::path& path);

}  // namespace driftless::io
