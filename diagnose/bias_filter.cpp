#include "diagnose/bias_filter.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace driftless::diagnose {

void ChannelNoise::validate() const {
  auto check = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("ChannelNoise: ") + what);
  };
  check(white_dps_rthz > 0 && std::isfinite(white_dps_rthz), "white_dps_rthz must be > 0 deg/s/rtHz");
  check(gm_sigma_dps >= 0 && std::isfinite(gm_sigma_dps), "gm_sigma_dps must be >= 0 deg/s");
  check(gm_tau_s > 0 && std::isfinite(gm_tau_s), "gm_tau_s must be > 0 s");
  check(rrw_dps_rts >= 0 && std::isfinite(rrw_dps_rts), "rrw_dps_rts must be >= 0 deg/s/rts");
  check(turn_on_sigma_dps > 0, "turn_on_sigma_dps must be > 0 deg/s");
}

namespace {

// the two-state bias model's constants: white-noise variance of one sample (rate units), the
// drift processes' variances; the state is [constant + random walk, Gauss-Markov]
struct Process {
  double white_var_rate, gm_var, rrw_var, gm_tau_s;
  Process(const BlockSeries& blocks, const ChannelNoise& noise)
      : white_var_rate(noise.white_dps_rthz * noise.white_dps_rthz * blocks.sample_rate_hz),
        gm_var(noise.gm_sigma_dps * noise.gm_sigma_dps),
        rrw_var(noise.rrw_dps_rts * noise.rrw_dps_rts),
        gm_tau_s(noise.gm_tau_s) {}
};

// the interval before block j, s (0 before the first)
double block_dt(const BlockSeries& b, std::size_t j) { return j == 0 ? 0.0 : b.t_s[j] - b.t_s[j - 1]; }

}  // namespace

// the filter's covariance recursion over the blocks, the one loop every user shares (the same
// operations in the same order, so the same bits whichever user): after block j it calls
// visit(j, g) with the step's gains and covariances. exp() runs once per distinct interval and the
// measurement variance once per distinct sample count (the noise-model searches run this
// thousands of times on 36 000 blocks)
template <class Visit>
void BiasWhitener::recursion(const BlockSeries& blocks, const ChannelNoise& noise, Visit&& visit) {
  noise.validate();
  const Process pr(blocks, noise);
  double p00 = noise.turn_on_sigma_dps * noise.turn_on_sigma_dps, p01 = 0.0, p11 = pr.gm_var;
  double last_dt = std::numeric_limits<double>::quiet_NaN(), phi = 1.0, q_gm = 0.0;
  std::uint16_t last_count = 0;
  double r = 0.0;
  bool first = true;
  Step st{};
  for (std::size_t j = 0; j < blocks.t_s.size(); ++j) {
    const double dt = block_dt(blocks, j);
    if (dt != last_dt) last_dt = dt, phi = std::exp(-dt / pr.gm_tau_s), q_gm = pr.gm_var * (1.0 - phi * phi);
    st.phi = phi;
    st.q_rw = pr.rrw_var * dt;
    st.q_gm = q_gm;
    // predict
    st.pp00 = p00 + st.q_rw;
    st.pp01 = phi * p01;
    st.pp11 = phi * phi * p11 + q_gm;
    const std::uint16_t count = blocks.count[j];
    bool used = false;
    if (count > 0) {
      if (count != last_count) last_count = count, r = pr.white_var_rate / count;
      st.s = st.pp00 + 2 * st.pp01 + st.pp11 + r;
      st.k0 = (st.pp00 + st.pp01) / st.s;
      st.k1 = (st.pp01 + st.pp11) / st.s;
      p00 = st.pp00 - st.k0 * st.k0 * st.s;
      p01 = st.pp01 - st.k0 * st.k1 * st.s;
      p11 = st.pp11 - st.k1 * st.k1 * st.s;
      used = !first;  // the first observed block only fixes the turn-on bias (diffuse prior)
      first = false;
    } else {
      st.s = 0.0;
      st.k0 = st.k1 = 0.0;
      p00 = st.pp00, p01 = st.pp01, p11 = st.pp11;
    }
    st.pf00 = p00, st.pf01 = p01, st.pf11 = p11;
    visit(j, st, used);
  }
}

