// Shared pieces of the render tests: a small inline box model, a synthetic flip log, and
// decoding videos with ffprobe/ffmpeg.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include <Eigen/Geometry>
#include <fmt/core.h>
#include <mujoco/mujoco.h>

#include "estimator/log.hpp"

namespace driftless::render::testing {

// a box like the twin's: see-through walls, base on slides + ball, two hinge platforms with IMU
// sites, a fixed camera and a tracking camera
inline constexpr const char* kBoxMjcf = R"(
<mujoco model="test_box">
  <compiler angle="degree"/>
  <visual><global offwidth="320" offheight="240"/></visual>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1" directional="true"/>
    <geom name="floor" type="plane" size="5 5 0.1" rgba="0.8 0.8 0.75 1" pos="0 0 -0.2"/>
    <camera name="cam_fixed" pos="0.05 -0.28 0.17" xyaxes="1 0 0 0 0.5 0.87" fovy="45"/>
    <body name="box">
      <joint name="drive_x" type="slide" axis="1 0 0"/>
      <joint name="drive_y" type="slide" axis="0 1 0"/>
      <joint name="drive_z" type="slide" axis="0 0 1"/>
      <joint name="drive_rot" type="ball"/>
      <geom name="shell" type="box" size="0.1 0.07 0.045" rgba="0.55 0.75 0.95 0.2" mass="0.4"
            contype="0" conaffinity="0"/>
      <camera name="track" mode="trackcom" pos="0.3 -0.4 0.3" xyaxes="0.8 0.6 0 -0.35 0.47 0.8"/>
      <body name="platform1" pos="-0.045 0 0">
        <joint name="hinge1" type="hinge" axis="0 0 1" range="-90 90" limited="true"/>
        <geom type="box" size="0.03 0.03 0.002" rgba="0.1 0.6 0.25 1" contype="0" conaffinity="0"/>
        <geom type="box" size="0.012 0.003 0.003" pos="0.015 0 0.004" rgba="0.9 0.2 0.1 1" contype="0" conaffinity="0"/>
        <site name="imu1" size="0.003"/>
      </body>
      <body name="platform2" pos="0.045 0 0">
        <joint name="hinge2" type="hinge" axis="1 0 0" range="-90 90" limited="true"/>
        <geom type="box" size="0.002 0.03 0.03" rgba="0.1 0.35 0.75 1" contype="0" conaffinity="0"/>
        <geom type="box" size="0.003 0.003 0.012" pos="0.004 0 0.015" rgba="0.9 0.2 0.1 1" contype="0" conaffinity="0"/>
        <site name="imu2" size="0.003"/>
      </body>
    </body>
  </worldbody>
  <sensor>
    <gyro name="gyro1" site="imu1"/>
    <gyro name="gyro2" site="imu2"/>
  </sensor>
</mujoco>
)";

using ModelPtr = std::unique_ptr<mjModel, decltype(&mj_deleteModel)>;

/// Loads kBoxMjcf (or other XML) from a string; fails the test on any MuJoCo error.
inline ModelPtr load_model(const std::string& xml = kBoxMjcf) {
  char err[1000] = "";
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  mj_makeEmptyFileVFS(&vfs, "model.xml", static_cast<int>(xml.size()));
  const int i = mj_findFileVFS(&vfs, "model.xml");
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs.filedata[i]));
  ModelPtr m(mj_loadXML("model.xml", &vfs, err, sizeof err), &mj_deleteModel);
  mj_deleteVFS(&vfs);
  if (!m || err[0] != '\0') throw std::runtime_error(std::string("test model: ") + err);
  return m;
}

/// A scratch folder in the test's temporary folder (under CTest, one of the test's own that is
/// removed when it passes: tests/run_in_scratch.sh; the pid keeps two processes apart without it),
/// emptied first.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("renders_" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Flip schedule of Fig. 3 for the tests: both at +90, then one platform flips every
/// `period_s` (flip_s of smooth motion, then rest), starting at `first_flip_s`.
struct FlipSchedule {
  double first_flip_s = 1.0;
  double period_s = 3.0;
  double flip_s = 1.0;

  /// Platform angles at time t, deg (smooth cosine ramps between +-90).
  std::pair<double, double> angles(double t) const {
    double a[2] = {90.0, 90.0};
    if (t < first_flip_s) return {a[0], a[1]};
    const long k_max = static_cast<long>(std::floor((t - first_flip_s) / period_s));
    // (+,+) -> (+,-) -> (-,-) -> (-,+) -> (+,+): flip k moves platform 2 when k even
    for (long k = 0; k <= k_max; ++k) {
      const int plat = (k % 2 == 0) ? 1 : 0;
      const double from = a[plat], to = -from;
      const double u = std::clamp((t - first_flip_s - k * period_s) / flip_s, 0.0, 1.0);
      a[plat] = from + (to - from) * 0.5 * (1.0 - std::cos(kPi * u));
    }
    return {a[0], a[1]};
  }
};

