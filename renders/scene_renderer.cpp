#include "renders/scene_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <Eigen/Core>
#include <fmt/core.h>

namespace driftless::render {

namespace {
constexpr double kMinNearM = 0.005;  // m, the closest near plane (depth buffer precision)
constexpr double kCameraMoveS = 0.3;  // s of video the auto camera takes to close in or back out
}  // namespace

void SceneParams::validate() const {
  if (width_px < 16 || width_px > 4096 || height_px < 16 || height_px > 4096) {
    throw std::invalid_argument(
        fmt::format("frame size {}x{} px is outside 16..4096 px", width_px, height_px));
  }
  if (font_scale != 0 && (font_scale < 50 || font_scale > 300 || font_scale % 50 != 0)) {
    throw std::invalid_argument(
        fmt::format("font scale {} is not one of 50, 100, ..., 300 (percent)", font_scale));
  }
  if (!(msaa_samples >= 0 && msaa_samples <= 16)) {
    throw std::invalid_argument(fmt::format("msaa samples {} is outside 0..16", msaa_samples));
  }
  if (!(triad_length_m >= 0.0) || !std::isfinite(triad_length_m)) {
    throw std::invalid_argument("triad length must be a finite length >= 0 m");
  }
}

// ---- renderer ----

void SceneRenderer::choose_camera(const mjModel* m, const FramedBodies& bodies) {
  mjv_defaultCamera(&camera_);
  const std::string& name = params_.camera;
  if (name.empty() || name == "auto") {
    CameraDirector::Params dp;
    dp.view = params_.view;
    dp.blend_frames = std::max(1, static_cast<int>(std::lround(kCameraMoveS * params_.fps)));
    director_ = std::make_unique<CameraDirector>(m, bodies, dp);
    camera_name_ = "auto";
    return;
  }
  camera_name_ = name;
  if (name == "free") {
    // an orbit camera tracking the box (or the first body)
    mjv_defaultFreeCamera(m, &camera_);
    if (m->nbody > 1) {
      camera_.type = mjCAMERA_TRACKING;
      camera_.trackbodyid = bodies.box > 0 ? bodies.box : 1;
    }
    camera_.distance = 2.5 * m->stat.extent;
    camera_.elevation = -25;
    camera_.azimuth = 135;
    return;
  }
  const int id = mj_name2id(m, mjOBJ_CAMERA, name.c_str());
  if (id < 0) {
    std::string known;
    for (int i = 0; i < m->ncam; ++i) {
      const char* n = mj_id2name(m, mjOBJ_CAMERA, i);
      known += fmt::format("{}{}", known.empty() ? "" : ", ", n != nullptr ? n : "(unnamed)");
    }
    throw std::invalid_argument(fmt::format("camera '{}' is not in the model (cameras: {}{}auto, free)", name, known,
                                            known.empty() ? "" : ", "));
  }
  camera_.type = mjCAMERA_FIXED;
  camera_.fixedcamid = id;
}

void SceneRenderer::find_triads(const mjModel* m) {
  // the sensors' axis triads sit at the sites of the gyro sensors
  for (int i = 0; i < m->nsensor; ++i) {
    if (m->sensor_type[i] == mjSENS_GYRO && m->sensor_objtype[i] == mjOBJ_SITE) {
      const int site = m->sensor_objid[i];
      if (std::find(triad_sites_.begin(), triad_sites_.end(), site) == triad_sites_.end()) {
        triad_sites_.push_back(site);
      }
    }
  }
  // triads scale with the box: 0.7 x the distance between the two sensors when there are two
  triad_length_m_ = params_.triad_length_m;
  if (triad_length_m_ <= 0 && triad_sites_.size() >= 2) {
    mjData* d0 = mj_makeData(m);
    mj_kinematics(m, d0);
    const Eigen::Map<const Eigen::Vector3d> a(d0->site_xpos + 3 * triad_sites_[0]);
    const Eigen::Map<const Eigen::Vector3d> b(d0->site_xpos + 3 * triad_sites_[1]);
    triad_length_m_ = 0.7 * (a - b).norm();
    mj_deleteData(d0);
  }
  if (triad_length_m_ <= 0) triad_length_m_ = m->stat.extent / 10.0;
}

SceneRenderer::SceneRenderer(const mjModel* model, const SceneParams& params, const FramedBodies& bodies)
    : params_(params), live_model_(model), model_(nullptr, &mj_deleteModel), bodies_(bodies) {
  params_.validate();
  if (model == nullptr) throw std::invalid_argument("SceneRenderer needs a model");
  model_.reset(mj_copyModel(nullptr, model));
  mjModel* m = model_.get();
  // the off-screen framebuffer is sized from the model's visual settings
  m->vis.global.offwidth = params_.width_px;
  m->vis.global.offheight = params_.height_px;
  m->vis.quality.offsamples = params_.msaa_samples;
  if (!params_.shadows) m->vis.quality.shadowsize = 0;
  choose_camera(m, bodies);
  find_triads(m);

  mjv_defaultOption(&option_);
  mjv_defaultScene(&scene_);
  mjv_makeScene(m, &scene_, 2000);
  scene_.flags[mjRND_SHADOW] = params_.shadows ? 1 : 0;
  scene_.flags[mjRND_REFLECTION] = params_.reflections ? 1 : 0;
  scene_.flags[mjRND_SKYBOX] = 0;

  mjr_defaultContext(&context_);
  int font = params_.font_scale;
  if (font == 0) {
    font = params_.height_px >= 1000 ? 200
           : params_.height_px >= 700 ? 150
           : params_.height_px >= 400 ? 100
                                      : 50;
  }
  mjr_makeContext(m, &context_, font);
  if (context_.offFBO == 0 || context_.offWidth < params_.width_px ||
      context_.offHeight < params_.height_px) {
    mjr_freeContext(&context_);
    mjv_freeScene(&scene_);
    throw std::runtime_error(fmt::format(
        "the GL context gave no {}x{} px off-screen framebuffer (got {}x{})", params_.width_px,
        params_.height_px, context_.offWidth, context_.offHeight));
  }
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  bottom_up_.resize(static_cast<std::size_t>(params_.width_px) * params_.height_px * 3);
}

SceneRenderer::~SceneRenderer() {
  mjr_freeContext(&context_);
  mjv_freeScene(&scene_);
}

void SceneRenderer::add_triads(const mjData* d) {
  static constexpr float kAxisRgba[3][4] = {
      {0.90f, 0.15f, 0.15f, 1.0f}, {0.15f, 0.80f, 0.15f, 1.0f}, {0.20f, 0.35f, 0.95f, 1.0f}};
  const mjtNum width = triad_length_m_ * 0.08;
  for (int site : triad_sites_) {
    const mjtNum* p = d->site_xpos + 3 * site;
    const mjtNum* R = d->site_xmat + 9 * site;  // row-major: column j is the site's axis j
    for (int axis = 0; axis < 3; ++axis) {
      if (scene_.ngeom >= scene_.maxgeom) return;
      mjvGeom* g = scene_.geoms + scene_.ngeom;
      mjv_initGeom(g, mjGEOM_ARROW, nullptr, nullptr, nullptr, kAxisRgba[axis]);
      const mjtNum L = triad_length_m_;
      mjv_makeConnector(g, mjGEOM_ARROW, width, p[0], p[1], p[2], p[0] + L * R[0 + axis],
                        p[1] + L * R[3 + axis], p[2] + L * R[6 + axis]);
      g->category = mjCAT_DECOR;
      g->emission = 0.3f;
      ++scene_.ngeom;
    }
  }
}

FrameLayout frame_layout(int w, int h, int text_rows, int row_px, int charts) {
  FrameLayout l;
  l.scene = {0, 0, w, h};
  // parts that would not be readable, or would leave the view too little room, are left out
  if (w * 36 / 100 < kMinChartWidthPx || (h - row_px - 8) / std::max(charts, 2) < kMinChartHeightPx) charts = 0;
  if (text_rows * row_px + 12 > h * 45 / 100) text_rows = 0;
  if (charts > 0) {
    // a column of charts on the right, each at most half the height
    const int cw = w * 36 / 100;
    l.column = {w - cw, 0, cw, h};
    l.scene.width = w - cw;
    l.title = {w - cw, h - row_px - 8, cw, row_px + 8};
    const int chh = l.title.bottom / std::max(charts, 2);
    for (int i = 0; i < charts; ++i) l.charts.push_back({w - cw, l.title.bottom - (i + 1) * chh, cw, chh});
  }
  if (text_rows > 0) {
    const int band = text_rows * row_px + 12;
    l.text = {0, h - band, l.scene.width, band};
    l.scene.height = h - band;
  }
  return l;
}

// MuJoCo puts the near plane at znear x the model's extent (0.5 m for the twin, whose ship is
// 12 m long), which would cut a camera close to the box: bring it to half the way to the box
void SceneRenderer::fit_near_plane(const mjData* data) {
  const auto corners = body_corners_world(live_model_, data, bodies_.box, option_);
  if (corners.empty()) return;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& c : corners) centre += c;
  centre /= static_cast<double>(corners.size());
  double radius = 0.0;
  for (const auto& c : corners) radius = std::max(radius, (c - centre).norm());
  for (auto& cam : scene_.camera) {
    const Eigen::Vector3d pos(cam.pos[0], cam.pos[1], cam.pos[2]);
    const float near = static_cast<float>(std::max(kMinNearM, 0.5 * ((pos - centre).norm() - radius)));
    if (cam.frustum_near <= near) continue;
    const float k = near / cam.frustum_near;
    cam.frustum_near = near;
    cam.frustum_center *= k;
    cam.frustum_bottom *= k;
    cam.frustum_top *= k;
  }
}

