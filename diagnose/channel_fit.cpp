#include "diagnose/channel_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "diagnose/parallel.hpp"

namespace driftless::diagnose {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double median_abs(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
  return std::abs(*mid);
}

// the nuisance-reduced quadratic of one channel over columns xs (positions in cols):
// objective(beta_x) = J - 2 s' beta_x + beta_x' S beta_x, the nuisance (prior > 0, not in xs)
// at its MAP given beta_x; in units of the channel's whitened residual variance
struct Partial {
  Eigen::MatrixXd S;
  Eigen::VectorXd s;
  double J = 0.0;
};

// the nuisance columns given the held ones: every column with a prior that is not held, and a
// held column whose value is given (not fitted) keeps its prior about that value (the held value
// plus a nuisance on the same column: a signal chain's second-order term is held where its
// delays put it, and the filter's shape, which the model does not know, spreads it)
std::vector<int> nuisance_of(const ChannelData& c, const std::vector<int>& held, const std::vector<int>& given) {
  std::vector<int> N;
  for (int i = 0; i < static_cast<int>(c.cols.size()); ++i) {
    const bool is_held = std::find(held.begin(), held.end(), i) != held.end();
    const bool is_given = std::find(given.begin(), given.end(), i) != given.end();
    if (c.prior[i] > 0 && (!is_held || is_given)) N.push_back(i);
  }
  return N;
}

Partial partial_out(const ChannelData& c, const std::vector<int>& xs, const std::vector<int>& given = {}) {
  const int P = static_cast<int>(c.cols.size());
  const int yi = P;
  const std::vector<int> N = nuisance_of(c, xs, given);
  const int n = static_cast<int>(N.size()), p = static_cast<int>(xs.size());
  Eigen::MatrixXd C(p + 1, p + 1);
  for (int q = 0; q < p; ++q) {
    for (int r = 0; r < p; ++r) C(q, r) = c.gram(xs[q], xs[r]);
    C(q, p) = C(p, q) = c.gram(xs[q], yi);
  }
  C(p, p) = c.gram(yi, yi);
  if (n > 0) {
    Eigen::MatrixXd A(n, n), B(n, p + 1);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) A(a, b) = c.gram(N[a], N[b]);
      A(a, a) += c.sigma2 / (c.prior[N[a]] * c.prior[N[a]]);  // prior precision, whitened units
      for (int q = 0; q < p; ++q) B(a, q) = c.gram(N[a], xs[q]);
      B(a, p) = c.gram(N[a], yi);
    }
    C -= B.transpose() * A.ldlt().solve(B);
  }
  return {C.topLeftCorner(p, p) / c.sigma2, C.col(p).head(p) / c.sigma2, C(p, p) / c.sigma2};
}

// pseudo-inverse of a symmetric positive semi-definite matrix and its rank. What is identified
// is decided on H scaled to unit diagonal (D H D, D = diag(H)^-1/2): eigenvalues below 1e-9 of
// the largest there are collinear directions. Unscaled, the test compared parameters in their
// own units: a delay's curvature per s^2 is ~1e9 times a scale's per %^2, so a scale fitted
// beside a free sample delay was "not identified" and never selected (a 3 % scale on a wobble
// with one sensor late went to the temperature coefficient it resembles)
struct PseudoInverse {
  Eigen::MatrixXd inv;
  int rank = 0;
};
PseudoInverse pseudo_inverse(const Eigen::MatrixXd& H) {
  const int p = static_cast<int>(H.rows());
  PseudoInverse out;
  out.inv = Eigen::MatrixXd::Zero(p, p);
  if (p == 0) return out;
  // a parameter the data barely touch stays unidentified: curvature below 1e-12 per unit^2 (a
  // sigma above 1e6 file units; its column's variation is the float block means' rounding)
  Eigen::VectorXd d(p);
  for (int i = 0; i < p; ++i) d[i] = H(i, i) > 1e-12 ? 1.0 / std::sqrt(H(i, i)) : 0.0;
  const Eigen::MatrixXd Hs = d.asDiagonal() * H * d.asDiagonal();
  // a well-conditioned Hs (the usual case: every free parameter identified) by Cholesky, a tenth
  // of an eigendecomposition's cost; its reciprocal condition estimate (1-norm, an upper bound
  // that is rarely 10x off) far above the 1e-9 cut-off below means full rank there too
  const Eigen::LLT<Eigen::MatrixXd> llt(Hs);
  if ((d.array() > 0.0).all() && llt.info() == Eigen::Success && llt.rcond() > 1e-6) {
    out.inv = d.asDiagonal() * llt.solve(Eigen::MatrixXd::Identity(p, p)) * d.asDiagonal();
    out.rank = p;
    return out;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Hs);
  const double top = std::max(es.eigenvalues().maxCoeff(), 1e-300);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(p);
  for (int i = 0; i < p; ++i) {
    if (es.eigenvalues()[i] > 1e-9 * top && es.eigenvalues()[i] > 1e-12) {
      e[i] = 1.0 / es.eigenvalues()[i];
      ++out.rank;
    }
  }
  out.inv = d.asDiagonal() * (es.eigenvectors() * e.asDiagonal() * es.eigenvectors().transpose()) * d.asDiagonal();
  return out;
}

