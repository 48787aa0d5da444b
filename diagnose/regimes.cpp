// Where the model fails: the residual after the selection by regime, by window, and its
// correlation with the inputs (docs/compare.md section 4).
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>

#include <fmt/core.h>

#include "diagnose/summary.hpp"
#include "estimator/sample.hpp"

namespace driftless::diagnose {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using Selector = std::function<bool(std::size_t)>;

// a regime's rows: the residual over its usable samples, and how many of them the fits use (the
// flips and the samples around them are left out of the fits: their rows say so)
void add_regime(const Residual& res, const AfterFit& a, const std::string& group, const std::string& name,
                const Selector& sel, CompareResult& out) {
  const Replay& r = *res.replay;
  RegimeSummary rs;
  rs.group = group;
  rs.name = name;
  std::array<double, 6> s1{}, s2{};
  const int nc = 3 * r.sensors;  // channels with data
  for (std::size_t k = 0; k < r.size(); ++k) {
    if (!r.usable[k] || !sel(k)) continue;
    std::array<float, 6> e{};
    bool ok = true;
    for (int c = 0; c < nc; ++c) e[c] = a.e(c, k), ok = ok && std::isfinite(e[c]);
    if (!ok) continue;
    ++rs.samples;
    rs.samples_in_fit += res.mask[k];
    for (int c = 0; c < nc; ++c) s1[c] += e[c], s2[c] += static_cast<double>(e[c]) * e[c];
  }
  if (rs.samples == 0) return;
  rs.mean_dps.fill(kNaN);
  rs.rms_dps.fill(kNaN);
  for (int c = 0; c < nc; ++c) {
    rs.mean_dps[c] = s1[c] / static_cast<double>(rs.samples);
    rs.rms_dps[c] = std::sqrt(s2[c] / static_cast<double>(rs.samples));
  }
  out.regimes.push_back(rs);
}

// bands [edges[i], edges[i+1]) of a per-sample value, outside flips
void add_bands(const Residual& res, const AfterFit& a, const std::string& group, const std::vector<double>& edges,
               const char* unit, const std::function<double(std::size_t)>& value, CompareResult& out) {
  const Replay& r = *res.replay;
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    const double lo = edges[i], hi = edges[i + 1];
    const std::string name = std::isinf(hi) ? fmt::format(">= {:g} {}", lo, unit) : fmt::format("{:g}-{:g} {}", lo, hi, unit);
    add_regime(res, a, group, name, [&, lo, hi](std::size_t k) {
      const double v = value(k);
      return !r.flipping[k] && v >= lo && v < hi;
    }, out);
  }
}

void temperature_quartiles(const Replay& r, const Residual& res, const AfterFit& a, CompareResult& out) {
  if (!r.has_temp || res.temp_span_c < 0.2) return;
  std::vector<double> t;
  for (std::size_t k = 0; k < r.size(); k += 7)
    if (std::isfinite(r.temp_c[0][k])) t.push_back(r.temp_c[0][k]);
  std::sort(t.begin(), t.end());
  if (t.size() <= 8) return;
  std::vector<double> edges{-kInf};
  for (std::size_t q = 1; q < 4; ++q) edges.push_back(t[t.size() * q / 4]);
  edges.push_back(kInf);
  for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
    const double lo = edges[i], hi = edges[i + 1];
    add_regime(res, a, "temperature",
               fmt::format("temp1 {}..{} degC", std::isinf(lo) ? std::string("min") : fmt::format("{:.2f}", lo),
                           std::isinf(hi) ? std::string("max") : fmt::format("{:.2f}", hi)),
               [&, lo, hi](std::size_t k) { return !r.flipping[k] && r.temp_c[0][k] >= lo && r.temp_c[0][k] < hi; }, out);
  }
}

void regimes(const Replay& r, const Residual& res, const AfterFit& a, CompareResult& out) {
  for (int p1 : {1, -1})
    for (int p2 : {1, -1})
      add_regime(res, a, "standstill", fmt::format("plat1 {}, plat2 {}", p1 > 0 ? "+" : "-", p2 > 0 ? "+" : "-"),
                 [&, p1, p2](std::size_t k) { return !r.flipping[k] && r.rest_side[0][k] == p1 && r.rest_side[1][k] == p2; },
                 out);
  add_regime(res, a, "flip", "during flips", [&](std::size_t k) { return r.flipping[k] != 0; }, out);
  add_regime(res, a, "flip", "0-2 s after a flip", [&](std::size_t k) {
    return !r.flipping[k] && (r.since_flip_s[0][k] < 2.0f || r.since_flip_s[1][k] < 2.0f);
  }, out);
  const double we = kEarthRateRadps * kDegPerRad;
  add_bands(res, a, "base rate", {0.0, 1.0, 10.0, 30.0, kInf}, "deg/s",
            [&](std::size_t k) { return std::max(0.0, r.w_body_radps[k].norm() * kDegPerRad - we); }, out);
  add_bands(res, a, "acceleration", {0.0, 0.5, 2.0, kInf}, "m/s^2",
            [&](std::size_t k) { return std::abs(static_cast<double>(r.f_body_mps2[k].norm()) - kStandardGravityMps2); }, out);
  temperature_quartiles(r, res, a, out);
}

