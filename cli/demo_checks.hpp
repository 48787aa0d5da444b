// The demo's self-check: for each output, whether it holds what the demo says it holds (the log
// is complete, the filter locked on, the attitude comparison exists, each figure was drawn and
// is a picture, the report is whole, the video decodes with the frame count the renderer
// claims). The demo exits non-zero when one does not, and says why.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace driftless::cli {

/// One output and whether it holds what is claimed for it.
struct OutputCheck {
  std::filesystem::path path;  // the file a user would open
  std::string claim;           // what the demo says it is
  bool ok = false;
  std::string detail;          // what was found (why not, when not ok)
};

/// The simulated log: complete, with `expected_rows` rows.
OutputCheck check_log(const std::filesystem::path& log, std::uint64_t expected_rows);
/// The estimate folder's summary.json: the filter locked on and the attitude comparison exists.
std::vector<OutputCheck> check_estimate(const std::filesystem::path& estimate_dir);
/// Each figure summary.json lists: drawn and a PNG picture, or why it is missing.
std::vector<OutputCheck> check_figures(const std::filesystem::path& estimate_dir);
/// report.html is a whole page and diagnosis.json names a verdict.
OutputCheck check_report(const std::filesystem::path& report_dir);
/// The MP4 decodes (ffprobe) to the frame count and size the renderer's sidecar (video.json)
/// claims, and holds at least `min_frames` frames.
OutputCheck check_video(const std::filesystem::path& video, std::uint64_t min_frames);

/// Width and height of a PNG file from its header; {0, 0} when it is not a PNG.
std::pair<int, int> png_size(const std::filesystem::path& png);

}  // namespace driftless::cli
