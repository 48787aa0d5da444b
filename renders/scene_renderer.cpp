#include "renders/scene_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

namespace driftless::render {

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

// ---- strip chart ----

StripChart::StripChart(std::string title, std::vector<Line> lines, double window_s)
    : title_(std::move(title)), lines_(std::move(lines)), window_s_(window_s),
      data_(lines_.size()) {
  if (lines_.empty() || lines_.size() > 8) {
    throw std::invalid_argument("a strip chart holds 1..8 lines");
  }
  if (!(window_s > 0.0)) throw std::invalid_argument("strip chart window must be > 0 s");
}

void StripChart::push(double t_s, const std::vector<double>& values) {
  for (std::size_t i = 0; i < lines_.size() && i < values.size(); ++i) {
    if (!std::isfinite(values[i])) continue;
    auto& d = data_[i];
    d.emplace_back(t_s, values[i]);
    // drop what slid out of the window (kept bounded: at most a few thousand points)
    std::size_t drop = 0;
    while (drop < d.size() && d[drop].first < t_s - window_s_) ++drop;
    if (drop > 0 && (drop > 256 || drop == d.size())) d.erase(d.begin(), d.begin() + drop);
    ++points_;
  }
}

void StripChart::clear() {
  for (auto& d : data_) d.clear();
  points_ = 0;
}

std::vector<std::pair<double, double>> StripChart::points(std::size_t i, double t_now_s) const {
  std::vector<std::pair<double, double>> out;
  for (const auto& p : data_.at(i)) {
    if (p.first >= t_now_s - window_s_ && p.first <= t_now_s) out.push_back(p);
  }
  return out;
}

// ---- renderer ----

SceneRenderer::SceneRenderer(const mjModel* model, const SceneParams& params)
    : params_(params),
      live_model_(model),
      model_(nullptr, &mj_deleteModel),
      figure_(std::make_unique<mjvFigure>()) {
  params_.validate();
  if (model == nullptr) throw std::invalid_argument("SceneRenderer needs a model");
  model_.reset(mj_copyModel(nullptr, model));
  mjModel* m = model_.get();
  // the off-screen framebuffer is sized from the model's visual settings
  m->vis.global.offwidth = params_.width_px;
  m->vis.global.offheight = params_.height_px;
  m->vis.quality.offsamples = params_.msaa_samples;
  if (!params_.shadows) m->vis.quality.shadowsize = 0;

  // camera: an MJCF camera by name, "free" (tracks the first body), or the default choice
  mjv_defaultCamera(&camera_);
  std::string name = params_.camera;
  if (name.empty()) {
    if (mj_name2id(m, mjOBJ_CAMERA, "track") >= 0) {
      name = "track";
    } else if (mj_name2id(m, mjOBJ_CAMERA, "cam_track") >= 0) {
      name = "cam_track";
    } else if (m->ncam > 0) {
      const char* n0 = mj_id2name(m, mjOBJ_CAMERA, 0);
      name = n0 != nullptr ? n0 : "";
      if (name.empty()) {
        camera_.type = mjCAMERA_FIXED;
        camera_.fixedcamid = 0;
        camera_name_ = "camera 0";
      }
    } else {
      name = "free";
    }
  }
  if (camera_name_.empty()) {
    if (name == "free") {
      mjv_defaultFreeCamera(m, &camera_);
      if (m->nbody > 1) {
        camera_.type = mjCAMERA_TRACKING;
        camera_.trackbodyid = 1;
      }
      camera_.distance = 2.5 * m->stat.extent;
      camera_.elevation = -25;
      camera_.azimuth = 135;
    } else {
      const int id = mj_name2id(m, mjOBJ_CAMERA, name.c_str());
      if (id < 0) {
        std::string known;
        for (int i = 0; i < m->ncam; ++i) {
          const char* n = mj_id2name(m, mjOBJ_CAMERA, i);
          known += fmt::format("{}{}", known.empty() ? "" : ", ", n != nullptr ? n : "(unnamed)");
        }
        throw std::invalid_argument(fmt::format("camera '{}' is not in the model (cameras: {}{})",
                                                name, known.empty() ? "none" : known,
                                                known.empty() ? "; use free" : ", free"));
      }
      camera_.type = mjCAMERA_FIXED;
      camera_.fixedcamid = id;
    }
    camera_name_ = name;
  }

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
    const mjtNum* a = d0->site_xpos + 3 * triad_sites_[0];
    const mjtNum* b = d0->site_xpos + 3 * triad_sites_[1];
    triad_length_m_ = 0.7 * std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                                      (a[2] - b[2]) * (a[2] - b[2]));
    mj_deleteData(d0);
  }
  if (triad_length_m_ <= 0) triad_length_m_ = m->stat.extent / 10.0;

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

