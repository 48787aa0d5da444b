#include "renders/render_job.hpp"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include <fmt/core.h>

#include "renders/gl_context.hpp"
#include "renders/overlay.hpp"
#include "renders/telemetry.hpp"

namespace driftless::render {

// ---- log replay ----

LogFrameSource::LogFrameSource(const std::filesystem::path& log, WorldPoser& poser,
                               double max_gap_s)
    : reader_(log), poser_(poser), max_gap_s_(max_gap_s) {
  const auto& meta = reader_.metadata();
  // a simulated log names its scenario: the replay then looks exactly like the simulation
  info_.title = meta.get("scenario").value_or(log.filename().string());
  info_.metadata = meta;
  info_.end_s = meta.get_number("duration_s", kNaN);
}

bool LogFrameSource::fill_ahead() {
  if (eof_) return false;
  Sample s;
  if (!reader_.next(s)) {
    eof_ = true;
    return false;
  }
  ahead_.push_back(s);
  return true;
}

bool LogFrameSource::next(Sample& sample, Sample& posed) {
  if (ahead_.empty() && !fill_ahead()) return false;
  sample = ahead_.front();
  ahead_.pop_front();
  posed = sample;
  double* deg[2] = {&posed.plat1_deg, &posed.plat2_deg};
  for (int i = 0; i < 2; ++i) {
    if (std::isfinite(*deg[i])) {
      last_deg_[i] = *deg[i];
      last_t_[i] = sample.t_s;
      continue;
    }
    // a gap: find the angle after it (reading ahead) and interpolate in time across it
    double next_deg = kNaN, next_t = kNaN;
    for (std::size_t k = 0;; ++k) {
      if (k == ahead_.size() && !fill_ahead()) break;
      const Sample& a = ahead_[k];
      if (a.t_s - sample.t_s > max_gap_s_) break;
      const double v = i == 0 ? a.plat1_deg : a.plat2_deg;
      if (std::isfinite(v)) {
        next_deg = v;
        next_t = a.t_s;
        break;
      }
    }
    if (std::isfinite(last_deg_[i]) && std::isfinite(next_deg)) {
      const double f = (sample.t_s - last_t_[i]) / (next_t - last_t_[i]);
      *deg[i] = last_deg_[i] + f * (next_deg - last_deg_[i]);
    } else if (std::isfinite(last_deg_[i])) {
      *deg[i] = last_deg_[i];
    } else {
      *deg[i] = next_deg;  // NaN too: the poser keeps the model's reference angle
    }
  }
  return true;
}

// ---- params ----

void RenderParams::validate() const {
  scene.validate();
  timeline.validate();
  encoder.validate();
  if (out.empty()) throw std::invalid_argument("--out needs a file name (e.g. video.mp4)");
  if (!std::isnan(chart_window_s) && !(chart_window_s > 0.0)) {
    throw std::invalid_argument("chart window must be > 0 s");
  }
}

namespace {

double now_s() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// hands frames to the sink on a second thread, so drawing and encoding overlap
class AsyncSink {
 public:
  AsyncSink(std::unique_ptr<VideoSink> sink, std::size_t frame_bytes, std::size_t depth = 3)
      : sink_(std::move(sink)), free_(depth, std::vector<std::uint8_t>(frame_bytes)) {
    worker_ = std::thread([this] { run(); });
  }
  ~AsyncSink() {
    stop();
  }
  // a free buffer to draw into (blocks while all are queued)
  std::vector<std::uint8_t> take_buffer() {
    std::unique_lock lk(mu_);
    cv_.wait(lk, [&] { return !free_.empty() || failed_; });
    rethrow_locked();
    auto b = std::move(free_.back());
    free_.pop_back();
    return b;
  }
  void submit(std::vector<std::uint8_t> frame) {
    {
      std::lock_guard lk(mu_);
      rethrow_locked();
      queue_.push_back(std::move(frame));
    }
    cv_.notify_all();
  }
  // waits for the queue to drain and closes the sink; rethrows the sink's error
  void close() {
    stop();
    std::lock_guard lk(mu_);
    rethrow_locked();
    sink_->close();
  }
  const VideoSink& sink() const { return *sink_; }
  double busy_s() const { return busy_s_; }

