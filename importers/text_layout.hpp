// How a delimited text file is laid out, found from its first lines: separator, preamble, header,
// which column is what, units and time base (docs/import.md, text). Internal to importers/.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "importers/imu_reader.hpp"
#include "importers/units.hpp"

namespace driftless::importers {

/// One column the reader extracts.
struct ColumnPick {
  int index = -1;        // 0-based field index
  ChannelInfo channel;   // name, quantity, axis
  double scale = 1.0;    // to deg/s, m/s^2 or degC
};

/// The layout of a text file.
struct TextLayout {
  char separator = ',';        // ' ' means runs of blanks (spaces and tabs)
  std::size_t fields = 0;      // fields per data row
  std::size_t data_line = 0;   // 1-based line of the first data row
  std::vector<std::string> header;  // column names (empty when the file has none)
  int time_index = -1;         // 0-based, or -1
  double time_scale = 1.0;     // to s
  std::vector<ColumnPick> picks;
  double nominal_rate_hz = 0.0;
  std::vector<std::string> assumptions;
};

/// Finds the layout from the first lines of the file (`head`, whole lines) and the options.
/// `euroc` applies the EuRoC / TUM-VI conventions (ns stamps, rad/s, m/s^2).
TextLayout detect_text_layout(std::string_view head, const std::string& file, const ImportOptions& opt, bool euroc);

/// Splits one line at `sep` (' ': runs of blanks), trimming blanks and a trailing '\r'.
void split_fields(std::string_view line, char sep, std::vector<std::string_view>& out);

/// Parses a whole field as a number: empty or nan -> NaN; false on anything else.
bool parse_field(std::string_view f, double& out);

}  // namespace driftless::importers