// the columns of channel `channel` a spec drives: positions in cols, and per position the
// free-parameter indices and the fixed contribution
struct ChannelUse {
  std::vector<int> pos;                       // distinct positions in cols
  std::vector<std::vector<int>> free_of_pos;  // free parameter indices per position
  Eigen::VectorXd fixed;                      // summed fixed values per position
  std::vector<int> given;                     // positions held at given values only (no free parameter)
};
ChannelUse channel_use(const ChannelData& c, int channel, const FitSpec& spec) {
  ChannelUse u;
  auto slot = [&](int col) {
    const int i = c.index(col);
    if (i < 0) return -1;
    auto it = std::find(u.pos.begin(), u.pos.end(), i);
    if (it != u.pos.end()) return static_cast<int>(it - u.pos.begin());
    u.pos.push_back(i);
    u.free_of_pos.emplace_back();
    return static_cast<int>(u.pos.size()) - 1;
  };
  std::vector<std::pair<int, double>> fixed_at;
  for (std::size_t f = 0; f < spec.free.size(); ++f) {
    for (const ColumnUse& cu : columns_of(spec.free[f])) {
      if (cu.channel != channel) continue;
      const int q = slot(cu.col);
      if (q >= 0) u.free_of_pos[static_cast<std::size_t>(q)].push_back(static_cast<int>(f));
    }
  }
  for (const auto& [ref, v] : spec.fixed) {
    for (const ColumnUse& cu : columns_of(ref)) {
      if (cu.channel != channel) continue;
      const int q = slot(cu.col);
      if (q >= 0) fixed_at.emplace_back(q, v);
    }
  }
  u.fixed = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(u.pos.size()));
  for (const auto& [q, v] : fixed_at) u.fixed[q] += v;
  for (std::size_t q = 0; q < u.pos.size(); ++q)
    if (u.free_of_pos[q].empty()) u.given.push_back(u.pos[q]);
  return u;
}

}  // namespace

double fit_white_density(const ChannelData& c, const BlockSeries& blocks, std::span<const double> z) {
  std::vector<double> d;
  for (std::size_t b = 1; b < z.size(); ++b) {
    if (blocks.count[b] && blocks.count[b - 1]) d.push_back(z[b] - z[b - 1]);
  }
  std::size_t L = 1;
  for (auto cnt : blocks.count) L = std::max<std::size_t>(L, cnt);
  const double n0 = std::max(1e-7, 1.4826 * median_abs(d) / std::sqrt(2.0) *
                                       std::sqrt(static_cast<double>(L) / blocks.sample_rate_hz));
  auto f = [&](double logN) {
    ChannelNoise nz = c.noise;
    nz.white_dps_rthz = std::exp(logN);
    return BiasWhitener::neg2_loglik(blocks, nz, z);
  };
  // the maximum likelihood over N, not over a bracket: the robust guess is from the block
  // differences' median, which structure the selection has not yet taken out leaves far below
  // the likelihood's N (a wobble's channel fitted at the bracket's edge ran its selection with a
  // variance unit of 4 664); an optimum on an edge moves the bracket on, 4 in ln N at a time
  double lo = std::log(n0) - 2.0, hi = std::log(n0) + 2.0, x = brent_min(f, lo, hi, std::log(n0), 1e-6);
  for (int shift = 0; shift < 6; ++shift) {
    const double edge_tol = 1e-4;
    if (x > hi - edge_tol) lo = hi - 0.5, hi += 4.0;
    else if (x < lo + edge_tol) hi = lo + 0.5, lo -= 4.0;
    else break;
    x = brent_min(f, lo, hi, x, 1e-6);
  }
  return std::exp(x);
}