void SceneRenderer::draw_chart(const StripChart& chart, double t_now_s, int slot) {
  mjvFigure& f = *figure_;
  mjv_defaultFigure(&f);
  f.flg_legend = 0;  // the title names the lines; a legend would hide the data
  f.flg_extend = 1;
  f.flg_ticklabel[0] = 1;
  f.flg_ticklabel[1] = 1;
  f.gridsize[0] = 3;
  f.gridsize[1] = 3;
  f.figurergba[3] = 0.55f;
  f.panergba[3] = 0.6f;
  f.legendrgba[3] = 0.0f;
  std::snprintf(f.title, sizeof f.title, "%s", chart.title().c_str());
  std::snprintf(f.xformat, sizeof f.xformat, "%%.0f");
  std::snprintf(f.yformat, sizeof f.yformat, "%%.2g");
  std::snprintf(f.minwidth, sizeof f.minwidth, "-0.000");
  f.range[0][0] = static_cast<float>(t_now_s - chart.window_s());
  f.range[0][1] = static_cast<float>(t_now_s);
  f.range[1][0] = 0.0f;  // y automatic
  f.range[1][1] = 0.0f;
  for (std::size_t i = 0; i < chart.lines().size(); ++i) {
    const auto& line = chart.lines()[i];
    std::snprintf(f.linename[i], sizeof f.linename[i], "%s", line.name.c_str());
    std::copy(line.rgb, line.rgb + 3, f.linergb[i]);
    auto pts = chart.points(i, t_now_s);
    // thin to the figure's capacity, keeping the newest point
    const std::size_t n = pts.size();
    const std::size_t step = n > mjMAXLINEPNT ? (n + mjMAXLINEPNT - 1) / mjMAXLINEPNT : 1;
    int k = 0;
    for (std::size_t j = (n - 1) % step; j < n && k < mjMAXLINEPNT; j += step, ++k) {
      f.linedata[i][2 * k] = static_cast<float>(pts[j].first);
      f.linedata[i][2 * k + 1] = static_cast<float>(pts[j].second);
    }
    f.linepnt[i] = k;
  }
  const int w = params_.width_px * 40 / 100;
  const int h = params_.height_px * 25 / 100;
  mjrRect rect{params_.width_px - w, slot * h, w, h};
  mjr_figure(rect, &f, &context_);
}

void SceneRenderer::render(mjData* data, const OverlayText& text,
                           const std::vector<const StripChart*>& charts, double t_now_s,
                           std::vector<std::uint8_t>& rgb_top_down) {
  mjv_updateScene(live_model_, data, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  add_triads(data);
  const mjrRect viewport{0, 0, params_.width_px, params_.height_px};
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  mjr_render(viewport, &scene_, &context_);
  if (!text.top_left_titles.empty()) {
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport, text.top_left_titles.c_str(),
                text.top_left_values.c_str(), &context_);
  }
  if (!text.bottom_left_titles.empty()) {
    mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMLEFT, viewport, text.bottom_left_titles.c_str(),
                text.bottom_left_values.c_str(), &context_);
  }
  int slot = 0;
  for (const StripChart* chart : charts) {
    if (chart != nullptr && !chart->empty()) draw_chart(*chart, t_now_s, slot++);
  }
  mjr_readPixels(bottom_up_.data(), nullptr, viewport, &context_);
  // OpenGL rows run bottom-up; video rows run top-down
  const std::size_t row = static_cast<std::size_t>(params_.width_px) * 3;
  rgb_top_down.resize(bottom_up_.size());
  for (int y = 0; y < params_.height_px; ++y) {
    std::memcpy(rgb_top_down.data() + row * static_cast<std::size_t>(y),
                bottom_up_.data() + row * static_cast<std::size_t>(params_.height_px - 1 - y),
                row);
  }
}

}  // namespace driftless::render
