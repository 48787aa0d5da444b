// The delimited-text reader (also EuRoC / TUM-VI imu0/data.csv). Internal to importers/; open it
// with open_imu().
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "importers/imu_reader.hpp"
#include "importers/text_layout.hpp"

namespace driftless::importers {

class TextReader : public ImuReader {
 public:
  TextReader(const std::filesystem::path& path, const ImportOptions& opt, bool euroc);
  ~TextReader() override;
  TextReader(const TextReader&) = delete;
  TextReader& operator=(const TextReader&) = delete;
  bool read(ImuBlock& out, std::size_t max_rows) override;

 private:
  static constexpr int kTimeSlot = -2;
  bool next_line(std::string_view& line);
  void refill();
  /// Maps a regular file whole (read-only); false when it cannot be mapped (a pipe, an empty file).
  bool map_file();
  /// Bytes of a last line cut off mid-write (no line end, too few fields) to leave out, said in the
  /// assumptions; 0 when the mapped file ends in a whole row.
  std::size_t cut_tail_bytes();
  /// Gives back the mapped pages already parsed (the page cache keeps them; RSS stays bounded).
  void release_parsed();
  const char* data() const { return map_ != nullptr ? map_ : buf_.get(); }
  /// Parses the whole lines of [b, e), the first being line `first_line`, into `out`; returns how
  /// many lines it walked.
  std::uint64_t parse_lines(const char* b, const char* e, std::uint64_t first_line, ImuBlock& out) const;
  /// One line: skipped (preamble, blank, comment) or parsed.
  void take_line(std::string_view line, std::uint64_t line_no, ImuBlock& out) const;
  void parse_row(std::string_view line, std::uint64_t line_no, ImuBlock& out) const;
  /// Parses the buffered whole lines (at most `room` of them) in two halves on two threads;
  /// false when too few are buffered to be worth a thread.
  bool parse_buffered_in_two(ImuBlock& out, std::size_t room);
  /// The stamp field [b, e) in s from the epoch; false when not a number.
  bool stamp_s(const char* b, const char* e, double& t_s) const;
  void set_epoch(std::string_view head);

  std::string path_;
  std::FILE* file_ = nullptr;
  TextLayout layout_;
  std::vector<int> slot_;  // field -> channel, kTimeSlot, or -1 (not read)
  std::unique_ptr<char[]> buf_;  // not zero-filled: each chunk is read over it
  const char* map_ = nullptr;    // the whole file when mapped (then buf_ is unused)
  std::size_t map_bytes_ = 0, released_ = 0;
  std::size_t cap_ = 0, len_ = 0, pos_ = 0;
  std::uint64_t line_no_ = 0;
  bool eof_ = false;
  std::int64_t ns_per_unit_ = 0;  // the time unit in ns (0: not a power of ten of s)
  ImuBlock side_;                 // the second half of a two-thread parse
};

}  // namespace driftless::importers