// whitened Gram of [cols..., z] and the null (nuisance-only) fit's variance and objective
void rebuild_gram(ChannelData& c, const BlockSeries& blocks) {
  WhitenedGram g = BiasWhitener::whitened_gram(blocks, c.noise, c.block_cols, c.z);
  c.m = g.used;
  c.gram = std::move(g.gram);
  c.sigma2 = 1.0;
  const double j = partial_out(c, {}).J;
  c.sigma2 = std::max(1e-6, j / static_cast<double>(std::max<std::size_t>(c.m, 1)));
  c.j0 = partial_out(c, {}).J;
}

void set_variance(ChannelData& c, const Eigen::VectorXd& coef) {
  if (!c.present) return;
  const auto P = static_cast<Eigen::Index>(c.cols.size());
  Eigen::VectorXd v(P + 1);
  v.head(P) = coef;
  v[P] = -1.0;
  const double rss = v.dot(c.gram * v);  // whitened residual sum of squares
  c.sigma2 = std::max(1e-6, rss / static_cast<double>(std::max<std::size_t>(c.m, 1)));
  c.j0 = partial_out(c, {}).J;
}

namespace {

// block means of every excited column of channel (s, j): all columns in one sweep over the
// samples (each column's sums in the same order as block_means_of), kept as float in place and
// the unexcited ones dropped (a double copy per column was 7 MB per worker on a 1 h log)
void fill_columns(const ColumnInputs& in, const Residual& res, ChannelData& c) {
  const std::size_t mb = res.blocks;
  std::vector<int> tried;
  for (int col = 0; col < kNumCols; ++col)
    if (!((col == kTempBias || col == kTempScale) && res.temp_span_c < 0.2)) tried.push_back(col);
  const std::size_t nc = tried.size();
  Eigen::MatrixXf means(static_cast<Eigen::Index>(mb), static_cast<Eigen::Index>(nc));
  std::vector<double> acc(nc), ss(nc, 0.0);
  std::vector<int> cnt(nc);
  ColumnSweep sweep(in, c.s, c.j);
  for (std::size_t b = 0; b < mb; ++b) {
    std::fill(acc.begin(), acc.end(), 0.0);
    std::fill(cnt.begin(), cnt.end(), 0);
    const std::size_t a = b * res.block_len, e = std::min(res.n, a + res.block_len);
    for (std::size_t k = a; k < e; ++k) {
      if (!res.bmask[k]) continue;
      for (std::size_t i = 0; i < nc; ++i) {
        const double v = sweep.value(tried[i], k);
        if (std::isfinite(v)) acc[i] += v, ++cnt[i];
      }
    }
    for (std::size_t i = 0; i < nc; ++i) {
      const double m = cnt[i] > 0 ? acc[i] / cnt[i] : 0.0;
      means(static_cast<Eigen::Index>(b), static_cast<Eigen::Index>(i)) = static_cast<float>(m);
      if (res.block_series.count[b]) ss[i] += m * m;
    }
  }
  Eigen::Index kept = 0;
  for (std::size_t i = 0; i < nc; ++i) {
    if (ss[i] < 1e-20) continue;  // not excited by this log
    const int col = tried[i];
    c.cols.push_back(col);
    c.prior.push_back(prior_sigma(in.params[c.s], c.j, col, res.fs_hz));
    // a latitude the log does not state: the Earth rate is a nuisance (kEarth is only excited then)
    if (in.r.latitude_assumed && col == kLat) c.prior.back() = kAssumedLatitudeSigmaDeg;
    if (col == kEarth) c.prior.back() = kAssumedEarthScaleSigma;
    if (kept != static_cast<Eigen::Index>(i)) means.col(kept) = means.col(static_cast<Eigen::Index>(i));
    ++kept;
  }
  means.conservativeResize(Eigen::NoChange, kept);
  c.block_cols = std::move(means);
}

}  // namespace

int ChannelData::index(int col) const {
  auto it = std::find(cols.begin(), cols.end(), col);
  return it == cols.end() ? -1 : static_cast<int>(it - cols.begin());
}

