// calib.yaml writer and reader: one table per block drives parse, allowed keys and emit
// (estimator/fields.hpp); the two writers (calibrate, estimate --selfcal) fill the same document.
#include "calibration/calib_file.hpp"

#include <cmath>
#include <stdexcept>

#include "estimator/geometry.hpp"
#include "estimator/output_file.hpp"
#include "twin/yaml_doc.hpp"

namespace driftless::calib {
namespace {

using fields::Table;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// ---- the document: what the file holds, block by block ----

// rig.segments[k]: a plan segment's span and axis, and the plateau samples it gave
struct SpanRecord {
  PlanSegment seg;
  bool has_samples = false;
  std::size_t samples_used = 0;
};

struct RigBlock {
  std::string source;
  double latitude_deg = kNaN;    // deg, null when unknown
  double sample_rate_hz = kNaN;  // Hz, null when unknown
  bool has_conditions = false;   // the keys below (calibrate writes them; a self-calibration not)
  bool earth_rate_removed = false;
  double gyro_full_scale_dps = 250.0;
  std::array<double, 2> mean_temp_degc{kNaN, kNaN};
  std::vector<SpanRecord> segments;
};

// sensorN.minus90 / plus90: M, and with a fit its sigma, inverse, residuals and biases
struct PositionBlock {
  est::SensorPositionFit fit;
  bool has_fit = false;
};

struct GBlock {
  Mat3 G_dps_per_g = Mat3::Zero();
  Mat3 G_sigma = Mat3::Zero();       // deg/s per g, 1-sigma
  bool has_fit = false;              // b0, residual, segments (the rig's fit)
  Vec3 b0_dps = Vec3::Zero();
  bool has_tc = false;
  Vec3 bias_tc_dps_per_degc = Vec3::Zero();
  Vec3 residual_rms_dps = Vec3::Zero();
  std::size_t segments = 0;
};

struct TempBlock {
  Vec3 tc_dps_per_degc = Vec3::Zero();
  Vec3 tc_sigma_dps_per_degc = Vec3::Zero();
  double final_temp_degc = kNaN;
};

// sensorN.scale_misalignment: y = (I + E) M^-1 w + ..., E and its 1-sigma per element (fraction)
struct EBlock {
  Mat3 E_frac = Mat3::Zero();
  Mat3 E_sigma_frac = Mat3::Zero();
};

struct SensorBlock {
  std::array<PositionBlock, 2> pos;  // [minus90, plus90]
  bool has_errors = false;
  est::CalibErrors errors;           // informational; readers ignore it
  bool has_g = false;
  GBlock g;
  bool has_e = false;
  EBlock e;
  bool has_temp = false;
  TempBlock temp;
};

// end_stops.platformN: the rest angle errors at its two stops (deg, actual - read about the hinge)
// and their 1-sigma; a self-calibration with end-stop states writes them
struct StopPair {
  double minus90_deg = 0.0, minus90_sigma_deg = 0.0;
  double plus90_deg = 0.0, plus90_sigma_deg = 0.0;
};

struct EndStopsBlock {
  std::array<StopPair, 2> platform;
};

enum class Matrices { kCalibrated, kNominal };

struct CalibDoc {
  std::string format = kCalibFormat;
  std::string method = "unknown";
  bool has_matrices = false;
  Matrices matrices = Matrices::kCalibrated;
  Vec3 hinge1_axis = Vec3::UnitZ();
  Vec3 hinge2_axis = Vec3::UnitX();
  RigBlock rig;
  std::array<SensorBlock, 2> sensor;
  bool has_end_stops = false;
  EndStopsBlock end_stops;
};

// ---- the tables ----

const Table<SpanRecord>& span_table() {
  using S = SpanRecord;
  static const Table<S> t = [] {
    Table<S> rows = {fields::text<S>("name", [](auto& r) -> auto& { return r.seg.name; }),
                     fields::vector<S>("axis_box", "", [](auto& r) -> auto& { return r.seg.axis_box; })};
    append_span_rows(rows, &S::seg);
    rows.push_back(fields::optional_row(fields::integer<S>("samples_used", &S::samples_used, 0, INT64_MAX),
                                        &S::has_samples));
    return rows;
  }();
  return t;
}

// [sensor 1, sensor 2] in degC, null where a sensor has no temperature
fields::Row<RigBlock> mean_temp_row() {
  return fields::custom<RigBlock>(
      "mean_temp", "degc",
      [](RigBlock& b, const fields::Node& n, const fields::Reading& r) {
        if (!n.is_list() || n.items.size() != 2) r.fail(n, "expected [sensor 1, sensor 2] in degC (null: unknown)");
        for (std::size_t i = 0; i < 2; ++i)
          b.mean_temp_degc[i] = n.items[i].is_null() ? kNaN : fields::read_number(n.items[i], r);
      },
      [](const RigBlock& b) -> std::optional<fields::Node> {
        std::vector<fields::Node> xs;
        for (double v : b.mean_temp_degc) xs.push_back(std::isfinite(v) ? fields::Node::scalar(exact_number(v)) : fields::Node{});
        return fields::Node::list(std::move(xs));
      });
}

const Table<RigBlock>& rig_table() {
  using R = RigBlock;
  static const Table<R> t = [] {
    Table<R> rows = {fields::text<R>("source", &R::source),
                     fields::number_or_null<R>("latitude", "deg", &R::latitude_deg),
                     fields::number_or_null<R>("sample_rate", "hz", &R::sample_rate_hz)};
    for (auto row : {fields::flag<R>("earth_rate_removed", &R::earth_rate_removed),
                     fields::number<R>("gyro_full_scale", "dps", &R::gyro_full_scale_dps), mean_temp_row(),
                     fields::block_list<R>("segments", &R::segments, &span_table)})
      rows.push_back(fields::optional_row(row, &R::has_conditions));
    return rows;
  }();
  return t;
}

const Table<est::SegmentBias>& bias_table() {
  using B = est::SegmentBias;
  static const Table<B> t = {fields::text<B>("segment", &B::segment), fields::vector<B>("value", "", &B::bias_dps),
                             fields::vector<B>("sigma", "", &B::sigma_dps)};
  return t;
}

const Table<PositionBlock>& position_table() {
  using P = PositionBlock;
  static const Table<P> t = [] {
    Table<P> rows = {fields::matrix3<P>("M", "", [](auto& p) -> auto& { return p.fit.M; }, false)};
    const auto fit = [](fields::Row<P> row) { return fields::optional_row(std::move(row), &P::has_fit); };
    rows.push_back(fit(fields::matrix3<P>("M_sigma", "", [](auto& p) -> auto& { return p.fit.M_sigma; }, false)));
    rows.push_back(fit(fields::matrix3<P>("M_inv", "", [](auto& p) -> auto& { return p.fit.M_inv; }, false)));
    rows.push_back(fit(fields::matrix3<P>("M_inv_sigma", "", [](auto& p) -> auto& { return p.fit.M_inv_sigma; }, false)));
    rows.push_back(fit(fields::vector<P>("residual_rms", "dps", [](auto& p) -> auto& { return p.fit.residual_rms_dps; })));
    rows.push_back(fit(fields::vector<P>("residual_max", "dps", [](auto& p) -> auto& { return p.fit.residual_max_dps; })));
    rows.push_back(fit(fields::integer<P>("samples", [](auto& p) -> auto& { return p.fit.n_samples; }, 0, INT64_MAX)));
    // bias_dps: every value and sigma in the list is in deg/s (a whole key: the list takes no other unit)
    rows.push_back(fit(fields::block_list<P>("bias_dps", [](auto& p) -> auto& { return p.fit.biases; }, &bias_table)));
    return rows;
  }();
  return t;
}

const Table<est::CalibErrors>& errors_table() {
  using E = est::CalibErrors;
  static const Table<E> t = {
      fields::vector<E>("scale_error", "pct", [](auto& e) -> auto& { return e.scale_error; }),
      fields::vector<E>("nonorthogonality", "deg", &E::nonorthogonality_deg),
      fields::vector<E>("tilt_minus90", "deg", [](auto& e) -> auto& { return e.tilt_box_deg[0]; }),
      fields::vector<E>("tilt_plus90", "deg", [](auto& e) -> auto& { return e.tilt_box_deg[1]; }),
      fields::number<E>("travel_error", "deg", &E::travel_error_deg),
      fields::number<E>("travel_offaxis", "deg", &E::travel_offaxis_deg),
  };
  return t;
}

const Table<GBlock>& g_table() {
  using G = GBlock;
  static const Table<G> t = {
      fields::matrix3<G>("G", "dps_per_g", &G::G_dps_per_g, false),
      fields::matrix3<G>("G_sigma", "", &G::G_sigma, false),
      fields::optional_row(fields::vector<G>("b0", "dps", &G::b0_dps), &G::has_fit),
      fields::optional_row(fields::vector<G>("bias_tc", "dps_per_degc", &G::bias_tc_dps_per_degc), &G::has_tc),
      fields::optional_row(fields::vector<G>("residual_rms", "dps", &G::residual_rms_dps), &G::has_fit),
      fields::optional_row(fields::integer<G>("segments", &G::segments, 0, INT64_MAX), &G::has_fit),
  };
  return t;
}

const Table<TempBlock>& temp_table() {
  using T = TempBlock;
  static const Table<T> t = {
      fields::vector<T>("bias_tc", "dps_per_degc", &T::tc_dps_per_degc),
      fields::vector<T>("bias_tc_sigma", "dps_per_degc", &T::tc_sigma_dps_per_degc),
      fields::number_or_null<T>("final_temp", "degc", &T::final_temp_degc),
  };
  return t;
}

// the g-sensitivity block: G and its 1-sigma, which cannot be negative (the filter's prior)
fields::Row<SensorBlock> g_row() {
  fields::Row<SensorBlock> row = fields::block<SensorBlock>("g_sensitivity", &SensorBlock::g, &g_table, {"G_dps_per_g"});
  auto read = row.read;
  row.read = [read](SensorBlock& s, const fields::Node& n, const fields::Reading& r) {
    read(s, n, r);
    if ((s.g.G_sigma.array() < 0.0).any() || !s.g.G_sigma.allFinite()) {
      const fields::Node* at = n.find("G_sigma");
      r.ctx.fail(at != nullptr ? *at : n, r.ctx.key("G_sigma"), "a sigma must be >= 0 deg/s per g");
    }
  };
  return fields::optional_row(std::move(row), &SensorBlock::has_g);
}

const Table<EBlock>& e_table() {
  using E = EBlock;
  static const Table<E> t = {
      fields::matrix3<E>("E", "frac", &E::E_frac, false),
      fields::matrix3<E>("E_sigma", "frac", &E::E_sigma_frac, false),
  };
  return t;
}

// the scale/misalignment block: E and its 1-sigma (>= 0), each element below 0.5 (50 %)
fields::Row<SensorBlock> scale_row() {
  fields::Row<SensorBlock> row =
      fields::block<SensorBlock>("scale_misalignment", &SensorBlock::e, &e_table, {"E_frac", "E_sigma_frac"});
  auto read = row.read;
  row.read = [read](SensorBlock& s, const fields::Node& n, const fields::Reading& r) {
    read(s, n, r);
    const auto fail = [&](const char* key, const char* what) {
      const fields::Node* at = n.find(key);
      r.ctx.fail(at != nullptr ? *at : n, r.ctx.key(key), what);
    };
    if ((s.e.E_sigma_frac.array() < 0.0).any()) fail("E_sigma_frac", "a sigma must be >= 0 (fraction)");
    if (!(s.e.E_frac.cwiseAbs().maxCoeff() < 0.5)) fail("E_frac", "each element must be below 0.5 (50 %) in size");
  };
  return fields::optional_row(std::move(row), &SensorBlock::has_e);
}

// the temperature block: both coefficients and their 1-sigma, which cannot be negative
fields::Row<SensorBlock> temperature_row() {
  fields::Row<SensorBlock> row = fields::block<SensorBlock>("temperature", &SensorBlock::temp, &temp_table,
                                                            {"bias_tc_dps_per_degc", "bias_tc_sigma_dps_per_degc"});
  auto read = row.read;
  row.read = [read](SensorBlock& s, const fields::Node& n, const fields::Reading& r) {
    read(s, n, r);
    if ((s.temp.tc_sigma_dps_per_degc.array() < 0.0).any()) {
      // the key may be written in another unit (bias_tc_sigma_dph_per_degc): then point at the block
      const fields::Node* at = n.find("bias_tc_sigma_dps_per_degc");
      r.ctx.fail(at != nullptr ? *at : n, r.ctx.key("bias_tc_sigma_dps_per_degc"), "a sigma must be >= 0 deg/s per degC");
    }
  };
  return fields::optional_row(std::move(row), &SensorBlock::has_temp);
}

const Table<StopPair>& stop_pair_table() {
  using P = StopPair;
  static const Table<P> t = {
      fields::number<P>("minus90", "deg", &P::minus90_deg),
      fields::number<P>("minus90_sigma", "deg", &P::minus90_sigma_deg),
      fields::number<P>("plus90", "deg", &P::plus90_deg),
      fields::number<P>("plus90_sigma", "deg", &P::plus90_sigma_deg),
  };
  return t;
}

// one platform's stops: all four keys, each angle within +-10 deg (the twin's limit), sigma >= 0
fields::Row<EndStopsBlock> platform_row(std::size_t i) {
  const char* stem = i == 0 ? "platform1" : "platform2";
  fields::Row<EndStopsBlock> row = fields::block<EndStopsBlock>(
      stem, [i](auto& b) -> auto& { return b.platform[i]; }, &stop_pair_table,
      {"minus90_deg", "minus90_sigma_deg", "plus90_deg", "plus90_sigma_deg"});
  auto read = row.read;
  row.read = [read, i](EndStopsBlock& b, const fields::Node& n, const fields::Reading& r) {
    read(b, n, r);
    const StopPair& p = b.platform[i];
    const auto fail = [&](const char* key, const char* what) {
      const fields::Node* at = n.find(key);
      r.ctx.fail(at != nullptr ? *at : n, r.ctx.key(key), what);
    };
    if (!(std::abs(p.minus90_deg) <= 10.0)) fail("minus90_deg", "an end-stop angle error within +-10 deg");
    if (!(std::abs(p.plus90_deg) <= 10.0)) fail("plus90_deg", "an end-stop angle error within +-10 deg");
    if (!(p.minus90_sigma_deg >= 0.0)) fail("minus90_sigma_deg", "a sigma must be >= 0 deg");
    if (!(p.plus90_sigma_deg >= 0.0)) fail("plus90_sigma_deg", "a sigma must be >= 0 deg");
  };
  return row;
}

const Table<EndStopsBlock>& end_stops_table() {
  static const Table<EndStopsBlock> t = {platform_row(0), platform_row(1)};
  return t;
}

const Table<SensorBlock>& sensor_table() {
  using S = SensorBlock;
  static const Table<S> t = {
      fields::block<S>("minus90", [](auto& s) -> auto& { return s.pos[0]; }, &position_table, {"M"}),
      fields::block<S>("plus90", [](auto& s) -> auto& { return s.pos[1]; }, &position_table, {"M"}),
      fields::optional_row(fields::block<S>("errors", &S::errors, &errors_table), &S::has_errors),
      g_row(),
      scale_row(),
      temperature_row(),
  };
  return t;
}

const Table<CalibDoc>& calib_table() {
  using D = CalibDoc;
  static const Table<D> t = {
      fields::text<D>("format", &D::format),
      fields::text<D>("method", &D::method),
      fields::optional_row(fields::choice<D>("matrices", &D::matrices,
                                             fields::Names<Matrices>{{"calibrated", Matrices::kCalibrated},
                                                                     {"nominal", Matrices::kNominal}}),
                           &D::has_matrices),
      fields::vector<D>("hinge1_axis", "", &D::hinge1_axis),
      fields::vector<D>("hinge2_axis", "", &D::hinge2_axis),
      fields::block<D>("rig", &D::rig, &rig_table),
      fields::block<D>("sensor1", [](auto& d) -> auto& { return d.sensor[0]; }, &sensor_table, {"minus90", "plus90"}),
      fields::block<D>("sensor2", [](auto& d) -> auto& { return d.sensor[1]; }, &sensor_table, {"minus90", "plus90"}),
      fields::optional_row(fields::block<D>("end_stops", &D::end_stops, &end_stops_table, {"platform1", "platform2"}),
                           &D::has_end_stops),
  };
  return t;
}

void write_doc(const std::filesystem::path& path, const CalibDoc& doc, const std::string& comment) {
  io::write_file(path, twin::to_yaml(fields::write_block(calib_table(), doc), comment) + "\n");
}

}  // namespace

void save_calib(const std::filesystem::path& path, const est::CalibFit& fit,
                const RigConditions& rig, const est::GSensitivityFit* g) {
  CalibDoc doc;
  doc.method = est::method_name(fit.method);
  doc.hinge1_axis = rig.hinge1_axis;
  doc.hinge2_axis = rig.hinge2_axis;
  doc.rig = RigBlock{rig.source, rig.latitude_deg, rig.sample_rate_hz, true, rig.earth_rate_removed,
                     rig.plan.gyro_full_scale_dps, rig.mean_temp_c, {}};
  for (std::size_t k = 0; k < rig.plan.segments.size(); ++k) {
    const bool counted = k < rig.samples_used.size();
    doc.rig.segments.push_back(SpanRecord{rig.plan.segments[k], counted, counted ? rig.samples_used[k] : 0});
  }
  const est::CalibMatrices mats = fit.matrices();
  for (std::size_t i = 0; i < 2; ++i) {
    SensorBlock& s = doc.sensor[i];
    for (std::size_t p = 0; p < 2; ++p) s.pos[p] = PositionBlock{fit.fit[i][p], true};
    // the physical errors M shows, for people to read
    s.has_errors = true;
    s.errors = est::describe_errors(mats, static_cast<int>(i), i == 0 ? rig.hinge1_axis : rig.hinge2_axis);
    s.errors.scale_error *= 100.0;  // written in %
    // y += G f: the gyro's response to specific force, from the per-segment biases
    s.has_g = g != nullptr && g->valid;
    if (s.has_g) {
      s.g = GBlock{g->G_dps_per_g[i], g->G_sigma[i], true, g->b0_dps[i], g->temperature_term,
                   g->bias_tc_dps_per_degc[i], g->residual_rms_dps[i], g->segments};
    }
  }
  write_doc(path, doc,
            "driftless calibrate output (docs/calibration.md). Convention: y_i = M^-1 w_box + b_i,\n"
            "so M (box_from_sensor) replaces R_i in eq. (1)-(2) and M^-1 replaces R_i^T. Units: deg/s, deg.");
}

void save_selfcal_calib(const std::filesystem::path& path, const SelfCalibration& sc) {
  CalibDoc doc;
  doc.method = "selfcal";
  doc.has_matrices = true;
  doc.matrices = Matrices::kNominal;
  doc.hinge1_axis = sc.hinge1_axis;
  doc.hinge2_axis = sc.hinge2_axis;
  doc.rig.source = sc.source;
  doc.rig.latitude_deg = sc.latitude_deg;
  doc.rig.sample_rate_hz = sc.sample_rate_hz;
  for (std::size_t i = 0; i < 2; ++i) {
    SensorBlock& s = doc.sensor[i];
    const Vec3 axis = (i == 0 ? sc.hinge1_axis : sc.hinge2_axis).normalized();
    for (std::size_t p = 0; p < 2; ++p) s.pos[p].fit.M = geo::rot_about_axis_deg(axis, p == 0 ? -90.0 : 90.0);
    s.has_g = true;
    s.g.G_dps_per_g = sc.G_dps_per_g[i];
    s.g.G_sigma = sc.G_sigma[i];
    s.has_e = sc.scale_states;
    s.e = EBlock{sc.E_frac[i], sc.E_sigma_frac[i]};
    s.has_temp = sc.temp_states;
    s.temp = TempBlock{sc.temp_coef_dps_per_degc[i], sc.temp_coef_sigma_dps_per_degc[i], sc.temp_ref_c[i]};
  }
  doc.has_end_stops = sc.stop_states;
  for (std::size_t p = 0; p < 2; ++p) {
    const Eigen::Index o = 2 * static_cast<Eigen::Index>(p);
    doc.end_stops.platform[p] = StopPair{sc.end_stop_deg[o], sc.end_stop_sigma_deg[o], sc.end_stop_deg[o + 1],
                                         sc.end_stop_sigma_deg[o + 1]};
  }
  write_doc(path, doc,
            "driftless estimate --selfcal output (docs/calibration.md). Convention as driftless calibrate's:\n"
            "y_i = (I + E_i) M^-1 w_box + b_i + G_i f_i + k_i (T_i - T_ref); M here are the nominal rotations\n"
            "(not calibrated), E_i the scale/misalignment error, end_stops each platform's rest angle error\n"
            "(actual - read, about its hinge). Units: deg/s, deg, deg/s per g, fraction, deg/s per degC, degC.");
}

est::CalibMatrices CalibFile::matrices_with_scale() const {
  est::CalibMatrices m = M;
  if (!has_scale_misalign) return m;
  for (int i = 0; i < 2; ++i) {
    const Mat3 inv = (Mat3::Identity() + E_frac[static_cast<std::size_t>(i)]).inverse();
    for (int p = 0; p < 2; ++p) m.M(i, p) = m.M(i, p) * inv;
  }
  return m;
}

est::Calibration CalibFile::to_filter_calibration() const {
  est::Calibration cal = matrices_nominal ? est::Calibration{} : est::to_filter_calibration(M);
  if (has_g_sensitivity) {
    cal.G_dps_per_g = G_dps_per_g;
    cal.has_g_sigma = true;
    cal.G_sigma_dps_per_g = G_sigma_dps_per_g;
  }
  cal.has_scale_misalign = has_scale_misalign;
  cal.E_frac = E_frac;
  cal.E_sigma_frac = E_sigma_frac;
  cal.has_temp_coef = has_temp_coef;
  cal.temp_coef_dps_per_degc = temp_coef_dps_per_degc;
  cal.temp_coef_sigma_dps_per_degc = temp_coef_sigma_dps_per_degc;
  cal.has_end_stops = has_end_stops;
  cal.end_stop_deg = end_stop_deg;
  cal.end_stop_sigma_deg = end_stop_sigma_deg;
  return cal;
}

CalibFile load_calib(const std::filesystem::path& path) { return parse_calib(twin::read_yaml_text(path), path.string()); }

CalibFile parse_calib(const std::string& yaml_text, const std::string& file) {
  const fields::Node root = twin::parse_yaml(yaml_text, file);
  if (!root.is_map()) throw InputError(file, root.line, "", "not a calibration file (expected a YAML map)");
  const fields::Context ctx{file, ""};
  CalibDoc doc;
  const auto given = fields::read_block(calib_table(), doc, root, ctx);
  fields::require(calib_table(), given, root, ctx, {"format"});
  if (doc.format != kCalibFormat)
    ctx.fail(*root.find("format"), "format", std::string("expected '") + kCalibFormat + "', got '" + doc.format + "'");
  fields::require(calib_table(), given, root, ctx, {"sensor1", "sensor2"});
  CalibFile c;
  c.method = doc.method;
  c.matrices_nominal = doc.has_matrices && doc.matrices == Matrices::kNominal;
  c.hinge1_axis = doc.hinge1_axis;
  c.hinge2_axis = doc.hinge2_axis;
  c.latitude_deg = doc.rig.latitude_deg;
  c.earth_rate_removed = doc.rig.earth_rate_removed;
  c.source = doc.rig.source;
  for (std::size_t i = 0; i < 2; ++i) {
    const SensorBlock& s = doc.sensor[i];
    for (std::size_t p = 0; p < 2; ++p) {
      c.M.M(static_cast<int>(i), static_cast<int>(p)) = s.pos[p].fit.M;
      c.M_sigma[i][p] = s.pos[p].fit.M_sigma;
      c.residual_rms_dps[i][p] = s.pos[p].fit.residual_rms_dps;
    }
    c.has_g_sensitivity = c.has_g_sensitivity || s.has_g;
    c.G_dps_per_g[i] = s.g.G_dps_per_g;
    c.G_sigma_dps_per_g[i] = s.g.G_sigma;
    c.has_scale_misalign = c.has_scale_misalign || s.has_e;
    c.E_frac[i] = s.e.E_frac;
    c.E_sigma_frac[i] = s.e.E_sigma_frac;
    c.has_temp_coef = c.has_temp_coef || s.has_temp;
    c.temp_coef_dps_per_degc[i] = s.temp.tc_dps_per_degc;
    c.temp_coef_sigma_dps_per_degc[i] = s.temp.tc_sigma_dps_per_degc;
  }
  // calibrated M hold the stops' true angles: a second set of stop errors would count them twice
  if (doc.has_end_stops && !c.matrices_nominal)
    ctx.fail(*root.find("end_stops"), "end_stops", "end_stops only with 'matrices: nominal' (a self-calibration): "
                                                   "calibrated matrices hold the stop angles already");
  c.has_end_stops = doc.has_end_stops;
  for (std::size_t p = 0; p < 2; ++p) {
    const StopPair& s = doc.end_stops.platform[p];
    const Eigen::Index o = 2 * static_cast<Eigen::Index>(p);
    c.end_stop_deg.segment<2>(o) << s.minus90_deg, s.plus90_deg;
    c.end_stop_sigma_deg.segment<2>(o) << s.minus90_sigma_deg, s.plus90_sigma_deg;
  }
  with_location(file, 0, "", [&] { c.M.validate(); });
  return c;
}

}  // namespace driftless::calib
