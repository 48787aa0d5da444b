// Format detection and the one entry point, open_imu().
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "importers/imu_reader.hpp"
#include "importers/reader_factories.hpp"
#include "importers/text_reader.hpp"

namespace driftless::importers {

void ImuBlock::clear() {
  t_s.clear();
  loc.clear();
  for (auto& v : values) v.clear();
}

const char* to_string(Format f) {
  switch (f) {
    case Format::kAuto: return "auto";
    case Format::kText: return "text";
    case Format::kEuroc: return "euroc";
    case Format::kNpy: return "npy";
    case Format::kBag: return "bag";
    case Format::kDriftlessLog: return "log";
  }
  return "?";
}

const char* unit_of(Quantity q) {
  switch (q) {
    case Quantity::kRate: return "deg/s";
    case Quantity::kAccel: return "m/s^2";
    case Quantity::kTemperature: return "degC";
  }
  return "?";
}

Format parse_format(const std::string& s) {
  for (Format f : {Format::kAuto, Format::kText, Format::kEuroc, Format::kNpy, Format::kBag, Format::kDriftlessLog}) {
    if (s == to_string(f)) return f;
  }
  throw ImportError("--format: expected auto, text, euroc, npy, bag or log, got '" + s + "'");
}

Format detect_format(const std::filesystem::path& path, std::string* why) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ImportError(path.string() + ": cannot open");
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  auto say = [&](const char* w) {
    if (why != nullptr) *why = w;
  };
  if (head.rfind("#ROSBAG V2.0", 0) == 0) return say("a ROS 1 bag (#ROSBAG V2.0)"), Format::kBag;
  if (head.rfind("\x93NUMPY", 0) == 0) return say("a NumPy .npy array"), Format::kNpy;
  if (head.rfind("# format: driftless-log", 0) == 0) return say("a driftless log"), Format::kDriftlessLog;
  if (head.find("w_RS_S_x") != std::string::npos) return say("EuRoC / TUM-VI imu0/data.csv (w_RS_S_x in the header)"), Format::kEuroc;
  if (path.extension() == ".bag") return say("a .bag file"), Format::kBag;
  if (path.extension() == ".npy") return say("a .npy file"), Format::kNpy;
  return say("delimited text"), Format::kText;
}

std::unique_ptr<ImuReader> make_text_reader(const std::filesystem::path& path, const ImportOptions& opt, bool euroc) {
  return std::make_unique<TextReader>(path, opt, euroc);
}

namespace {

// An option that the detected format has no use for is refused, never silently ignored: a user who
// gives --topic believes the file is a bag, and one who gives --separator believes it is text.
void refuse_options_for_other_formats(const std::filesystem::path& path, Format f, const std::string& why,
                                      const ImportOptions& opt) {
  const bool text = f == Format::kText || f == Format::kEuroc;
  const char* option = nullptr;
  const char* applies = nullptr;
  if (!opt.topic.empty() && f != Format::kBag) option = "--topic", applies = "ROS bags";
  else if (!opt.separator.empty() && !text) option = "--separator", applies = "delimited text";
  else if (opt.no_header && !text) option = "--no-header", applies = "delimited text";
  if (option == nullptr) return;
  throw ImportError(path.string() + ": " + option + " applies to " + applies + ", but this file is " + to_string(f) +
                    " (" + why + "); drop " + option + " or give --format");
}

}  // namespace

std::unique_ptr<ImuReader> open_imu(const std::filesystem::path& path, const ImportOptions& opt) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw ImportError(path.string() + ": no such file");
  std::string why = "as given (--format)";
  const Format f = opt.format == Format::kAuto ? detect_format(path, &why) : opt.format;
  if (f != Format::kDriftlessLog) refuse_options_for_other_formats(path, f, why, opt);
  std::unique_ptr<ImuReader> r;
  switch (f) {
    case Format::kText: r = make_text_reader(path, opt, false); break;
    case Format::kEuroc: r = make_text_reader(path, opt, true); break;
    case Format::kNpy: r = make_npy_reader(path, opt); break;
    case Format::kBag: r = make_bag_reader(path, opt); break;
    case Format::kDriftlessLog:
      throw ImportError(path.string() + ": a driftless log: read it with --log (or give --format text)");
    case Format::kAuto: break;
  }
  r->say_first(std::string("format ") + to_string(f) + ": " + why);
  return r;
}

}  // namespace driftless::importers
