// Draws a posed MuJoCo world plus an overlay into an off-screen buffer and reads it back as RGB.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

namespace driftless::render {

/// How a frame looks. Defaults are chosen for software rendering speed (no shadows, no MSAA).
struct SceneParams {
  int width_px = 640;
  int height_px = 480;
  std::string camera;  // MJCF camera name, "free", or empty: "track"/"cam_track", else the first
  bool shadows = false;         // shadows double llvmpipe's cost per frame
  bool reflections = false;
  int msaa_samples = 0;         // off-screen multisampling (0 = off)
  double triad_length_m = 0.0;  // sensor axis arrows, m; 0 = 0.7 x the distance between sensors
  int font_scale = 0;           // mjtFontScale (50..300); 0 = from the height

  /// Throws std::invalid_argument on sizes outside 16..4096 px or a bad font scale.
  void validate() const;
};

/// Text placed on the frame (lines separated by '\n'); titles left, values right of them.
struct OverlayText {
  std::string top_left_titles, top_left_values;
  std::string bottom_left_titles, bottom_left_values;
};

/// A strip chart in the lower right corner: up to 8 named lines over a sliding window.
class StripChart {
 public:
  struct Line {
    std::string name;
    float rgb[3];
  };
  /// title: chart title; window_s: width of the x axis in seconds of data time.
  StripChart(std::string title, std::vector<Line> lines, double window_s);
  /// Appends one point per line (NaN leaves a line untouched at that time).
  void push(double t_s, const std::vector<double>& values);
  void clear();
  bool empty() const { return points_ == 0; }
  const std::string& title() const { return title_; }
  const std::vector<Line>& lines() const { return lines_; }
  double window_s() const { return window_s_; }
  /// Points of line i as (t, value) pairs inside the window ending at t_now_s.
  std::vector<std::pair<double, double>> points(std::size_t i, double t_now_s) const;

 private:
  std::string title_;
  std::vector<Line> lines_;
  double window_s_;
  std::vector<std::vector<std::pair<double, double>>> data_;  // per line, time-ordered
  std::size_t points_ = 0;
};

/// Owns the MuJoCo visual state (mjvScene, mjrContext) for one model. Needs a current GL context
/// (GlContext) on the calling thread for its whole life.
class SceneRenderer {
 public:
  /// Sizes the off-screen buffer for a copy of `model`; frames draw `model` itself (so changes
  /// such as hidden carriers show), which must outlive the renderer. Throws
  /// std::invalid_argument for an unknown camera (listing the model's cameras).
  SceneRenderer(const mjModel* model, const SceneParams& params);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Renders `data` (positions already computed: mj_kinematics + mj_comPos + mj_camlight) with
  /// the overlay text and charts (stacked up from the lower right corner, drawn up to t_now_s);
  /// `rgb_top_down` receives width*height*3 bytes, first row at the top.
  void render(mjData* data, const OverlayText& text, const std::vector<const StripChart*>& charts,
              double t_now_s, std::vector<std::uint8_t>& rgb_top_down);

  /// The camera in use ("free" or an MJCF camera name).
  const std::string& camera_name() const { return camera_name_; }
  /// Site ids drawn with an axis triad (the sites of the model's gyro sensors).
  const std::vector<int>& triad_sites() const { return triad_sites_; }
  int width() const { return params_.width_px; }
  int height() const { return params_.height_px; }

 private:
  void add_triads(const mjData* data);
  void draw_chart(const StripChart& chart, double t_now_s, int slot);

  SceneParams params_;
  const mjModel* live_model_;
  std::unique_ptr<mjModel, decltype(&mj_deleteModel)> model_;
  mjvScene scene_{};
  mjrContext context_{};
  mjvCamera camera_{};
  mjvOption option_{};
  std::unique_ptr<mjvFigure> figure_;
  std::string camera_name_;
  std::vector<int> triad_sites_;
  double triad_length_m_ = 0.05;
  std::vector<std::uint8_t> bottom_up_;
};

}  // namespace driftless::render