double golden_min(const std::function<double(double)>& f, double lo, double hi, int iters) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = lo, b = hi;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1), f2 = f(x2);
  for (int i = 0; i < iters; ++i) {
    if (f1 < f2) {
      b = x2; x2 = x1; f2 = f1; x1 = b - g * (b - a); f1 = f(x1);
    } else {
      a = x1; x1 = x2; f1 = f2; x2 = a + g * (b - a); f2 = f(x2);
    }
  }
  return 0.5 * (a + b);
}

// Brent's method (golden section with parabolic steps, R. Brent 1973, ch. 5) from a first
// guess: the likelihood in log N is smooth and the robust guess close, so it needs about half
// of golden_min's evaluations for the same precision
double brent_min(const std::function<double(double)>& f, double lo, double hi, double x0, double tol) {
  const double cgold = 0.5 * (3.0 - std::sqrt(5.0));
  double a = lo, b = hi, x = std::clamp(x0, lo, hi), w = x, v = x;
  double fx = f(x), fw = fx, fv = fx, d = 0.0, e = 0.0;
  for (int it = 0; it < 100; ++it) {
    const double m = 0.5 * (a + b), tol1 = tol + 1e-10 * std::abs(x), tol2 = 2.0 * tol1;
    if (std::abs(x - m) <= tol2 - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol1) {  // try a parabola through x, w, v
      const double r = (x - w) * (fx - fv), q0 = (x - v) * (fx - fw);
      double p = (x - v) * q0 - (x - w) * r, q = 2.0 * (q0 - r);
      if (q > 0.0) p = -p;
      q = std::abs(q);
      if (std::abs(p) < std::abs(0.5 * q * e) && p > q * (a - x) && p < q * (b - x)) {
        e = d;
        d = p / q;
        const double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = x < m ? tol1 : -tol1;
        golden = false;
      }
    }
    if (golden) {
      e = (x < m ? b : a) - x;
      d = cgold * e;
    }
    const double u = std::abs(d) >= tol1 ? x + d : x + (d > 0 ? tol1 : -tol1);
    const double fu = f(u);
    if (fu <= fx) {
      (u < x ? b : a) = x;
      v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w, fv = fw, w = u, fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u, fv = fu;
      }
    }
  }
  return x;
}

Channels build_channels(const ColumnInputs& in, const Residual& res) {
  Channels ch;
  for_each_index(6, [&](int c) {
    ChannelData& C = ch[static_cast<std::size_t>(c)];
    C.s = c / 3;
    C.j = c % 3;
    const twin::SensorParams& p = in.params[C.s];
    if (c >= res.channels()) {  // an absent channel: no columns, no data, no objective
      C.present = false;
      C.z.assign(res.blocks, 0.0);
      C.block_cols.resize(static_cast<Eigen::Index>(res.blocks), 0);
      C.gram = Eigen::MatrixXd::Zero(1, 1);
      return;
    }
    block_means_of(res, [&](std::size_t k) { return res.e_dps(c, k); }, C.z);
    fill_columns(in, res, C);
    // noise model: the model's bias processes; the white density is a nuisance, fitted
    C.noise.white_dps_rthz = p.white_noise.enabled ? std::max(1e-6, p.white_noise.density_dps_rthz[C.j]) : 1e-6;
    C.noise.gm_sigma_dps = p.bias_instability.enabled ? p.bias_instability.sigma_dps[C.j] : 0.0;
    C.noise.gm_tau_s = p.bias_instability.tau_s[C.j];
    C.noise.rrw_dps_rts = p.rate_random_walk.enabled ? p.rate_random_walk.k_dps_rts[C.j] : 0.0;
    C.noise.turn_on_sigma_dps = 1e3;
    refit_white(C, res.block_series, C.z);
    // again without the nuisance structure
    refit_white(C, res.block_series, block_residual(C, channel_coefficients(C, c, FitSpec{}, FitResult{})));
  });
  return ch;
}

double refit_white(ChannelData& c, const BlockSeries& blocks, std::span<const double> z) {
  const double before = c.noise.white_dps_rthz;
  c.noise.white_dps_rthz = fit_white_density(c, blocks, z);
  rebuild_gram(c, blocks);
  return std::abs(c.noise.white_dps_rthz / before - 1.0);
}