 private:
  void stop() {
    {
      std::lock_guard lk(mu_);
      stopping_ = true;
    }
    cv_.notify_all();
    if (worker_.joinable()) worker_.join();
  }
  void rethrow_locked() {
    if (error_) {
      auto e = error_;
      error_ = nullptr;
      std::rethrow_exception(e);
    }
  }
  void run() {
    for (;;) {
      std::vector<std::uint8_t> frame;
      {
        std::unique_lock lk(mu_);
        cv_.wait(lk, [&] { return !queue_.empty() || stopping_; });
        if (queue_.empty()) return;
        frame = std::move(queue_.front());
        queue_.pop_front();
      }
      const double t0 = now_s();
      try {
        if (!failed_) sink_->write(frame.data());
      } catch (...) {
        std::lock_guard lk(mu_);
        failed_ = true;
        error_ = std::current_exception();
      }
      busy_s_ += now_s() - t0;
      {
        std::lock_guard lk(mu_);
        free_.push_back(std::move(frame));
      }
      cv_.notify_all();
    }
  }

  std::unique_ptr<VideoSink> sink_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<std::vector<std::uint8_t>> free_;
  std::deque<std::vector<std::uint8_t>> queue_;
  std::thread worker_;
  bool stopping_ = false;
  bool failed_ = false;
  std::exception_ptr error_;
  double busy_s_ = 0.0;
};

// time after a flip before the residual counts (stop ringing), s
constexpr double kSettleS = 0.3;

// what a frame needs of a sample
struct Held {
  Sample posed;
  OverlayState overlay;
  double rest_s = 0.0;          // s, both platforms at rest this long (0 while one moves)
  int last_flip_platform = -1;  // 0/1, the platform of the latest flip
};

// the platform a frame shows in close-up: the flip a time-lapse plays at x1, or at x1 and
// slower the platform that moves (until the flip's tail has passed), else none
int close_up_platform(const FrameInfo& f, const Held& held, double speed, int realtime_platform,
                      double tail_s) {
  if (f.realtime_flip) return realtime_platform;
  if (speed > 1.0) return -1;
  for (int i = 0; i < 2; ++i) {
    if (held.overlay.moving[i]) return i;
  }
  return held.rest_s < tail_s ? held.last_flip_platform : -1;
}

// draws the frames the planner emits and hands them to the sink
class FrameDrawer {
 public:
  FrameDrawer(const RenderParams& p, const StreamInfo& info, WorldPoser& poser, SceneRenderer& scene,
              const Telemetry& telemetry, AsyncSink& out, RenderStats& stats)
      : p_(p), info_(info), poser_(poser), scene_(scene), telemetry_(telemetry), out_(out), stats_(stats) {
    end_s_ = info.end_s;
    if (!std::isnan(p.timeline.to_s) && !(p.timeline.to_s >= end_s_)) end_s_ = p.timeline.to_s;
  }
  int realtime_platform = -1;  // the flip a time-lapse is playing at x1

  void draw(const FrameInfo& f, const Held& held) {
    const double t0 = now_s();
    poser_.pose(held.posed);
    mjData* data = poser_.data();
    data->time = f.t_s;
    auto buf = out_.take_buffer();
    const double t1 = now_s();
    PlayState play{f.t_s, p_.timeline.speed, f.realtime_flip, end_s_, -1};
    play.close_up = close_up_platform(f, held, p_.timeline.speed, realtime_platform, p_.timeline.flip_tail_s);
    if (p_.overlay) {
      FrameOverlay o{info_.title, overlay_rows(play, held.overlay), telemetry_.charts(), held.posed.t_s};
      scene_.render(data, &o, play.close_up, buf);
    } else {
      scene_.render(data, nullptr, play.close_up, buf);
    }
    const double t2 = now_s();
    out_.submit(std::move(buf));
    stats_.draw_s += t2 - t1;
    stats_.sink_s += (t1 - t0) + (now_s() - t2);
    if (std::isnan(stats_.first_frame_s)) stats_.first_frame_s = f.t_s;
    stats_.last_frame_s = f.t_s;
    ++stats_.frames;
    if (f.realtime_flip) ++stats_.realtime_flip_frames;
  }

