// The delimited-text reader (also EuRoC / TUM-VI imu0/data.csv). Internal to importers/; open it
// with open_imu().
#pragma once

#include <cstdio>
#include <filesystem>
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
  void parse_row(std::string_view line, ImuBlock& out);

  std::string path_;
  std::FILE* file_ = nullptr;
  TextLayout layout_;
  std::vector<int> slot_;  // field -> channel, kTimeSlot, or -1 (not read)
  std::string buf_;
  std::size_t pos_ = 0;
  std::size_t line_no_ = 0;
  bool eof_ = false;
};

}  // namespace driftless::importers