void windows(const Replay& r, const Residual& res, const AfterFit& a, const CompareOptions& opt, CompareResult& out) {
  const double ws = opt.window_s > 0 ? opt.window_s : std::clamp(out.duration_s / 30.0, 10.0, 300.0);
  std::size_t k = 0;
  while (k < res.n) {
    WindowSummary w;
    w.t0_s = r.t_s[k];
    std::array<double, 6> s2{};
    std::size_t cnt = 0;
    for (; k < res.n && r.t_s[k] < w.t0_s + ws; ++k) {
      if (!res.mask[k]) continue;
      std::array<float, 6> e{};
      bool ok = true;
      for (int c = 0; c < res.channels(); ++c) e[c] = a.e(c, k), ok = ok && std::isfinite(e[c]);
      if (!ok) continue;
      for (int c = 0; c < res.channels(); ++c) s2[c] += static_cast<double>(e[c]) * e[c];
      ++cnt;
    }
    w.t1_s = k < res.n ? r.t_s[k] : r.t_s.back();
    if (cnt < 10) continue;
    w.rms_dps.fill(kNaN);
    for (int c = 0; c < res.channels(); ++c) {
      w.rms_dps[c] = std::sqrt(s2[c] / static_cast<double>(cnt));
      const double ratio = w.rms_dps[c] / std::max(1e-9, out.channels[c].noise_floor_dps);
      if (ratio > w.worst_ratio) w.worst_ratio = ratio, w.worst_channel = c;
    }
    out.windows.push_back(w);
  }
  out.worst_windows = out.windows;
  auto by_ratio = [](const WindowSummary& x, const WindowSummary& y) { return x.worst_ratio > y.worst_ratio; };
  std::sort(out.worst_windows.begin(), out.worst_windows.end(), by_ratio);
  if (out.worst_windows.size() > static_cast<std::size_t>(opt.worst_windows))
    out.worst_windows.resize(static_cast<std::size_t>(opt.worst_windows));
  std::sort(out.worst_windows.begin(), out.worst_windows.end(),
            [](const WindowSummary& x, const WindowSummary& y) { return x.t0_s < y.t0_s; });
}

void correlations(const Replay& r, const Residual& res, const Channels& ch, const AfterFit& a,
                  const CompareOptions& opt, CompareResult& out) {
  std::vector<std::pair<std::string, std::function<double(std::size_t)>>> sigs;
  for (int ax = 0; ax < 3; ++ax) {
    sigs.emplace_back(fmt::format("body rate {}", axis_letter(ax)), [&, ax](std::size_t k) { return r.w_body_radps[k][ax]; });
    sigs.emplace_back(fmt::format("|body rate {}|", axis_letter(ax)), [&, ax](std::size_t k) { return std::abs(r.w_body_radps[k][ax]); });
    sigs.emplace_back(fmt::format("specific force {}", axis_letter(ax)), [&, ax](std::size_t k) { return static_cast<double>(r.f_body_mps2[k][ax]); });
  }
  sigs.emplace_back("time", [&](std::size_t k) { return r.t_s[k]; });
  for (int s = 0; s < res.sensors; ++s) {
    sigs.emplace_back(fmt::format("temperature {}", s + 1), [&, s](std::size_t k) { return res.temp_c(s, k); });
    sigs.emplace_back(fmt::format("time since flip {}", s + 1), [&, s](std::size_t k) { return std::min(10.0f, r.since_flip_s[s][k]); });
  }
  // the block means of every signal as columns; per channel the whitened Gram of [signals,
  // residual] holds every sum the correlations need (sxx, sxy on its last column, syy)
  const auto S = static_cast<Eigen::Index>(sigs.size());
  Eigen::MatrixXd X(static_cast<Eigen::Index>(res.blocks), S);
  std::vector<double> sb;
  for (Eigen::Index i = 0; i < S; ++i) {
    block_means_of(res, sigs[static_cast<std::size_t>(i)].second, sb);
    X.col(i) = Eigen::Map<const Eigen::VectorXd>(sb.data(), static_cast<Eigen::Index>(sb.size()));
  }
  std::array<Eigen::MatrixXd, 6> gram;
  for (int c = 0; c < res.channels(); ++c) {
    std::vector<double> z = a.z[c];
    for (double& v : z) v = std::isfinite(v) ? v : 0.0;
    gram[static_cast<std::size_t>(c)] = BiasWhitener::whitened_gram(res.block_series, ch[c].noise, X, z).gram;
  }
  for (Eigen::Index i = 0; i < S; ++i) {
    for (int c = 0; c < res.channels(); ++c) {
      const Eigen::MatrixXd& g = gram[static_cast<std::size_t>(c)];
      const double sxy = g(i, S), sxx = g(i, i), syy = g(S, S);
      if (sxx <= 1e-300 || syy <= 0) continue;
      const double rho = sxy / std::sqrt(sxx * syy);
      const double z = rho * std::sqrt(static_cast<double>(ch[c].m));
      // significant and material: a long log makes a negligible correlation significant
      if (std::abs(z) > opt.correlation_z && rho * rho >= opt.min_effect_fraction) {
        out.correlations.push_back({sigs[static_cast<std::size_t>(i)].first, c, rho, z});
      }
    }
  }
  std::sort(out.correlations.begin(), out.correlations.end(),
            [](const Correlation& x, const Correlation& y) { return std::abs(x.z) > std::abs(y.z); });
}

}  // namespace

void summarise_regimes(const Replay& r, const Residual& res, const Channels& ch, const AfterFit& after,
                       const CompareOptions& opt, CompareResult& out) {
  regimes(r, res, after, out);
  windows(r, res, after, opt, out);
  correlations(r, res, ch, after, opt, out);
}

}  // namespace driftless::diagnose