 private:
  const RenderParams& p_;
  const StreamInfo& info_;
  WorldPoser& poser_;
  SceneRenderer& scene_;
  const Telemetry& telemetry_;
  AsyncSink& out_;
  RenderStats& stats_;
  double end_s_ = kNaN;
};

std::unique_ptr<VideoSink> open_sink(const RenderParams& params, RenderStats& stats) {
  const int w = params.scene.width_px, h = params.scene.height_px;
  const auto ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) {
    stats.png_fallback = true;
    return make_png_sink(png_fallback_dir(params.out), w, h);
  }
  std::error_code ec;
  if (params.out.has_parent_path()) std::filesystem::create_directories(params.out.parent_path(), ec);
  return make_ffmpeg_sink(ffmpeg, params.out, w, h, params.timeline.fps, params.encoder);
}

}  // namespace

RenderStats render_video(FrameSource& source, const RenderParams& params,
                         const RenderProgress& progress) {
  params.validate();
  RenderStats stats;
  const double t_start = now_s();
  // the GL context comes first: without it there is nothing to encode
  GlContext gl;
  stats.gl_renderer = gl.renderer();
  WorldPoser& poser = source.poser();
  SceneParams sp = params.scene;
  sp.fps = params.timeline.fps;
  SceneRenderer scene(poser.model(), sp, poser.bodies());
  const int w = params.scene.width_px, h = params.scene.height_px;
  AsyncSink out(open_sink(params, stats), static_cast<std::size_t>(w) * h * 3);
  stats.output = out.sink().description();

  const auto& info = source.info();
  TelemetryParams tp;
  tp.run_estimator = params.run_estimator;
  tp.estimator = params.estimator;
  tp.window_s = std::isnan(params.chart_window_s) ? std::max(30.0, 20.0 * params.timeline.speed) : params.chart_window_s;
  tp.settle_s = kSettleS;
  Telemetry telemetry(tp, info.metadata);
  PlatformTracker tracker;
  FramePlanner<Held> planner(params.timeline);
  FrameDrawer drawer(params, info, poser, scene, telemetry, out, stats);
  bool keep_going = true;
  auto emit = [&](const FrameInfo& f, const Held& held) {
    if (!keep_going) return;
    drawer.draw(f, held);
    if (progress && !progress(f.t_s, stats.frames)) keep_going = false;
  };
  Sample sample;
  Held cur;
  while (keep_going && source.next(sample, cur.posed)) {
    ++stats.samples;
    const bool flip_starts = tracker.update(sample.t_s, sample.plat1_deg, sample.plat2_deg);
    cur.overlay = overlay_state(tracker);
    cur.rest_s = tracker.rest_duration_s(sample.t_s);
    cur.last_flip_platform = tracker.last_flip_platform();
    if (params.overlay) telemetry.push(sample, cur.rest_s, cur.overlay);
    if (flip_starts && !planner.in_realtime_flip()) drawer.realtime_platform = tracker.last_flip_platform();
    if (!planner.push(sample.t_s, flip_starts, cur.rest_s, cur, emit)) break;
  }
  if (keep_going) planner.finish(emit);
  out.close();
  if (const est::DriftlessFilter* f = telemetry.filter(); f != nullptr && params.overlay) {
    stats.estimator_ran = true;
    stats.estimator_locked_from_s = telemetry.locked_from_s();
    stats.estimator_final_sigma_dps = f->correction_sigma_dps().maxCoeff();
  }
  stats.wall_s = now_s() - t_start;
  return stats;
}

}  // namespace driftless::render