BiasWhitener::BiasWhitener(const BlockSeries& blocks, const ChannelNoise& noise) {
  const std::size_t m = blocks.t_s.size();
  steps_.resize(m);
  used_.assign(m, 0);
  recursion(blocks, noise, [&](std::size_t j, const Step& st, bool used) {
    steps_[j] = st;
    used_[j] = used;
    n_used_ += used;
  });
  final_sigma_ = m > 0 ? std::sqrt(std::max(0.0, steps_.back().pf00)) : std::sqrt(noise.turn_on_sigma_dps * noise.turn_on_sigma_dps);
}

// -2 log-likelihood of the innovations: sum of nu^2/s plus the log-determinant, summed as the log
// of products of up to 8 innovation variances (one log per 8 blocks instead of per block: the
// searches evaluate it a thousand times on 36 000 blocks); 8 variances within 1e-30..1e30 stay
// far inside double's range, a variance outside it is logged alone
class Neg2LogLik {
 public:
  void add(double nu, double s) {
    quad_ += nu * nu / s;
    if (!(s > 1e-30 && s < 1e30)) {
      logdet_ += std::log(s);
      return;
    }
    prod_ *= s;
    if (++in_prod_ == 8) logdet_ += std::log(prod_), prod_ = 1.0, in_prod_ = 0;
  }
  double value() const { return logdet_ + std::log(prod_) + quad_; }

 private:
  double quad_ = 0.0, logdet_ = 0.0, prod_ = 1.0;
  int in_prod_ = 0;
};

// the recursion and neg2_loglik(z) fused, keeping nothing per block (the same bits as the member)
double BiasWhitener::neg2_loglik(const BlockSeries& blocks, const ChannelNoise& noise, std::span<const double> z) {
  double x0 = 0.0, x1 = 0.0;
  Neg2LogLik acc;
  recursion(blocks, noise, [&](std::size_t j, const Step& st, bool used) {
    x1 *= st.phi;
    if (!(st.s > 0.0)) return;
    const double nu = z[j] - x0 - x1;
    x0 += st.k0 * nu;
    x1 += st.k1 * nu;
    if (used) acc.add(nu, st.s);
  });
  return acc.value();
}

// whiten() of every column and of z at once, block by block, summing the rows' outer products in
// chunks: no per-block gains and no whitened copy of the columns (they were 10 MB per call an hour)
template <class Matrix>
WhitenedGram BiasWhitener::whitened_gram_of(const BlockSeries& blocks, const ChannelNoise& noise,
                                            const Matrix& cols, std::span<const double> z) {
  const Eigen::Index P = cols.cols(), n = P + 1;
  constexpr Eigen::Index kChunk = 256;
  WhitenedGram out;
  out.gram = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd rows(n, kChunk);  // one whitened block per column
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(n), x1 = Eigen::VectorXd::Zero(n);
  Eigen::Index filled = 0;
  auto flush = [&] {
    out.gram.noalias() += rows.leftCols(filled) * rows.leftCols(filled).transpose();
    filled = 0;
  };
  recursion(blocks, noise, [&](std::size_t j, const Step& st, bool used) {
    x1 *= st.phi;
    if (!(st.s > 0.0)) return;
    const double sq = std::sqrt(st.s);
    const auto b = static_cast<Eigen::Index>(j);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double v = i < P ? static_cast<double>(cols(b, i)) : z[j];
      const double nu = v - x0[i] - x1[i];
      x0[i] += st.k0 * nu;
      x1[i] += st.k1 * nu;
      if (used) rows(i, filled) = nu / sq;
    }
    if (!used) return;
    ++out.used;
    if (++filled == kChunk) flush();
  });
  flush();
  return out;
}

