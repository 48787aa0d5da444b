// The Rauch-Tung-Striebel pass of `estimate --smooth` (docs/estimator.md section 6.3).
//
// Between two accepted updates k and k+1 the filter's state moves only by the bias random walk
// (Q, on the bias states) and the temperature step x <- F x, F = I + N, N putting dT_i k_i into
// b_i (N^2 = 0, so F^-1 = I - N). In the coordinates of update k (bias referred to its
// temperatures) the state at a time t in between is z(t) = z_k + walk, P(t|t) = P_k + s Qk with
// s = (t - t_k) / (t_{k+1} - t_k) and Qk = F^-1 P(k+1|k) F^-T - P_k what the interval added (the
// random walk, and the widening of a gate re-lock if one came). RTS:
//   C(t)     = P(t|t) F^T P(k+1|k)^-1 = (P_k + s Qk) M,     M = F^T P(k+1|k)^-1
//   z(t|N)   = z_k + C(t) (x(k+1|N) - x(k+1|k))      = u + s v    (linear in t)
//   P(t|N)   = P(t|t) + C(t) (P(k+1|N) - P(k+1|k)) C(t)^T     (diagonal: a + s b + s^2 c)
// At s = 0 this is the smoothed update k; at s = 1, F z equals x(k+1|N): no step at the updates.
#include "estimator/smoother.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

