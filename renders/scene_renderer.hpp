// Draws a posed MuJoCo world plus an overlay into an off-screen buffer and reads it back as RGB.
// Frame layout (docs/render.md, "Frame layout"): the 3D view on the left under a band of text,
// strip charts in a column on the right; without overlay the view fills the frame.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "renders/chart.hpp"
#include "renders/framing.hpp"

namespace driftless::render {

/// How a frame looks. Defaults are chosen for software rendering speed (no shadows, no MSAA).
struct SceneParams {
  int width_px = 640;
  int height_px = 480;
  // "" (default) or "auto": the framing camera (box large, close-up of a flipping platform);
  // "free": an orbit camera tracking the box; else an MJCF camera by name
  std::string camera;
  ViewAngles view;              // direction of the framing camera, deg
  bool close_ups = true;        // framing camera: show a flipping platform large
  double fps = 30.0;            // video frames per second: the camera's moves take 0.3 s of video
  bool shadows = false;         // shadows double llvmpipe's cost per frame
  bool reflections = false;
  int msaa_samples = 0;         // off-screen multisampling (0 = off)
  double triad_length_m = 0.0;  // sensor axis arrows, m; 0 = 0.7 x the distance between sensors
  int font_scale = 0;           // mjtFontScale (50..300); 0 = from the height

  /// Throws std::invalid_argument on sizes outside 16..4096 px or a bad font scale.
  void validate() const;
};

/// Where each part of a frame goes (pixels, origin bottom left).
struct FrameLayout {
  PixelRect scene;               // the 3D view
  PixelRect text;                // the band of overlay text above the view
  PixelRect column;              // the chart column
  PixelRect title;               // its top row: the run's title
  std::vector<PixelRect> charts; // top to bottom
};
/// Charts narrower or lower than this are left out of a frame, px.
inline constexpr int kMinChartWidthPx = 200;
inline constexpr int kMinChartHeightPx = 90;
/// The layout for a w x h frame with `text_rows` rows of text of `row_px` pixels and `charts`
/// charts under a title row; no text and no charts give the whole frame to the view. Charts
/// that would be smaller than kMinChart*Px, and a text band taller than 45 % of the frame, are
/// left out (small frames show the world only).
FrameLayout frame_layout(int w, int h, int text_rows, int row_px, int charts);

/// What a frame shows besides the world.
struct FrameOverlay {
  std::string title;  // the run (scenario or log name), above the charts
  std::vector<TextRow> rows;
  std::vector<const StripChart*> charts;  // top to bottom; empty charts say why
  double t_now_s = 0.0;                   // data time the charts are drawn up to, s
};

/// Owns the MuJoCo visual state (mjvScene, mjrContext) for one model. Needs a current GL context
/// (GlContext) on the calling thread for its whole life.
class SceneRenderer {
 public:
  /// Sizes the off-screen buffer for a copy of `model`; frames draw `model` itself (so changes
  /// such as hidden carriers show), which must outlive the renderer. `bodies`: the box and its
  /// platforms for the framing camera. Throws std::invalid_argument for an unknown camera
  /// (listing the model's cameras).
  SceneRenderer(const mjModel* model, const SceneParams& params, const FramedBodies& bodies);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Renders `data` (positions already computed: mj_kinematics + mj_comPos + mj_camlight) with
  /// `overlay` (nullptr: the world only); `close_up`: the platform (0/1) the framing camera shows
  /// large, -1 for the box. `rgb_top_down` receives width*height*3 bytes, first row at the top.
  void render(mjData* data, const FrameOverlay* overlay, int close_up, std::vector<std::uint8_t>& rgb_top_down);

  /// The camera in use ("auto", "free" or an MJCF camera name).
  const std::string& camera_name() const { return camera_name_; }
  /// Site ids drawn with an axis triad (the sites of the model's gyro sensors).
  const std::vector<int>& triad_sites() const { return triad_sites_; }
  int width() const { return params_.width_px; }
  int height() const { return params_.height_px; }
  /// Pixel height of one overlay text row.
  int text_row_px() const { return context_.charHeight + 3; }
  /// The layout of the last frame rendered.
  const FrameLayout& layout() const { return layout_; }
  /// The framing camera (null with an MJCF or free camera).
  const CameraDirector* director() const { return director_.get(); }

 private:
  void choose_camera(const mjModel* m, const FramedBodies& bodies);
  void find_triads(const mjModel* m);
  void add_triads(const mjData* data);
  void draw_world(mjData* data, const PixelRect& view, int close_up);
  void fit_near_plane(const mjData* data);

  SceneParams params_;
  const mjModel* live_model_;
  std::unique_ptr<mjModel, decltype(&mj_deleteModel)> model_;
  mjvScene scene_{};
  mjrContext context_{};
  mjvCamera camera_{};
  mjvOption option_{};
  FramedBodies bodies_;
  std::unique_ptr<CameraDirector> director_;
  std::string camera_name_;
  std::vector<int> triad_sites_;
  double triad_length_m_ = 0.05;
  FrameLayout layout_;
  std::vector<std::uint8_t> bottom_up_;
};

}  // namespace driftless::render