double log_blocks(const Channels& ch) {
  double m = 0.0;
  int present = 0;
  for (const auto& c : ch) m += static_cast<double>(c.m), present += c.present;
  return std::log(std::max(2.0, m / std::max(1, present)));
}

FitResult map_fit(const Channels& ch, const FitSpec& spec) {
  const auto P = static_cast<Eigen::Index>(spec.free.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(P, P);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(P);
  double cst = 0.0, j_null = 0.0;
  for (int c = 0; c < 6; ++c) {
    const ChannelUse u = channel_use(ch[c], c, spec);
    if (u.pos.empty()) continue;
    const Partial pt = partial_out(ch[c], u.pos, u.given);
    const auto q = static_cast<Eigen::Index>(u.pos.size());
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(q, P);
    for (Eigen::Index i = 0; i < q; ++i)
      for (int f : u.free_of_pos[static_cast<std::size_t>(i)]) A(i, f) += 1.0;
    H += A.transpose() * pt.S * A;
    g += A.transpose() * (pt.s - pt.S * u.fixed);
    cst += pt.J - 2.0 * pt.s.dot(u.fixed) + u.fixed.dot(pt.S * u.fixed);
    j_null += ch[c].j0;
  }
  const PseudoInverse pi = pseudo_inverse(H);
  FitResult out;
  out.value = pi.inv * g;
  out.rank = pi.rank;
  out.gain = j_null - (cst - g.dot(out.value));
  out.sigma = Eigen::VectorXd(P);
  for (Eigen::Index i = 0; i < P; ++i) out.sigma[i] = pi.inv(i, i) > 0 ? std::sqrt(pi.inv(i, i)) : kInf;
  return out;
}

Eigen::VectorXd channel_coefficients(const ChannelData& c, int channel, const FitSpec& spec, const FitResult& fit) {
  const int P = static_cast<int>(c.cols.size());
  Eigen::VectorXd coef = Eigen::VectorXd::Zero(P);
  std::vector<int> held;
  auto hold = [&](const ParamRef& ref, double v) {
    for (const ColumnUse& cu : columns_of(ref)) {
      const int i = cu.channel == channel ? c.index(cu.col) : -1;
      if (i < 0) continue;
      coef[i] += v;
      if (std::find(held.begin(), held.end(), i) == held.end()) held.push_back(i);
    }
  };
  for (std::size_t f = 0; f < spec.free.size(); ++f) hold(spec.free[f], fit.value[static_cast<Eigen::Index>(f)]);
  for (const auto& [ref, v] : spec.fixed) hold(ref, v);
  // the nuisance at its MAP given the held columns:
  // beta_N = (G_NN + sigma^2/prior^2)^-1 (G_Ny - G_NX beta_X)
  std::vector<int> given;
  const ChannelUse u = channel_use(c, channel, spec);
  for (int i : u.given) given.push_back(i);
  const std::vector<int> N = nuisance_of(c, held, given);
  if (N.empty()) return coef;
  const auto k = static_cast<Eigen::Index>(N.size());
  Eigen::MatrixXd A(k, k);
  Eigen::VectorXd b(k);
  for (Eigen::Index a = 0; a < k; ++a) {
    for (Eigen::Index e = 0; e < k; ++e) A(a, e) = c.gram(N[a], N[e]);
    A(a, a) += c.sigma2 / (c.prior[N[a]] * c.prior[N[a]]);
    b[a] = c.gram(N[a], P);
    for (int h : held) b[a] -= c.gram(N[a], h) * coef[h];
  }
  const Eigen::VectorXd x = A.ldlt().solve(b);
  for (Eigen::Index a = 0; a < k; ++a) coef[N[a]] += x[a];  // a given column: its value plus the nuisance
  return coef;
}

std::vector<double> block_residual(const ChannelData& c, const Eigen::VectorXd& coef) {
  std::vector<double> zr = c.z;
  for (int i = 0; i < static_cast<int>(c.cols.size()); ++i) {
    if (coef[i] == 0.0) continue;
    for (std::size_t b = 0; b < zr.size(); ++b) zr[b] -= c.block_cols(static_cast<Eigen::Index>(b), i) * coef[i];
  }
  return zr;
}

}  // namespace driftless::diagnose
