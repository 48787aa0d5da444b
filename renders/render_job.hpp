// The frame loop: read samples from a source (a log replay or a running simulation), pose the
// world, draw frames with the overlay at the times the timeline picks, and hand them to a sink.
#pragma once

#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <mujoco/mujoco.h>

#include "estimator/config.hpp"
#include "estimator/log.hpp"
#include "renders/pose.hpp"
#include "renders/scene_renderer.hpp"
#include "renders/timeline.hpp"
#include "renders/video_sink.hpp"

namespace driftless::render {

/// What a source tells the overlay about its stream.
struct StreamInfo {
  std::string title = "DriftLess Twin";  // first overlay line (scenario or log name)
  log::Metadata metadata;  // hinge axes, sample rate, latitude (docs/log-format.md keys)
  double end_s = kNaN;     // last data time if known (progress), s
};

/// A time-ordered stream of samples and the world they are drawn in.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The world a frame is drawn in, posed from a sample at frame time.
  virtual WorldPoser& poser() = 0;
  virtual const StreamInfo& info() const = 0;
  /// The next sample as read (NaN kept: the overlay sees what the log says) and the sample to
  /// pose the world from (gaps in platform angles filled); false at the end.
  virtual bool next(Sample& sample, Sample& posed) = 0;
};

/// Replays a log: base from ref_q/ref_p, platforms from plat*_deg. A platform angle missing
/// while it moves (hardware logs) is interpolated between the angles around the gap (the gap
/// is read ahead, up to max_gap_s; longer gaps hold the last angle).
class LogFrameSource final : public FrameSource {
 public:
  /// `poser` must outlive the source.
  LogFrameSource(const std::filesystem::path& log, WorldPoser& poser, double max_gap_s = 30.0);
  WorldPoser& poser() override { return poser_; }
  const StreamInfo& info() const override { return info_; }
  bool next(Sample& sample, Sample& posed) override;

 private:
  bool fill_ahead();
  log::LogReader reader_;
  WorldPoser& poser_;
  double max_gap_s_;
  StreamInfo info_;
  std::deque<Sample> ahead_;  // raw samples read but not yet returned
  double last_deg_[2] = {kNaN, kNaN};
  double last_t_[2] = {kNaN, kNaN};
  bool eof_ = false;
};

/// Everything `driftless render` decides.
struct RenderParams {
  SceneParams scene;
  TimelineParams timeline;
  EncoderParams encoder;
  std::filesystem::path out = "video.mp4";
  bool overlay = true;
  bool run_estimator = true;     // overlay the DriftLess filter's estimate (else the residual)
  est::EstimatorConfig estimator;  // the filter's configuration
  double chart_window_s = kNaN;  // strip chart width in data s; NaN: max(30, 20 * speed)

  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

/// What a render did.
struct RenderStats {
  std::uint64_t frames = 0;
  std::uint64_t samples = 0;
  std::uint64_t realtime_flip_frames = 0;  // frames inside flips shown at x1
  double first_frame_s = kNaN, last_frame_s = kNaN;  // data times
  double wall_s = 0.0;             // whole render, s
  double draw_s = 0.0;             // GL drawing and read-back, s
  double sink_s = 0.0;             // handing frames to the encoder (waits included), s
  std::string output;              // the MP4 path or the PNG pattern
  bool png_fallback = false;       // ffmpeg was missing
  std::string gl_renderer;
  bool estimator_ran = false;      // the DriftLess filter ran for the overlay
  double estimator_locked_from_s = kNaN;  // its lock (data time, s); NaN: it never locked
  double estimator_final_sigma_dps = kNaN;  // largest sigma of its bias correction at the end
};

/// Called after each frame with the frame's data time; return false to stop early (Ctrl-C).
using RenderProgress = std::function<bool(double t_s, std::uint64_t frames)>;

/// Renders `source` to params.out. Throws GlUnavailable when no GL context can be made,
/// std::invalid_argument on bad params, std::runtime_error when the encoder fails.
RenderStats render_video(FrameSource& source, const RenderParams& params,
                         const RenderProgress& progress = {});

}  // namespace driftless::render
