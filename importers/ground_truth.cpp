#include "importers/ground_truth.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>

#include "importers/imu_reader.hpp"
#include "importers/stamp_ns.hpp"
#include "importers/text_layout.hpp"

namespace driftless::importers {
namespace {

constexpr std::int64_t kNsPerS = 1'000'000'000;
constexpr const char* kLayout = "#timestamp [ns], p x y z [m], q w x y z (EuRoC state_groundtruth_estimate0 or vicon0)";

std::string where(const std::string& file, std::size_t line) { return file + ":" + std::to_string(line); }

// The quaternion's order in columns 5..8 from the header's names: the axis letter each name ends in
// (EuRoC " q_RS_w []", "qx", "q.w"), after its unit in brackets. EuRoC's w x y z unless the four names
// spell another order of w, x, y, z (many tools write x y z w: read as w x y z that is another rotation,
// with a norm of 1, so nothing else would notice). order[k]: the column (0..3) holding w, x, y, z.
std::array<int, 4> quaternion_order(const std::string& header, std::string& said) {
  std::vector<std::string_view> names;
  split_fields(header, ',', names);
  std::array<int, 4> order{0, 1, 2, 3};
  said = "w x y z";
  if (names.size() < 8) return order;
  std::array<int, 4> found{-1, -1, -1, -1};
  for (int c = 0; c < 4; ++c) {
    std::string_view n = names[static_cast<std::size_t>(4 + c)];
    n = n.substr(0, std::min(n.find('['), n.find('(')));
    while (!n.empty() && (n.back() == ' ' || n.back() == '\t')) n.remove_suffix(1);
    if (n.empty()) return order;
    const char last = static_cast<char>(std::tolower(static_cast<unsigned char>(n.back())));
    const auto k = std::string_view("wxyz").find(last);
    if (k == std::string_view::npos || found[k] >= 0) return order;
    found[k] = c;
  }
  said.clear();
  for (int c = 0; c < 4; ++c) {
    for (int k = 0; k < 4; ++k) {
      if (found[static_cast<std::size_t>(k)] == c) said += std::string(said.empty() ? "" : " ") + "wxyz"[k];
    }
  }
  return found;
}

// one data row into a pose; throws naming the line
PoseStamp parse_pose(std::string_view line, const std::string& file, std::size_t line_no,
                     std::vector<std::string_view>& fields, const std::array<int, 4>& q_order, const std::string& q_said) {
  split_fields(line, ',', fields);
  if (fields.size() < 8) {
    throw ImportError(where(file, line_no) + ": expected at least 8 fields (" + kLayout + "), got " +
                      std::to_string(fields.size()));
  }
  PoseStamp p;
  if (!parse_stamp_ns(fields[0].data(), fields[0].data() + fields[0].size(), 1, p.t_ns)) {
    throw ImportError(where(file, line_no) + ": column 1 (timestamp): expected whole ns, got '" + std::string(fields[0]) + "'");
  }
  double v[7];
  for (std::size_t k = 0; k < 7; ++k) {
    if (!parse_field(fields[k + 1], v[k]) || !std::isfinite(v[k])) {
      throw ImportError(where(file, line_no) + ": column " + std::to_string(k + 2) + ": expected a number, got '" +
                        std::string(fields[k + 1]) + "'");
    }
  }
  p.p_ref_m = Eigen::Vector3d(v[0], v[1], v[2]);
  const double* q = v + 3;
  p.q_ref_from_body = Eigen::Quaterniond(q[q_order[0]], q[q_order[1]], q[q_order[2]], q[q_order[3]]);
  const double n = p.q_ref_from_body.norm();
  if (!(n > 0.5 && n < 1.5)) {
    throw ImportError(where(file, line_no) + ": quaternion norm " + std::to_string(n) +
                      " is not close to 1 (columns 5..8 are q " + q_said + ")");
  }
  p.q_ref_from_body.normalize();
  return p;
}

std::int64_t median_step(const std::vector<PoseStamp>& poses) {
  std::vector<std::int64_t> steps;
  for (std::size_t i = 1; i < poses.size(); ++i) steps.push_back(poses[i].t_ns - poses[i - 1].t_ns);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  return steps[steps.size() / 2];
}

}  // namespace

GroundTruth read_ground_truth(const std::filesystem::path& path) {
  GroundTruth gt;
  gt.source = path.string();
  std::ifstream in(path);
  if (!in) throw ImportError(gt.source + ": cannot open the ground truth");
  std::string line;
  std::size_t line_no = 0;
  bool header = false;
  std::array<int, 4> q_order{0, 1, 2, 3};
  std::vector<std::string_view> fields;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    if (!header) {
      if (line.rfind("#timestamp", 0) != 0) {
        throw ImportError(where(gt.source, line_no) + ": expected the header " + kLayout + ", got '" + line.substr(0, 60) + "'");
      }
      header = true;
      q_order = quaternion_order(line, gt.quaternion_order);
      continue;
    }
    if (line[0] == '#') continue;
    const PoseStamp p = parse_pose(line, gt.source, line_no, fields, q_order, gt.quaternion_order);
    if (!gt.poses.empty() && p.t_ns <= gt.poses.back().t_ns) {
      throw ImportError(where(gt.source, line_no) + ": timestamp " + std::to_string(p.t_ns) +
                        " ns does not increase (previous " + std::to_string(gt.poses.back().t_ns) + " ns)");
    }
    gt.poses.push_back(p);
  }
  if (gt.poses.size() < 2) throw ImportError(gt.source + ": a ground truth needs at least 2 rows, got " + std::to_string(gt.poses.size()));
  gt.median_step_ns = median_step(gt.poses);
  return gt;
}

PoseInterpolator::PoseInterpolator(const GroundTruth& gt, std::int64_t epoch_s, std::int64_t max_gap_ns)
    : gt_(gt), epoch_ns_(epoch_s * kNsPerS), max_gap_ns_(max_gap_ns) {}

double PoseInterpolator::first_s() const { return static_cast<double>(gt_.poses.front().t_ns - epoch_ns_) * 1e-9; }
double PoseInterpolator::last_s() const { return static_cast<double>(gt_.poses.back().t_ns - epoch_ns_) * 1e-9; }

PoseAt PoseInterpolator::at(double t_s) {
  const auto& P = gt_.poses;
  const std::int64_t t = epoch_ns_ + std::llround(t_s * 1e9);
  PoseAt out;
  if (t < P.front().t_ns) return out.where = PoseAt::Where::kBefore, out;
  if (t > P.back().t_ns) return out.where = PoseAt::Where::kAfter, out;
  // the bracket P[k] <= t < P[k + 1] (the last stamp itself: the last pair)
  if (t < P[k_].t_ns) {
    const auto it = std::upper_bound(P.begin(), P.end(), t, [](std::int64_t v, const PoseStamp& p) { return v < p.t_ns; });
    k_ = static_cast<std::size_t>(it - P.begin()) - 1;
  }
  while (k_ + 2 < P.size() && P[k_ + 1].t_ns <= t) ++k_;
  const PoseStamp& a = P[k_];
  const PoseStamp& b = P[k_ + 1];
  if (b.t_ns - a.t_ns > max_gap_ns_) return out.where = PoseAt::Where::kGap, out;
  const double f = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  out.q_ref_from_body = a.q_ref_from_body.slerp(f, b.q_ref_from_body);
  out.p_ref_m = a.p_ref_m + f * (b.p_ref_m - a.p_ref_m);
  return out;
}

}  // namespace driftless::importers