// the 3D view into `view`
void SceneRenderer::draw_world(mjData* data, const PixelRect& view, int close_up) {
  if (director_) {
    director_->update(data, option_, params_.close_ups ? close_up : -1,
                      static_cast<double>(view.width) / view.height, &camera_);
  }
  mjv_updateScene(live_model_, data, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  fit_near_plane(data);
  add_triads(data);
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  mjr_render(mjrRect{view.left, view.bottom, view.width, view.height}, &scene_, &context_);
}

void SceneRenderer::render(mjData* data, const FrameOverlay* overlay, int close_up,
                           std::vector<std::uint8_t>& rgb_top_down) {
  const int w = params_.width_px, h = params_.height_px;
  layout_ = overlay == nullptr ? frame_layout(w, h, 0, 0, 0)
                               : frame_layout(w, h, static_cast<int>(overlay->rows.size()), text_row_px(),
                                              static_cast<int>(overlay->charts.size()));
  draw_world(data, layout_.scene, close_up);
  if (overlay != nullptr) {
    if (layout_.text.height > 0) {
      fill_rect(layout_.text, 0.1f, 0.11f, 0.13f, 1.0f, w, h);
      draw_text_rows(overlay->rows, layout_.text, context_, w, h);
    }
    if (layout_.column.width > 0) {
      fill_rect(layout_.column, 0.1f, 0.11f, 0.13f, 1.0f, w, h);
      draw_text_rows({{"", overlay->title}}, layout_.title, context_, w, h);
    }
    for (std::size_t i = 0; i < overlay->charts.size() && i < layout_.charts.size(); ++i) {
      if (overlay->charts[i] != nullptr) draw_chart(*overlay->charts[i], layout_.charts[i], overlay->t_now_s, context_, w, h);
    }
  }
  mjr_readPixels(bottom_up_.data(), nullptr, mjrRect{0, 0, w, h}, &context_);
  // OpenGL rows run bottom-up; video rows run top-down
  const std::size_t row = static_cast<std::size_t>(w) * 3;
  rgb_top_down.resize(bottom_up_.size());
  for (int y = 0; y < h; ++y) {
    std::memcpy(rgb_top_down.data() + row * static_cast<std::size_t>(y),
                bottom_up_.data() + row * static_cast<std::size_t>(h - 1 - y), row);
  }
}

}  // namespace driftless::render
