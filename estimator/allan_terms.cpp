#include "estimator/allan_terms.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace driftless::est {
namespace {

// two doubles per vector register (SSE2 on x86-64, NEON on aarch64, plain pairs elsewhere: GCC and
// Clang vector extensions) and four independent vector sums: eight adds in flight instead of one
// serial chain; the small-m levels run at the arithmetic's speed, the large-m ones at memory's
typedef double Pair __attribute__((vector_size(16)));

inline Pair load_pair(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

inline double lanes_sum(Pair a, Pair b, Pair c, Pair d) {
  const Pair s = (a + b) + (c + d);
  return s[0] + s[1];
}

double sum_allan(const double* S, std::size_t i0, std::size_t i1, std::size_t m) {
  const double* a = S;
  const double* b = S + m;
  const double* c = S + 2 * m;
  Pair s0 = {0.0, 0.0}, s1 = s0, s2 = s0, s3 = s0;
  std::size_t i = i0;
  for (; i + 8 <= i1; i += 8) {
    const Pair d0 = load_pair(c + i) - 2.0 * load_pair(b + i) + load_pair(a + i);
    const Pair d1 = load_pair(c + i + 2) - 2.0 * load_pair(b + i + 2) + load_pair(a + i + 2);
    const Pair d2 = load_pair(c + i + 4) - 2.0 * load_pair(b + i + 4) + load_pair(a + i + 4);
    const Pair d3 = load_pair(c + i + 6) - 2.0 * load_pair(b + i + 6) + load_pair(a + i + 6);
    s0 += d0 * d0;
    s1 += d1 * d1;
    s2 += d2 * d2;
    s3 += d3 * d3;
  }
  double s = lanes_sum(s0, s1, s2, s3);
  for (; i < i1; ++i) {
    const double d = c[i] - 2.0 * b[i] + a[i];
    s += d * d;
  }
  return s;
}

double sum_hadamard(const double* S, std::size_t i0, std::size_t i1, std::size_t m) {
  const double* a = S;
  const double* b = S + m;
  const double* c = S + 2 * m;
  const double* e = S + 3 * m;
  auto diff = [&](std::size_t k) {
    return load_pair(e + k) - 3.0 * load_pair(c + k) + 3.0 * load_pair(b + k) - load_pair(a + k);
  };
  Pair s0 = {0.0, 0.0}, s1 = s0, s2 = s0, s3 = s0;
  std::size_t i = i0;
  for (; i + 8 <= i1; i += 8) {
    const Pair d0 = diff(i), d1 = diff(i + 2), d2 = diff(i + 4), d3 = diff(i + 6);
    s0 += d0 * d0;
    s1 += d1 * d1;
    s2 += d2 * d2;
    s3 += d3 * d3;
  }
  double s = lanes_sum(s0, s1, s2, s3);
  for (; i < i1; ++i) {
    const double d = e[i] - 3.0 * c[i] + 3.0 * b[i] - a[i];
    s += d * d;
  }
  return s;
}

// modified Allan: the window sum w_j of the second differences d_i, i in [j, j + m), is moved
// along by one add and one subtract (rounding grows like sqrt(N) eps, far below the noise)
void sum_modified(const double* S, std::size_t np, std::size_t m, TermSum& out) {
  if (np < 3 * m) return;
  auto d = [&](std::size_t i) { return S[i + 2 * m] - 2.0 * S[i + m] + S[i]; };
  double w = 0.0;
  for (std::size_t i = 0; i < m; ++i) w += d(i);
  const std::size_t last = np - 3 * m;  // j = 0..last
  double s = w * w;
  for (std::size_t j = 1; j <= last; ++j) {
    w += d(j + m - 1) - d(j - 1);
    s += w * w;
  }
  out.sum += s;
  out.terms += last + 1;
}

}  // namespace

std::size_t span_in_m(Deviation dev) { return dev == Deviation::kAllan ? 2 : 3; }

void accumulate_range(Deviation dev, const double* S, std::size_t i0, std::size_t i1, std::size_t m,
                      std::size_t stride, TermSum& out) {
  if (i1 <= i0) return;
  if (stride == 1) {
    out.sum += dev == Deviation::kHadamard ? sum_hadamard(S, i0, i1, m) : sum_allan(S, i0, i1, m);
    out.terms += i1 - i0;
    return;
  }
  for (std::size_t i = i0; i < i1; i += stride) {
    const double d = dev == Deviation::kHadamard ? S[i + 3 * m] - 3.0 * S[i + 2 * m] + 3.0 * S[i + m] - S[i]
                                                 : S[i + 2 * m] - 2.0 * S[i + m] + S[i];
    out.sum += d * d;
    ++out.terms;
  }
}

void accumulate_terms(Deviation dev, const double* S, std::size_t np, std::size_t m, std::size_t stride,
                      TermSum& out) {
  if (dev == Deviation::kModifiedAllan) {
    if (stride != 1) throw std::invalid_argument("allan: the modified Allan variance is overlapping only");
    sum_modified(S, np, m, out);
    return;
  }
  const std::size_t span = span_in_m(dev) * m;
  if (np <= span) return;
  accumulate_range(dev, S, 0, np - span, m, stride, out);
}

double deviation_from_sum(Deviation dev, const TermSum& s, std::size_t m) {
  if (s.terms == 0) return std::nan("");
  const double M = static_cast<double>(m);
  const double T = static_cast<double>(s.terms);
  switch (dev) {
    case Deviation::kAllan: return std::sqrt(s.sum / (2.0 * M * M * T));
    case Deviation::kModifiedAllan: return std::sqrt(s.sum / (2.0 * M * M * M * M * T));
    case Deviation::kHadamard: return std::sqrt(s.sum / (6.0 * M * M * T));
  }
  return std::nan("");
}

}  // namespace driftless::est
