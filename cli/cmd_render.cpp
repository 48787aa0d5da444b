// driftless render: an off-screen video (OSMesa, no display or GPU) of a log replay or a
// simulated scenario, with an overlay of time, platform state, residual and attitude error.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <fmt/core.h>
#include <mujoco/mujoco.h>

#include "cli/command.hpp"
#include "estimator/config.hpp"
#include "estimator/output_file.hpp"
#include "estimator/pipeline.hpp"
#include "report/json.hpp"
#include "renders/render_job.hpp"
#include "renders/twin_source.hpp"

namespace driftless::cli {
namespace {

struct RenderArgs {
  std::string scenario, log, model, out;
  int width = 640, height = 480;
  double fps = 30.0, speed = 1.0;
  double from = kNaN, to = kNaN;
  double realtime_flip_every = kNaN;
  std::string camera;
  double azimuth_deg = render::ViewAngles{}.azimuth_deg;
  double elevation_deg = render::ViewAngles{}.elevation_deg;
  bool no_close_ups = false;
  std::string preset = "ultrafast";
  int crf = 23;
  bool no_overlay = false;
  bool no_estimate = false;
  std::string config;    // estimator config YAML (docs/estimator.md)
  bool selfcal = false;  // the self-calibrating filter
};

// the filter's configuration as `driftless estimate` reads it (--config, --selfcal)
est::EstimatorConfig estimator_config(const RenderArgs& a) {
  est::EstimatorConfig cfg;
  if (!a.config.empty()) {
    std::ifstream in(a.config);
    if (!in) throw std::runtime_error("cannot read --config " + a.config);
    cfg = est::parse_estimator_config(in, a.config, est::EstimatorConfig{});
  }
  if (a.selfcal) cfg.self_calibration = true;
  return cfg;
}

using ModelPtr = std::unique_ptr<mjModel, decltype(&mj_deleteModel)>;

ModelPtr load_mjcf(const std::string& path) {
  char err[1000] = "";
  ModelPtr m(mj_loadXML(path.c_str(), nullptr, err, sizeof err), &mj_deleteModel);
  if (!m) throw std::runtime_error(fmt::format("{}: cannot load the MJCF model: {}", path, err));
  return m;
}

// video.json beside video.mp4: what the renderer wrote, for checks (driftless demo) and users
void write_sidecar(const RenderArgs& a, const render::RenderParams& p, const render::RenderStats& st, bool complete) {
  const std::filesystem::path path = std::filesystem::path(a.out).replace_extension(".json");
  using report::json_number;
  using report::json_string;
  io::write_file(path, fmt::format(
      "{{\n  \"format\": \"driftless-video 1\",\n  \"output\": {},\n  \"png_fallback\": {},\n"
      "  \"complete\": {},\n  \"frames\": {},\n  \"width\": {},\n  \"height\": {},\n  \"fps\": {},\n"
      "  \"speed\": {},\n  \"first_frame_s\": {},\n  \"last_frame_s\": {},\n  \"realtime_flip_frames\": {},\n"
      "  \"camera\": {},\n  \"wall_s\": {:.3f},\n  \"stopped_at_t_s\": {},\n"
      "  \"estimator\": {{\"ran\": {}, \"self_calibration\": {}, \"locked_from_t_s\": {}, \"final_sigma_dps\": {}}}\n}}\n",
      json_string(st.output), st.png_fallback, complete, st.frames, p.scene.width_px, p.scene.height_px,
      json_number(p.timeline.fps), json_number(p.timeline.speed), json_number(st.first_frame_s),
      json_number(st.last_frame_s), st.realtime_flip_frames, json_string(p.scene.camera.empty() ? "auto" : p.scene.camera),
      st.wall_s, complete ? std::string("null") : json_number(st.last_frame_s), st.estimator_ran,
      st.estimator_ran && p.estimator.self_calibration, json_number(st.estimator_locked_from_s),
      json_number(st.estimator_final_sigma_dps)));
}

int run_render(const RenderArgs& a) {
  render::RenderParams p;
  p.scene.width_px = a.width;
  p.scene.height_px = a.height;
  p.scene.camera = a.camera;
  p.scene.view = {a.azimuth_deg, a.elevation_deg};
  p.scene.close_ups = !a.no_close_ups;
  p.timeline.fps = a.fps;
  p.timeline.speed = a.speed;
  p.timeline.from_s = a.from;
  p.timeline.to_s = a.to;
  p.timeline.realtime_flip_every_s = a.realtime_flip_every;
  p.encoder.preset = a.preset;
  p.encoder.crf = a.crf;
  p.out = a.out;
  p.overlay = !a.no_overlay;
  p.run_estimator = !a.no_estimate;
  if (p.run_estimator) p.estimator = estimator_config(a);
  p.validate();

  // the source: a simulation as it runs, or a log replayed in the twin's model (or an MJCF)
  std::unique_ptr<render::FrameSource> source;
  std::unique_ptr<render::WorldPoser> poser;
  ModelPtr mjcf(nullptr, &mj_deleteModel);
  if (!a.scenario.empty()) {
    source = std::make_unique<render::ScenarioFrameSource>(twin::load_scenario(a.scenario));
  } else {
    const bool is_xml = a.model.size() > 4 && a.model.substr(a.model.size() - 4) == ".xml";
    if (is_xml) {
      mjcf = load_mjcf(a.model);
      poser = std::make_unique<render::BoxPoser>(mjcf.get());
    } else {
      // the twin's box with the log's hinge axes, or the model config's box (--model .yaml)
      log::LogReader head(a.log);
      twin::ModelConfig cfg;
      cfg.box.hinge1_axis = head.metadata().hinge1_axis().normalized();
      cfg.box.hinge2_axis = head.metadata().hinge2_axis().normalized();
      if (!a.model.empty()) cfg = twin::load_model_config(a.model, cfg);
      poser = std::make_unique<render::TwinPoser>(cfg.box,
                                                  render::carrier_from_metadata(head.metadata()));
    }
    source = std::make_unique<render::LogFrameSource>(a.log, *poser);
  }

  Progress bar("render");
  const double end = std::isnan(a.to) ? source->info().end_s : a.to;
  const double begin = std::isnan(a.from) ? 0.0 : a.from;
  const auto stats = render::render_video(*source, p, [&](double t, std::uint64_t frames) {
    if (std::isfinite(end) && end > begin) {
      bar.update(std::clamp((t - begin) / (end - begin), 0.0, 1.0),
                 fmt::format("{} frames, t = {:.1f} s", frames, t));
    }
    return !stop_requested().load();
  });
  bar.done(fmt::format("{} frames", stats.frames));
  if (stats.png_fallback) {
    fmt::print(stderr,
               "driftless render: note: the ffmpeg program was not found (set {} or install "
               "ffmpeg), so no MP4 was made: wrote {} PNG frames to {} instead\n",
               render::kFfmpegEnv, stats.frames, stats.output);
  }
  fmt::print("{}: {} frames {}x{} px at {:g} frames/s ({:.2f} s of video), data t = {:.2f} .. "
             "{:.2f} s, {} frames of flips at x1; rendered in {:.1f} s ({:.1f} frames/s)\n",
             stats.output, stats.frames, a.width, a.height, a.fps,
             static_cast<double>(stats.frames) / a.fps, stats.first_frame_s, stats.last_frame_s,
             stats.realtime_flip_frames, stats.wall_s,
             stats.wall_s > 0 ? static_cast<double>(stats.frames) / stats.wall_s : 0.0);
  write_sidecar(a, p, stats, !stop_requested().load());
  if (stats.estimator_ran && std::isnan(stats.estimator_locked_from_s)) {
    fmt::print(stderr,
               "driftless render: note: the overlaid DriftLess filter never locked on (the largest sigma of "
               "its bias correction is {:.3g} deg/s at the end, lock needs < {:g}): its bias charts are "
               "unconverged and no attitude error is shown. 'driftless estimate' on the log says why; "
               "uncalibrated MEMS gyros on a moving box (the shipped pan_tilt and vehicle scenarios) need "
               "--selfcal and a log long enough to lock\n",
               stats.estimator_final_sigma_dps, est::EstimateRunOptions{}.attitude_start_sigma_dps);
  }
  if (stop_requested().load()) {
    fmt::print(stderr, "driftless render: stopped early (Ctrl-C); the video ends at t = {:.2f} s\n",
               stats.last_frame_s);
    return interrupted_exit_code();
  }
  return kExitOk;
}

const bool registered_render = register_command(60, [](CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "render",
      "Render an off-screen video (MP4, H.264 via ffmpeg; PNG frames if ffmpeg is missing) of a "
      "log replay or a simulated scenario: box, platforms, sensor axes, carrier, overlay "
      "(docs/render.md)");
  auto a = std::make_shared<RenderArgs>();
  auto* scen = cmd->add_option("--scenario", a->scenario,
                               "Scenario YAML to simulate and render (models/scenarios/*.yaml) "
                               "or a built-in scenario name (static, pan_tilt, vehicle, ...)");
  auto* log = cmd->add_option("--log", a->log,
                              "Measurement log to replay (docs/log-format.md): base from "
                              "ref_q/ref_p, platforms from plat1_deg/plat2_deg")
                  ->check(CLI::ExistingFile);
  scen->excludes(log);
  log->excludes(scen);
  cmd->add_option("--model", a->model,
                  "Model for --log: a model config YAML (its box block; default: the shipped box "
                  "with the log's hinge axes) or an MJCF file (.xml) with a 'box' body and "
                  "'hinge1'/'hinge2' joints")
      ->check(CLI::ExistingFile)
      ->needs(log);
  cmd->add_option("--out", a->out, "Output video file (.mp4)")->required();
  cmd->add_option("--width", a->width, "Frame width, px (even)")->capture_default_str();
  cmd->add_option("--height", a->height, "Frame height, px (even)")->capture_default_str();
  cmd->add_option("--fps", a->fps, "Video frame rate, frames/s")->capture_default_str();
  cmd->add_option("--camera", a->camera,
                  "auto (default): a camera that frames the box large, follows it and closes in "
                  "on a flipping platform; 'free': an orbit camera tracking the box; or an MJCF "
                  "camera name");
  cmd->add_option("--azimuth", a->azimuth_deg,
                  "Direction the auto camera looks towards, deg from East towards North (ENU)")
      ->capture_default_str();
  cmd->add_option("--elevation", a->elevation_deg,
                  "Elevation of the auto camera's line of sight, deg (negative: looking down)")
      ->capture_default_str()
      ->check(CLI::Range(-89.0, 89.0));
  cmd->add_flag("--no-close-ups", a->no_close_ups,
                "Auto camera: keep the whole box in view during flips (no close-up of the platform)");
  auto* from = cmd->add_option("--from", a->from, "First data time shown, s (default: start)");
  auto* to = cmd->add_option("--to", a->to, "Data time where the video ends, s (default: end)");
  (void)from;
  (void)to;
  cmd->add_option("--speed", a->speed,
                  "Playback speed, x real time (data s per video s); > 1 is a time-lapse in "
                  "which flips are still shown at x1 now and then (--realtime-flip-every)")
      ->capture_default_str();
  cmd->add_option("--realtime-flip-every", a->realtime_flip_every,
                  "In a time-lapse, play a flip at x1 if it starts at least this long after the "
                  "last one so shown, s of data time (default: 5 s of video, i.e. 5 x speed; "
                  "0: never)");
  cmd->add_option("--preset", a->preset, "x264 preset (ultrafast .. veryslow)")
      ->capture_default_str();
  cmd->add_option("--crf", a->crf, "x264 quality, 0 (lossless) .. 51 (worst)")
      ->capture_default_str();
  cmd->add_flag("--no-overlay", a->no_overlay, "Draw the scene only (no text, no chart)");
  CLI::Option* no_estimate = cmd->add_flag("--no-estimate", a->no_estimate,
                "Chart the residual of eq. (2) instead of running the DriftLess filter for the "
                "bias chart and the attitude error");
  cmd->add_option("--config", a->config,
                  "Estimator config YAML for the overlaid filter, as for driftless estimate "
                  "(docs/estimator.md; default: the defaults)")
      ->check(CLI::ExistingFile)
      ->excludes(no_estimate);
  cmd->add_flag("--selfcal", a->selfcal,
                "Run the overlaid filter self-calibrating (g-sensitivity, scale factor, "
                "misalignment; needs accel columns): the shipped moving-base scenarios use "
                "uncalibrated MPU6050s, which the default filter does not lock on")
      ->excludes(no_estimate);
  return [a, cmd] {
    if (a->scenario.empty() && a->log.empty()) {
      throw std::invalid_argument("give --scenario FILE or --log FILE (see driftless render --help)");
    }
    (void)cmd;
    return run_render(*a);
  };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