WhitenedGram BiasWhitener::whitened_gram(const BlockSeries& blocks, const ChannelNoise& noise,
                                         const Eigen::MatrixXf& cols, std::span<const double> z) {
  return whitened_gram_of(blocks, noise, cols, z);
}

WhitenedGram BiasWhitener::whitened_gram(const BlockSeries& blocks, const ChannelNoise& noise,
                                         const Eigen::MatrixXd& cols, std::span<const double> z) {
  return whitened_gram_of(blocks, noise, cols, z);
}

void BiasWhitener::whiten(std::span<const double> z, std::span<double> out) const {
  forward(z, [&](std::size_t j, const Step& st, double nu, double, double) {
    out[j] = st.s > 0.0 && used_[j] ? nu / std::sqrt(st.s) : 0.0;
  });
}

double BiasWhitener::neg2_loglik(std::span<const double> z) const {
  Neg2LogLik acc;
  forward(z, [&](std::size_t j, const Step& st, double nu, double, double) {
    if (st.s > 0.0 && used_[j]) acc.add(nu, st.s);
  });
  return acc.value();
}

std::vector<double> BiasWhitener::smooth(std::span<const double> z) const {
  const std::size_t m = steps_.size();
  std::vector<double> xf0(m), xf1(m), out(m);
  forward(z, [&](std::size_t j, const Step&, double, double x0, double x1) { xf0[j] = x0, xf1[j] = x1; });
  if (m == 0) return out;
  // Rauch-Tung-Striebel backward pass: C = Pf F^T Pp_next^{-1}
  double s0 = xf0[m - 1], s1 = xf1[m - 1];
  out[m - 1] = s0 + s1;
  for (std::size_t jj = m - 1; jj-- > 0;) {
    const Step& st = steps_[jj];
    const Step& nx = steps_[jj + 1];
    const double det = nx.pp00 * nx.pp11 - nx.pp01 * nx.pp01;
    // Pf F^T with F = diag(1, phi)
    const double a00 = st.pf00, a01 = st.pf01 * nx.phi, a10 = st.pf01, a11 = st.pf11 * nx.phi;
    double c00, c01, c10, c11;
    if (det > 1e-300) {
      const double i00 = nx.pp11 / det, i01 = -nx.pp01 / det, i11 = nx.pp00 / det;
      c00 = a00 * i00 + a01 * i01;
      c01 = a00 * i01 + a01 * i11;
      c10 = a10 * i00 + a11 * i01;
      c11 = a10 * i01 + a11 * i11;
    } else {
      // degenerate (no GM part): scalar smoother on the first state
      c00 = nx.pp00 > 0 ? a00 / nx.pp00 : 1.0;
      c01 = c10 = 0.0;
      c11 = nx.pp11 > 0 ? a11 / nx.pp11 : 0.0;
    }
    const double xp0 = xf0[jj], xp1 = xf1[jj] * nx.phi;
    const double d0 = s0 - xp0, d1 = s1 - xp1;
    s0 = xf0[jj] + c00 * d0 + c01 * d1;
    s1 = xf1[jj] + c10 * d0 + c11 * d1;
    out[jj] = s0 + s1;
  }
  return out;
}

void block_means(std::span<const double> x, std::span<const std::uint8_t> mask,
                 std::size_t block_len, std::span<double> out) {
  for (std::size_t j = 0; j < out.size(); ++j) {
    double acc = 0.0;
    int cnt = 0;
    const std::size_t a = j * block_len, b = std::min(x.size(), a + block_len);
    for (std::size_t k = a; k < b; ++k) {
      if (mask[k] && std::isfinite(x[k])) {
        acc += x[k];
        ++cnt;
      }
    }
    out[j] = cnt > 0 ? acc / cnt : 0.0;
  }
}

}  // namespace driftless::diagnose