/// A synthetic log: static base (ref_q from yaw_deg, ref_p), platforms on the schedule, gyros
/// reading constant biases (deg/s) through eq. (1) with no rotation, true_ columns filled.
inline void write_flip_log(const std::filesystem::path& path, double duration_s, double rate_hz,
                           const FlipSchedule& sched, double yaw_deg = 30.0) {
  log::Metadata meta;
  meta.set("sample_rate_hz", std::to_string(rate_hz));
  meta.set("latitude_deg", "52.0");
  meta.set("source", "render test");
  log::LogWriter w(path, meta, kFieldRefQ | kFieldRefP | kFieldTrueBias | kFieldTruePlat);
  const Eigen::Vector3d b1(0.4, -0.2, 0.3), b2(-0.3, 0.25, 0.1);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()));
  const long n = static_cast<long>(std::llround(duration_s * rate_hz));
  for (long i = 0; i < n; ++i) {
    Sample s;
    s.t_s = static_cast<double>(i) / rate_hz;
    const auto [p1, p2] = sched.angles(s.t_s);
    s.plat1_deg = s.true_plat1_deg = p1;
    s.plat2_deg = s.true_plat2_deg = p2;
    s.gyro1_dps = b1;
    s.gyro2_dps = b2;
    s.true_bias1_dps = b1;
    s.true_bias2_dps = b2;
    s.set_q_enu_from_body(q);
    s.ref_p_enu_m = Eigen::Vector3d(0.0, 0.0, 0.0);
    w.write(s);
  }
  w.finish(true);
}

/// Runs a shell command and returns its stdout (throws on a non-zero exit).
inline std::string run(const std::string& cmd) {
  std::string out;
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) throw std::runtime_error("popen failed: " + cmd);
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int rc = ::pclose(p);
  if (rc != 0) throw std::runtime_error("command failed (" + std::to_string(rc) + "): " + cmd);
  return out;
}

/// Stream facts from ffprobe: frame count (decoded), width, height, frame rate.
struct VideoFacts {
  long frames = 0;
  int width = 0, height = 0;
  double fps = 0;
};

inline VideoFacts probe(const std::filesystem::path& video) {
  const std::string out = run(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=nb_read_frames,width,height,r_frame_rate,codec_name -of default=nw=1 '" +
      video.string() + "'");
  VideoFacts f;
  std::size_t pos = 0;
  while (pos < out.size()) {
    const std::size_t end = out.find('\n', pos);
    const std::string line = out.substr(pos, end - pos);
    pos = end == std::string::npos ? out.size() : end + 1;
    const auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string k = line.substr(0, eq), v = line.substr(eq + 1);
    if (k == "width") f.width = std::stoi(v);
    if (k == "height") f.height = std::stoi(v);
    if (k == "nb_read_frames") f.frames = std::stol(v);
    if (k == "r_frame_rate") {
      const auto slash = v.find('/');
      f.fps = std::stod(v.substr(0, slash)) / std::stod(v.substr(slash + 1));
    }
  }
  return f;
}

/// Decodes every frame to RGB24 (row-major, top row first).
inline std::vector<std::vector<std::uint8_t>> decode(const std::filesystem::path& video, int w,
                                                     int h) {
  const std::string cmd = "ffmpeg -v error -i '" + video.string() +
                          "' -f rawvideo -pix_fmt rgb24 pipe:1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) throw std::runtime_error("popen failed: " + cmd);
  std::vector<std::vector<std::uint8_t>> frames;
  const std::size_t bytes = static_cast<std::size_t>(w) * h * 3;
  for (;;) {
    std::vector<std::uint8_t> f(bytes);
    if (std::fread(f.data(), 1, bytes, p) != bytes) break;
    frames.push_back(std::move(f));
  }
  if (::pclose(p) != 0) throw std::runtime_error("ffmpeg decode failed: " + cmd);
  return frames;
}

/// Mean absolute difference of two RGB images over a rectangle (x0,y0,w,h), in 0..255.
inline double mean_abs_diff(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b,
                            int width, int x0, int y0, int w, int h) {
  double sum = 0;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3 + c;
        sum += std::abs(static_cast<int>(a[i]) - static_cast<int>(b[i]));
      }
    }
  }
  return sum / (3.0 * w * h);
}

/// Standard deviation of the pixel values of an RGB image (0 for a uniform image).
inline double pixel_stddev(const std::vector<std::uint8_t>& img) {
  double s = 0, s2 = 0;
  for (auto v : img) {
    s += v;
    s2 += static_cast<double>(v) * v;
  }
  const double n = static_cast<double>(img.size());
  return std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n)));
}

}  // namespace driftless::render::testing
