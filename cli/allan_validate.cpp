// `driftless allan --validate N`: N records of the same length and rate simulated from each fit with
// the twin's sensor model (twin/sensor, the one effect catalogue), their 95 % band at every octave
// tau against the measured curve, and the first tau where the model fails (docs/allan.md).
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/core.h>

#include "cli/allan_result.hpp"
#include "estimator/sample.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::cli::allan {
namespace {

// the peak of a Gauss-Markov Allan deviation per unit sigma, and where it lies (tau / T)
std::pair<double, double> gm_peak() {
  est::NoiseModel m;
  m.coef[static_cast<int>(est::NoiseTerm::kGaussMarkov)] = 1.0;
  m.gm_tau_s = 1.0;
  double best = 0.0, at = 1.0;
  for (double x = 0.5; x < 5.0; x *= 1.001) {
    const double v = std::sqrt(m.avar(x));
    if (v > best) best = v, at = x;
  }
  return {best, at};
}

// one axis of the catalogue from a fit; notes say what the catalogue cannot represent
void set_axis(twin::SensorParams& p, int ax, const est::NoiseFit& f, std::vector<std::string>& notes) {
  if (f.N.valid) p.white_noise.density_dps_rthz[ax] = f.N.value;
  if (f.K.valid) p.rate_random_walk.k_dps_rts[ax] = f.K.value;
  if (f.preferred == est::BiasModel::kGaussMarkov && f.gm_sigma.valid && std::isfinite(f.gm_tau.value)) {
    p.bias_instability.sigma_dps[ax] = f.gm_sigma.value;
    p.bias_instability.tau_s[ax] = f.gm_tau.value;
  } else if (f.B.valid && f.B_min.valid) {
    // no flicker process in the catalogue: one Gauss-Markov process with the same floor, peaking there
    const auto [peak, x] = gm_peak();
    p.bias_instability.sigma_dps[ax] = est::kFlickerFloorFactor * f.B.value / peak;
    p.bias_instability.tau_s[ax] = f.B_min.tau_s / x;
    notes.push_back("flicker B simulated as one Gauss-Markov process with the same floor (the catalogue has no flicker)");
  }
  if (f.Q.valid) notes.push_back("Q (angle quantisation) not simulated: not in the catalogue");
  if (f.R.valid) notes.push_back("R (rate ramp) not simulated: not in the catalogue");
}

// the sensor model's continuous low-pass as a pure first-order pole of time constant `tau_s`: the
// bandwidth 1/(2 pi tau) and, as group delay, the pole's own (no added sample delay)
void set_lowpass(twin::SensorParams& p, double tau_s, double rate_hz) {
  const double pole = std::exp(-1.0 / (tau_s * rate_hz));
  p.lowpass_latency.enabled = true;
  p.lowpass_latency.bandwidth_hz = 1.0 / (2.0 * 3.14159265358979323846 * tau_s);
  p.lowpass_latency.delay_s = pole / (1.0 - pole) / rate_hz;
}

twin::SensorParams params_for(const std::array<const ChannelResult*, 3>& axes, double rate_hz, std::vector<std::string>& notes) {
  twin::SensorParams p = twin::ideal_sensor();
  p.white_noise.enabled = p.rate_random_walk.enabled = p.bias_instability.enabled = true;
  double tf = 0.0;
  for (int ax = 0; ax < 3; ++ax) {
    if (axes[ax] == nullptr) continue;
    set_axis(p, ax, axes[ax]->fit, notes);
    tf = std::max(tf, axes[ax]->fit.white_lowpass_tau_s);
  }
  if (tf > 0.0) {
    set_lowpass(p, tf, rate_hz);
    notes.push_back(fmt::format("white-noise low-pass simulated as a first-order low-pass of {:.3g} ms ({:.3g} Hz)", 1e3 * tf,
                                p.lowpass_latency.bandwidth_hz));
  }
  return p;
}

Validation band_and_verdict(const est::AllanCurve& measured, std::vector<std::vector<double>>& sims, std::size_t records) {
  Validation v;
  v.records = records;
  for (std::size_t i = 0; i < measured.points.size(); ++i) {
    std::vector<double>& s = sims[i];
    if (s.size() < 2) continue;
    std::sort(s.begin(), s.end());
    auto q = [&](double p) { return s[static_cast<std::size_t>(std::clamp(p * (s.size() - 1) + 0.5, 0.0, s.size() - 1.0))]; };
    const auto& m = measured.points[i];
    v.tau_s.push_back(m.tau_s), v.lo95.push_back(q(0.025)), v.hi95.push_back(q(0.975));
    if (v.fails_at_tau_s == 0.0 && (m.adev < v.lo95.back() || m.adev > v.hi95.back())) {
      v.fails_at_tau_s = m.tau_s;
      v.verdict = fmt::format("the model fails from tau = {:.4g} s: the measured deviation {:.3e} is {} the 95 % band "
                              "[{:.3e}, {:.3e}] of {} simulated records",
                              m.tau_s, m.adev, m.adev > v.hi95.back() ? "above" : "below", v.lo95.back(), v.hi95.back(), records);
    }
  }
  if (v.fails_at_tau_s == 0.0 && !v.tau_s.empty()) {
    v.verdict = fmt::format("the model holds at every tau ({:.3g} to {:.3g} s) within the 95 % band of {} simulated records",
                            v.tau_s.front(), v.tau_s.back(), records);
  }
  return v;
}

// simulates the triad `axes` (nullptr: unused axis) `records` times and attaches each band
void validate_group(const Result& r, std::array<ChannelResult*, 3> axes, std::size_t records, std::uint64_t seed) {
  std::vector<std::string> notes;
  const twin::SensorParams p = params_for({axes[0], axes[1], axes[2]}, r.rate_hz, notes);
  std::array<std::vector<std::vector<double>>, 3> sims;
  std::size_t n = 0;
  for (const auto* c : axes) n = std::max(n, c != nullptr ? c->fit_curve.samples : 0);
  for (int ax = 0; ax < 3; ++ax) {
    if (axes[ax] != nullptr) sims[ax].resize(axes[ax]->fit_curve.points.size());
  }
  std::array<std::vector<double>, 3> x;
  for (auto& v : x) v.resize(n);
  for (std::size_t rec = 0; rec < records; ++rec) {
    twin::SensorModel model(p, r.rate_hz, twin::derive_seed(seed, 7000 + rec));
    for (std::size_t k = 0; k < n; ++k) {
      const auto y = model.step(twin::SensorTruth{static_cast<double>(k) / r.rate_hz, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
      for (int ax = 0; ax < 3; ++ax) x[ax][k] = y.gyro_radps[ax] / driftless::kRadPerDeg;
    }
    for (int ax = 0; ax < 3; ++ax) {
      if (axes[ax] == nullptr) continue;
      est::AllanOptions o;
      o.sample_rate_hz = r.rate_hz;
      const auto c = est::allan_deviation(std::span<const double>(x[ax].data(), axes[ax]->fit_curve.samples), o);
      for (std::size_t i = 0; i < c.points.size() && i < sims[ax].size(); ++i) sims[ax][i].push_back(c.points[i].adev);
    }
  }
  std::sort(notes.begin(), notes.end());
  notes.erase(std::unique(notes.begin(), notes.end()), notes.end());
  for (int ax = 0; ax < 3; ++ax) {
    if (axes[ax] == nullptr) continue;
    Validation v = band_and_verdict(axes[ax]->fit_curve, sims[ax], records);
    v.notes = notes;
    axes[ax]->validation = std::move(v);
  }
}

}  // namespace

void validate_round_trip(Result& r, std::size_t records, std::uint64_t seed) {
  // rate channels in triads of x, y, z (one simulated sensor each); the rest one by one on axis x
  std::vector<bool> done(r.channels.size(), false);
  for (std::size_t i = 0; i < r.channels.size(); ++i) {
    if (done[i] || r.channels[i].quantity != importers::Quantity::kRate) continue;
    std::array<ChannelResult*, 3> axes{nullptr, nullptr, nullptr};
    for (std::size_t j = i; j < r.channels.size(); ++j) {
      auto& c = r.channels[j];
      const bool same_triad = c.quantity == importers::Quantity::kRate && c.axis >= 0 && r.channels[i].axis >= 0;
      if (!done[j] && (j == i || same_triad) && axes[std::max(0, c.axis)] == nullptr) {
        axes[std::max(0, c.axis)] = &c;
        done[j] = true;
      }
      if (r.channels[i].axis < 0) break;
    }
    validate_group(r, axes, records, seed + i);
  }
  for (auto& c : r.channels) {
    if (c.quantity == importers::Quantity::kAccel) {
      c.validation = Validation{{}, {}, {}, 0, 0.0, "not validated: the catalogue's accelerometer has white noise only", {}};
    }
  }
}

}  // namespace driftless::cli::allan
