#include "estimator/accel_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Geometry>

#include "estimator/units.hpp"

namespace driftless::est {

const char* to_string(GravitySource s) {
  switch (s) {
    case GravitySource::kAccel: return "accel";
    case GravitySource::kRefQ: return "ref_q";
    case GravitySource::kNone: return "none";
  }
  return "?";
}

GravitySource gravity_source(std::uint32_t fields) {
  if ((fields & kFieldAccel) != 0) return GravitySource::kAccel;
  if ((fields & kFieldRefQ) != 0) return GravitySource::kRefQ;
  return GravitySource::kNone;
}

void gravity_from_ref_q(const DriftlessFilter& filter, Sample& s) {
  s.accel1_mps2.setConstant(kNaN);
  s.accel2_mps2.setConstant(kNaN);
  if (!s.ref_q_wxyz.allFinite() || !(s.ref_q_wxyz.norm() > 0.0)) return;
  const Eigen::Quaterniond q(s.ref_q_wxyz[0], s.ref_q_wxyz[1], s.ref_q_wxyz[2], s.ref_q_wxyz[3]);
  // the specific force of a box at rest points up: (0, 0, g) in ENU, C^T of it in box axes
  const Eigen::Vector3d f_box = q.normalized().toRotationMatrix().transpose() * Eigen::Vector3d(0.0, 0.0, kStandardGravityMps2);
  if (std::isfinite(s.plat1_deg)) s.accel1_mps2 = filter.body_from_sensor(1, s.plat1_deg).transpose() * f_box;
  if (std::isfinite(s.plat2_deg)) s.accel2_mps2 = filter.body_from_sensor(2, s.plat2_deg).transpose() * f_box;
}

AccelSensorReading classify_accel(double median_norm, std::uint64_t samples) {
  AccelSensorReading r;
  r.median_norm = median_norm;
  r.samples = samples;
  if (samples == 0 || !std::isfinite(median_norm)) return r;
  if (median_norm < kAccelEmptyFraction * kStandardGravityMps2) {
    r.reading = AccelReading::kEmpty;
    return r;
  }
  // gravity read in each acceleration unit of the one unit table: 9.81 in m/s^2, 1 in g, 1000 in mg
  const units::Unit* mps2 = units::find("mps2");
  r.reading = AccelReading::kOff;
  for (const units::Unit& u : units::table()) {
    if (u.quantity != units::Quantity::kAccel) continue;
    const double expected = kStandardGravityMps2 / u.to_base;
    if (!(std::fabs(median_norm / expected - 1.0) < kAccelUnitTolerance)) continue;
    if (&u == mps2) {
      r.reading = AccelReading::kOk;
    } else {
      r.reading = AccelReading::kOtherUnit;
      r.unit_suffix = u.suffix;
      r.factor = units::factor(u, *mps2);
    }
    break;
  }
  return r;
}

void AccelCheck::push(const Sample& s, bool at_rest) {
  if (!at_rest) return;
  const std::array<const Eigen::Vector3d*, 2> a{&s.accel1_mps2, &s.accel2_mps2};
  for (std::size_t i = 0; i < 2; ++i) {
    if (!a[i]->allFinite()) continue;
    ++n_[i];
    const double norm = a[i]->norm();
    const double bin = (std::log10(norm) - kLowestLog10) * kBinsPerDecade;
    if (!(bin >= 0.0)) {
      ++zeros_[i];
      continue;
    }
    ++bins_[i][static_cast<std::size_t>(std::min(bin, double(kBins - 1)))];
  }
}

AccelCheckResult AccelCheck::finish() const {
  AccelCheckResult out;
  for (std::size_t i = 0; i < 2; ++i) {
    if (n_[i] == 0) continue;
    const std::uint64_t half = (n_[i] + 1) / 2;  // the median sample, 1-based
    std::uint64_t seen = zeros_[i];
    double median = 0.0;
    for (std::size_t b = 0; seen < half && b < bins_[i].size(); ++b) {
      seen += bins_[i][b];
      if (seen >= half) median = std::pow(10.0, kLowestLog10 + (double(b) + 0.5) / kBinsPerDecade);
    }
    out[i] = classify_accel(median, n_[i]);
  }
  return out;
}

std::string gravity_from_ref_q_note(double accel_sigma_g, double speed_mps) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "gravity_source: ref_q: no accel columns, so the g-sensitivity states took gravity from ref_q at each "
                "standstill (M_i^T C^T (0, 0, g)); the box's own acceleration is unknown and entered R as %.3g g "
                "(1 sigma, ref_gravity_accel_sigma_g) plus the centripetal %.3g m/s (ref_gravity_speed_mps) times "
                "the fused turn rate. Logging accel1_*/accel2_* measures it",
                accel_sigma_g, speed_mps);
  return buf;
}

void add_accel_findings(HealthReport& h, const AccelCheckResult& r, bool self_calibration) {
  std::vector<HealthFinding> first;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const AccelSensorReading& a = r[i];
    if (a.reading != AccelReading::kOtherUnit && a.reading != AccelReading::kEmpty && a.reading != AccelReading::kOff) continue;
    HealthFinding f;
    f.cause = a.reading == AccelReading::kEmpty ? HealthCause::kAccelEmpty : HealthCause::kAccelUnit;
    f.severity = self_calibration ? HealthVerdict::kFailed : HealthVerdict::kDegraded;
    if (a.reading == AccelReading::kOff) f.severity = self_calibration ? HealthVerdict::kDegraded : HealthVerdict::kOk;
    f.value = a.median_norm;
    f.suggested = a.factor;
    f.count = a.samples;
    f.components = {static_cast<int>(i) + 1};
    first.push_back(std::move(f));
  }
  put_findings_first(h, std::move(first));
}

std::vector<UncertainElement> uncertain_calibration(const Calibration& cal) {
  std::vector<UncertainElement> out;
  const auto scan = [&out](int sensor, bool g, const Eigen::Matrix3d& v, const Eigen::Matrix3d& sd, double floor) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        if (sd(r, c) > floor && sd(r, c) > std::fabs(v(r, c)) / 3.0) out.push_back({sensor, g, r, c, v(r, c), sd(r, c)});
      }
    }
  };
  for (int i = 0; i < 2; ++i) {
    const std::size_t u = static_cast<std::size_t>(i);
    if (cal.has_g_sigma) scan(i + 1, true, cal.G_dps_per_g[u], cal.G_sigma_dps_per_g[u], kCalibGSigmaFloorDpsPerG);
    if (cal.has_scale_misalign) scan(i + 1, false, cal.E_frac[u], cal.E_sigma_frac[u], kCalibESigmaFloor);
  }
  return out;
}

void add_calib_finding(HealthReport& h, const Calibration& cal) {
  const std::vector<UncertainElement> el = uncertain_calibration(cal);
  if (el.empty()) return;
  HealthFinding f;
  f.cause = HealthCause::kCalibUncertain;
  f.value = 18.0 * ((cal.has_g_sigma ? 1.0 : 0.0) + (cal.has_scale_misalign ? 1.0 : 0.0));
  f.count = el.size();
  for (const UncertainElement& e : el) {
    f.components.push_back(e.sensor * 100 + (e.g ? 0 : 10) + 3 * e.row + e.col);
    f.positions_deg.push_back({e.value, e.sigma});
  }
  put_findings_first(h, {std::move(f)});
}

}  // namespace driftless::est