namespace driftless::est {

// ---------------------------------------------------------------------------------------------
// temporary records

TempRecords::TempRecords() : file_(std::tmpfile(), &std::fclose) {
  if (!file_) throw std::runtime_error("smoother: cannot create a temporary file (TMPDIR full or not writable?)");
}

void TempRecords::write(std::uint64_t index, const double* rec) {
  if (position_ != static_cast<std::int64_t>(index) &&
      std::fseek(file_.get(), static_cast<long>(index * size_ * sizeof(double)), SEEK_SET) != 0)
    throw std::runtime_error("smoother: cannot seek in its temporary file");
  if (std::fwrite(rec, sizeof(double), size_, file_.get()) != size_) {
    position_ = -1;
    throw std::runtime_error("smoother: cannot write its temporary file (disk full?)");
  }
  position_ = static_cast<std::int64_t>(index) + 1;
}

void TempRecords::read(std::uint64_t index, double* rec) {
  if (position_ != static_cast<std::int64_t>(index) &&
      std::fseek(file_.get(), static_cast<long>(index * size_ * sizeof(double)), SEEK_SET) != 0)
    throw std::runtime_error("smoother: cannot seek in its temporary file");
  if (std::fread(rec, sizeof(double), size_, file_.get()) != size_) {
    position_ = -1;
    throw std::runtime_error("smoother: cannot read back its temporary file");
  }
  position_ = static_cast<std::int64_t>(index) + 1;
}

namespace {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;
constexpr int kFull = kFullStateDim;

// knot record: t, temp_ref (2), x_prior, x_post (full), P_prior, P_post (active n x n)
constexpr std::size_t kKnotHead = 3;
// interval record: t_k, span, t_next, temp_ref (2), u, v, a, b, c (full, 0 where inactive)
constexpr std::size_t kIntervalHead = 5;
constexpr std::size_t kIntervalSize = kIntervalHead + 5 * kFull;

struct Knot {
  double t_s = kNaN;
  std::array<double, 2> temp_ref{kNaN, kNaN};
  StateVector x_prior, x_post;
  Mat P_prior, P_post;
};

Knot unpack_knot(const std::vector<double>& r, Eigen::Index n) {
  Knot k;
  k.t_s = r[0];
  k.temp_ref = {r[1], r[2]};
  k.x_prior = Eigen::Map<const StateVector>(r.data() + kKnotHead);
  k.x_post = Eigen::Map<const StateVector>(r.data() + kKnotHead + kFull);
  k.P_prior = Eigen::Map<const Mat>(r.data() + kKnotHead + 2 * kFull, n, n);
  k.P_post = Eigen::Map<const Mat>(r.data() + kKnotHead + 2 * kFull + n * n, n, n);
  return k;
}

// F of the temperature step between two updates, in the active states
Mat temperature_step(const std::array<double, 2>& from, const std::array<double, 2>& to,
                     const std::vector<Eigen::Index>& active) {
  const Eigen::Index n = static_cast<Eigen::Index>(active.size());
  Mat F = Mat::Identity(n, n);
  std::array<Eigen::Index, kFull> where;
  where.fill(-1);
  for (Eigen::Index i = 0; i < n; ++i) where[static_cast<std::size_t>(active[static_cast<std::size_t>(i)])] = i;
  for (int s = 0; s < 2; ++s) {
    const std::size_t su = static_cast<std::size_t>(s);
    if (!std::isfinite(from[su]) || !std::isfinite(to[su])) continue;
    for (int r = 0; r < 3; ++r) {
      const Eigen::Index b = where[static_cast<std::size_t>(kBias1.start + 3 * s + r)];
      const Eigen::Index k = where[static_cast<std::size_t>(kTempCoef1.start + 3 * s + r)];
      if (b >= 0 && k >= 0) F(b, k) = to[su] - from[su];
    }
  }
  return F;
}

Vec gather(const StateVector& x, const std::vector<Eigen::Index>& active) {
  Vec v(static_cast<Eigen::Index>(active.size()));
  for (std::size_t i = 0; i < active.size(); ++i) v[static_cast<Eigen::Index>(i)] = x[active[i]];
  return v;
}

void scatter(const Vec& v, const std::vector<Eigen::Index>& active, double* full) {
  for (std::size_t i = 0; i < active.size(); ++i) full[active[i]] = v[static_cast<Eigen::Index>(i)];
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// forward: one knot per accepted update

FixedIntervalSmoother::FixedIntervalSmoother(double q_dps2_per_s) : q_dps2_per_s_(q_dps2_per_s) {
  intervals_file_.set_size(kIntervalSize);
}

void FixedIntervalSmoother::on_accepted_update(const UpdateSnapshot& u) {
  if (smoothed_) throw std::logic_error("smoother: an update after smooth()");
  if (active_.empty()) {
    for (Eigen::Index i = 0; i < kFull; ++i)
      if ((*u.P_prior)(i, i) > 0.0) active_.push_back(i);
    const std::size_t n = active_.size();
    knots_file_.set_size(kKnotHead + 2 * kFull + 2 * n * n);
  }
  const Eigen::Index n = static_cast<Eigen::Index>(active_.size());
  buf_.assign(knots_file_.size(), 0.0);
  buf_[0] = u.t_s;
  buf_[1] = u.temp_ref_c[0];
  buf_[2] = u.temp_ref_c[1];
  Eigen::Map<StateVector>(buf_.data() + kKnotHead) = *u.x_prior;
  Eigen::Map<StateVector>(buf_.data() + kKnotHead + kFull) = *u.x_post;
  Eigen::Map<Mat> Pp(buf_.data() + kKnotHead + 2 * kFull, n, n), Pu(buf_.data() + kKnotHead + 2 * kFull + n * n, n, n);
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = 0; c < n; ++c) {
      Pp(r, c) = (*u.P_prior)(active_[static_cast<std::size_t>(r)], active_[static_cast<std::size_t>(c)]);
      Pu(r, c) = (*u.P_post)(active_[static_cast<std::size_t>(r)], active_[static_cast<std::size_t>(c)]);
    }
  knots_file_.write(knots_, buf_.data());
  ++knots_;
}

// ---------------------------------------------------------------------------------------------
// backward

void FixedIntervalSmoother::smooth() {
  if (smoothed_) return;
  smoothed_ = true;
  if (knots_ == 0) return;
  const Eigen::Index n = static_cast<Eigen::Index>(active_.size());
  std::vector<double> rec(knots_file_.size());
  std::vector<double> iv(kIntervalSize, 0.0);
  // the last update: smoothed = filtered; afterwards the bias variance grows by q per second
  knots_file_.read(knots_ - 1, rec.data());
  Knot next = unpack_knot(rec, n);
  StateVector xs = next.x_post;
  Mat Ps = next.P_post;
  {
    iv.assign(kIntervalSize, 0.0);
    iv[0] = next.t_s;
    iv[1] = 1.0;  // s = seconds after the last update
    iv[2] = std::numeric_limits<double>::infinity();
    iv[3] = next.temp_ref[0];
    iv[4] = next.temp_ref[1];
    Eigen::Map<StateVector>(iv.data() + kIntervalHead) = xs;
    scatter(Ps.diagonal(), active_, iv.data() + kIntervalHead + 2 * kFull);
    for (Eigen::Index i = 0; i < kStateDim; ++i) iv[kIntervalHead + 3 * kFull + static_cast<std::size_t>(i)] = q_dps2_per_s_;
    intervals_file_.write(knots_ - 1, iv.data());
  }
  for (std::uint64_t k = knots_ - 1; k-- > 0;) {
    knots_file_.read(k, rec.data());
    const Knot cur = unpack_knot(rec, n);
    const Mat F = temperature_step(cur.temp_ref, next.temp_ref, active_);
    const Mat Finv = 2.0 * Mat::Identity(n, n) - F;
    Eigen::LDLT<Mat> ldlt(next.P_prior);
    if (ldlt.info() != Eigen::Success) throw std::runtime_error("smoother: a prior covariance is not positive definite");
    const Mat M = ldlt.solve(F).transpose();  // F^T P(k+1|k)^-1
    const Vec delta = gather(xs, active_) - gather(next.x_prior, active_);
    const Mat& Pk = cur.P_post;
    const Mat Qk = Finv * next.P_prior * Finv.transpose() - Pk;
    const Mat C = Pk * M;
    const Mat W = Ps - next.P_prior;
    const Mat N = M * W * M.transpose();
    iv.assign(kIntervalSize, 0.0);
    iv[0] = cur.t_s;
    iv[1] = next.t_s - cur.t_s;
    iv[2] = next.t_s;
    iv[3] = cur.temp_ref[0];
    iv[4] = cur.temp_ref[1];
    StateVector u = cur.x_post;
    Vec ua = gather(u, active_) + C * delta;
    scatter(ua, active_, u.data());
    Eigen::Map<StateVector>(iv.data() + kIntervalHead) = u;
    scatter(Qk * (M * delta), active_, iv.data() + kIntervalHead + kFull);
    const Mat NP = N * Pk;
    scatter(Pk.diagonal() + (Pk * NP).diagonal(), active_, iv.data() + kIntervalHead + 2 * kFull);
    scatter(Qk.diagonal() + 2.0 * (Qk * NP).diagonal(), active_, iv.data() + kIntervalHead + 3 * kFull);
    scatter((Qk * N * Qk).diagonal(), active_, iv.data() + kIntervalHead + 4 * kFull);
    intervals_file_.write(k, iv.data());
    // the smoothed update k for the next step back
    xs = u;
    Ps = Pk + C * W * C.transpose();
    next = cur;
  }
}

// ---------------------------------------------------------------------------------------------
// second forward pass

void FixedIntervalSmoother::read_interval(std::uint64_t k) {
  std::vector<double> iv(kIntervalSize);
  intervals_file_.read(k, iv.data());
  current_ = static_cast<std::int64_t>(k);
  t_k_ = iv[0];
  span_s_ = iv[1];
  t_next_ = iv[2];
  out_.temp_ref_c = {iv[3], iv[4]};
  u_ = Eigen::Map<const StateVector>(iv.data() + kIntervalHead);
  v_ = Eigen::Map<const StateVector>(iv.data() + kIntervalHead + kFull);
  a_ = Eigen::Map<const StateVector>(iv.data() + kIntervalHead + 2 * kFull);
  b_ = Eigen::Map<const StateVector>(iv.data() + kIntervalHead + 3 * kFull);
  c_ = Eigen::Map<const StateVector>(iv.data() + kIntervalHead + 4 * kFull);
}

const SmoothedState& FixedIntervalSmoother::at(double t_s) {
  if (!smoothed_) throw std::logic_error("smoother: at() before smooth()");
  if (knots_ == 0) return out_;  // no update: nothing to smooth (x = 0, var = 0)
  if (current_ < 0) read_interval(0);
  while (t_s >= t_next_ && static_cast<std::uint64_t>(current_ + 1) < knots_) read_interval(static_cast<std::uint64_t>(current_ + 1));
  const double s = t_s > t_k_ ? (t_s - t_k_) / span_s_ : 0.0;
  out_.x = u_ + s * v_;
  out_.var = a_ + s * b_ + s * s * c_;
  return out_;
}

void smoothed_outputs(const EstimatorConfig& cfg, const BoxGeometry& box, const std::function<bool(Sample&)>& next,
                      FixedIntervalSmoother& sm, const std::function<void(const Sample&, const SampleOutput&)>& out) {
  DriftlessFilter filter(cfg, box);
  Sample s;
  while (next(s)) {
    const SmoothedState& st = sm.at(s.t_s);
    filter.set_output_state(&st.x, &st.temp_ref_c);
    filter.push(s);
    out(s, filter.output());
  }
}

}  // namespace driftless::est
