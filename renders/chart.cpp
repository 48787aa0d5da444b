#include "renders/chart.hpp"


#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/sample.hpp"
#include "renders/gl_api.hpp"

namespace driftless::render {

// ---- data ----

StripChart::StripChart(std::string title, std::vector<ChartLine> lines, std::vector<LegendEntry> legend,
                       double window_s, double min_span)
    : title_(std::move(title)),
      lines_(std::move(lines)),
      legend_(std::move(legend)),
      window_s_(window_s),
      min_span_(min_span),
      data_(lines_.size()),
      first_t_s_(kNaN) {
  if (lines_.empty() || lines_.size() > 8) throw std::invalid_argument("a strip chart holds 1..8 lines");
  if (!(window_s > 0.0)) throw std::invalid_argument("strip chart window must be > 0 s");
  if (!(min_span > 0.0)) throw std::invalid_argument("strip chart minimum span must be > 0");
}

void StripChart::push(double t_s, const std::vector<double>& values) {
  for (std::size_t i = 0; i < lines_.size() && i < values.size(); ++i) {
    if (!std::isfinite(values[i])) continue;
    auto& d = data_[i];
    d.emplace_back(t_s, values[i]);
    // drop what slid out of the window (kept bounded: at most a few thousand points)
    std::size_t drop = 0;
    while (drop < d.size() && d[drop].first < t_s - window_s_) ++drop;
    if (drop > 0 && (drop > 256 || drop == d.size())) d.erase(d.begin(), d.begin() + static_cast<long>(drop));
    if (points_ == 0) first_t_s_ = t_s;
    ++points_;
  }
}

void StripChart::clear() {
  for (auto& d : data_) d.clear();
  points_ = 0;
  first_t_s_ = kNaN;
}

std::vector<std::pair<double, double>> StripChart::points(std::size_t i, double t_now_s) const {
  std::vector<std::pair<double, double>> out;
  for (const auto& p : data_.at(i)) {
    if (p.first >= t_now_s - window_s_ && p.first <= t_now_s) out.push_back(p);
  }
  return out;
}

// ---- axes ----

Ticks round_ticks(double lo, double hi, int max_ticks) {
  Ticks t;
  if (!(hi > lo) || max_ticks < 2) {
    t.values = {lo};
    return t;
  }
  // the smallest 1-2-5 step that keeps the count of ticks inside [lo, hi] at most max_ticks
  const double raw = (hi - lo) / (max_ticks - 1);
  double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (;;) {
    for (double m : {1.0, 2.0, 5.0}) {
      t.step = m * mag;
      const double first = std::ceil(lo / t.step - 1e-9) * t.step;
      const int n = static_cast<int>(std::floor((hi - first) / t.step + 1e-9)) + 1;
      if (n <= max_ticks) {
        t.values.clear();
        for (int k = 0; k < n; ++k) {
          const double v = first + k * t.step;
          t.values.push_back(std::abs(v) < 1e-9 * t.step ? 0.0 : v);
        }
        t.decimals = std::max(0, -static_cast<int>(std::floor(std::log10(t.step) + 1e-9)));
        return t;
      }
    }
    mag *= 10.0;
  }
}

AxisRange value_axis(double data_lo, double data_hi, double min_span, int max_ticks) {
  AxisRange a;
  if (!std::isfinite(data_lo) || !std::isfinite(data_hi)) data_lo = data_hi = 0.0;
  double pad = 0.08 * (data_hi - data_lo);
  double lo = data_lo - pad, hi = data_hi + pad;
  if (hi - lo < min_span) {
    const double mid = 0.5 * (data_lo + data_hi);
    lo = mid - 0.5 * min_span;
    hi = mid + 0.5 * min_span;
  }
  // a quantity that never changes sign keeps its axis on one side of zero
  if (data_lo >= 0.0) lo = std::max(lo, 0.0);
  if (data_hi <= 0.0) hi = std::min(hi, 0.0);
  // widen to whole steps so the axis ends on ticks
  a.ticks = round_ticks(lo, hi, max_ticks);
  a.lo = std::floor(lo / a.ticks.step + 1e-9) * a.ticks.step;
  a.hi = std::ceil(hi / a.ticks.step - 1e-9) * a.ticks.step;
  a.ticks = round_ticks(a.lo, a.hi, max_ticks + 2);
  return a;
}

// ---- drawing ----

int text_width_px(const std::string& text, const mjrContext& con) {
  int w = 0;
  for (unsigned char c : text) w += con.charWidth[c];
  return w;
}

std::string fit_text(const std::string& text, int width_px, const mjrContext& con) {
  if (text_width_px(text, con) <= width_px) return text;
  std::string t = text;
  while (!t.empty() && text_width_px(t + "..", con) > width_px) t.pop_back();
  return t + "..";
}

namespace {

// reference (dashed) lines are mixed this much with white, so they show on top of their estimate
constexpr float kReferenceLighten = 0.55f;
constexpr float kText[3] = {0.95f, 0.95f, 0.95f};
constexpr float kDim[3] = {0.7f, 0.72f, 0.75f};

// pixel coordinates, origin bottom left, for everything drawn after it
void begin_2d(int w, int h) {
  gl_api().Viewport(0, 0, w, h);
  gl_api().MatrixMode(GL_PROJECTION);
  gl_api().LoadIdentity();
  gl_api().Ortho(0, w, 0, h, -1, 1);
  gl_api().MatrixMode(GL_MODELVIEW);
  gl_api().LoadIdentity();
  gl_api().Disable(GL_DEPTH_TEST);
  gl_api().Disable(GL_LIGHTING);
  gl_api().Disable(GL_TEXTURE_2D);
  gl_api().Disable(GL_CULL_FACE);
  gl_api().Enable(GL_BLEND);
  gl_api().BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
}

// text with its baseline at pixel (x, y); mjr_text works in relative coordinates
void text_at(const std::string& s, int x, int y, const float rgb[3], const mjrContext& con, int w, int h) {
  gl_api().Viewport(0, 0, w, h);
  mjr_text(mjFONT_NORMAL, s.c_str(), &con, static_cast<float>(x) / w, static_cast<float>(y) / h, rgb[0], rgb[1],
           rgb[2]);
  begin_2d(w, h);
}

void line_sample(int x, int y, int len, const float rgb[3], bool dashed) {
  gl_api().LineWidth(2.0f);
  if (dashed) {
    gl_api().Enable(GL_LINE_STIPPLE);
    gl_api().LineStipple(2, 0x0F0F);
  }
  const float k = dashed ? kReferenceLighten : 0.0f;
  gl_api().Color4f(rgb[0] + k * (1 - rgb[0]), rgb[1] + k * (1 - rgb[1]), rgb[2] + k * (1 - rgb[2]), 1.0f);
  gl_api().Begin(GL_LINES);
  gl_api().Vertex2f(static_cast<float>(x), static_cast<float>(y));
  gl_api().Vertex2f(static_cast<float>(x + len), static_cast<float>(y));
  gl_api().End();
  gl_api().Disable(GL_LINE_STIPPLE);
}


// the legend row: a line sample and the text of each entry, left to right
void draw_legend(const std::vector<LegendEntry>& legend, int x, int y, int right, const mjrContext& con, int w,
                 int h) {
  const int sample = std::max(10, con.charHeight);
  for (const auto& e : legend) {
    const int need = sample + 4 + text_width_px(e.text, con) + 10;
    if (x + need - 10 > right) break;  // no room: drop entries rather than overlap
    line_sample(x, y + con.charHeight / 3, sample, e.rgb, e.dashed);
    text_at(e.text, x + sample + 4, y, kText, con, w, h);
    x += need;
  }
}

struct PlotArea {
  double x_lo, x_hi;
  AxisRange y;
  PixelRect px;
  float to_x(double t) const { return static_cast<float>(px.left + (t - x_lo) / (x_hi - x_lo) * px.width); }
  float to_y(double v) const { return static_cast<float>(px.bottom + (v - y.lo) / (y.hi - y.lo) * px.height); }
};

void draw_axes(const PlotArea& a, const Ticks& xt, const mjrContext& con, int w, int h) {
  gl_api().LineWidth(1.0f);
  gl_api().Color4f(1.0f, 1.0f, 1.0f, 0.18f);
  gl_api().Begin(GL_LINES);
  for (double v : a.y.ticks.values) {
    gl_api().Vertex2f(static_cast<float>(a.px.left), a.to_y(v));
    gl_api().Vertex2f(static_cast<float>(a.px.left + a.px.width), a.to_y(v));
  }
  for (double t : xt.values) {
    gl_api().Vertex2f(a.to_x(t), static_cast<float>(a.px.bottom));
    gl_api().Vertex2f(a.to_x(t), static_cast<float>(a.px.bottom + a.px.height));
  }
  gl_api().End();
  const int ch = con.charHeight;
  for (double v : a.y.ticks.values) {
    const std::string s = fmt::format("{:.{}f}", v, a.y.ticks.decimals);
    text_at(s, a.px.left - 4 - text_width_px(s, con), static_cast<int>(a.to_y(v)) - ch / 3, kDim, con, w, h);
  }
  for (double t : xt.values) {
    const std::string s = fmt::format("{:.{}f}", t, xt.decimals);
    int x = static_cast<int>(a.to_x(t)) - text_width_px(s, con) / 2;
    x = std::clamp(x, a.px.left - 4, a.px.left + a.px.width - text_width_px(s, con));
    text_at(s, x, a.px.bottom - ch - 1, kDim, con, w, h);
  }
}

void draw_lines(const StripChart& chart, const PlotArea& a, double t_now_s) {
  gl_api().Enable(GL_SCISSOR_TEST);
  gl_api().Scissor(a.px.left, a.px.bottom, a.px.width + 1, a.px.height + 1);
  // reference lines last, dashed and lighter, so both show where they agree
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < chart.lines().size(); ++i) {
      const auto& line = chart.lines()[i];
      if (line.dashed != (pass == 1)) continue;
      if (line.dashed) {
        gl_api().Enable(GL_LINE_STIPPLE);
        gl_api().LineStipple(2, 0x0F0F);
      }
      gl_api().LineWidth(line.dashed ? 1.5f : 2.0f);
      const float k = line.dashed ? kReferenceLighten : 0.0f;
      gl_api().Color4f(line.rgb[0] + k * (1 - line.rgb[0]), line.rgb[1] + k * (1 - line.rgb[1]),
                line.rgb[2] + k * (1 - line.rgb[2]), 1.0f);
      gl_api().Begin(GL_LINE_STRIP);
      for (const auto& [t, v] : chart.points(i, t_now_s)) gl_api().Vertex2f(a.to_x(t), a.to_y(v));
      gl_api().End();
      gl_api().Disable(GL_LINE_STIPPLE);
    }
  }
  gl_api().Disable(GL_SCISSOR_TEST);
}

// as many round time ticks as their labels leave room for
Ticks time_ticks(const PlotArea& a, const mjrContext& con) {
  for (int n = std::max(2, a.px.width / 30); n > 2; --n) {
    const Ticks t = round_ticks(a.x_lo, a.x_hi, n);
    int widest = 0;
    for (double v : t.values) widest = std::max(widest, text_width_px(fmt::format("{:.{}f}", v, t.decimals), con));
    const double spacing = t.step / (a.x_hi - a.x_lo) * a.px.width;
    if (spacing >= widest + 12) return t;
  }
  return round_ticks(a.x_lo, a.x_hi, 2);
}

// the data's value range inside [x_lo, x_hi]
std::pair<double, double> data_range(const StripChart& chart, double t_now_s, double x_lo) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < chart.lines().size(); ++i) {
    for (const auto& [t, v] : chart.points(i, t_now_s)) {
      if (t < x_lo) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  return {lo, hi};
}

}  // namespace

void fill_rect(const PixelRect& r, float red, float green, float blue, float alpha, int w, int h) {
  begin_2d(w, h);
  gl_api().Color4f(red, green, blue, alpha);
  gl_api().Begin(GL_QUADS);
  gl_api().Vertex2f(static_cast<float>(r.left), static_cast<float>(r.bottom));
  gl_api().Vertex2f(static_cast<float>(r.left + r.width), static_cast<float>(r.bottom));
  gl_api().Vertex2f(static_cast<float>(r.left + r.width), static_cast<float>(r.bottom + r.height));
  gl_api().Vertex2f(static_cast<float>(r.left), static_cast<float>(r.bottom + r.height));
  gl_api().End();
}

void draw_chart(const StripChart& chart, const PixelRect& r, double t_now_s, const mjrContext& con, int w, int h) {
  fill_rect(r, 0.08f, 0.09f, 0.11f, 0.88f, w, h);
  const int ch = con.charHeight, pad = 4;
  int y = r.bottom + r.height - pad - ch;
  text_at(fit_text(chart.title(), r.width - 2 * pad, con), r.left + pad, y + ch / 4, kText, con, w, h);
  y -= ch + 2;
  draw_legend(chart.legend(), r.left + pad, y + ch / 4, r.left + r.width - pad, con, w, h);
  const int plot_top = y - 4;
  if (chart.empty()) {
    const std::string s = fit_text(chart.empty_text, r.width - 2 * pad, con);
    text_at(s, r.left + (r.width - text_width_px(s, con)) / 2, r.bottom + (plot_top - r.bottom) / 2, kDim, con, w, h);
    return;
  }
  // the time axis starts with the data and slides once the window is full
  PlotArea a;
  a.x_hi = t_now_s;
  a.x_lo = std::max(chart.first_t_s(), t_now_s - chart.window_s());
  if (!(a.x_hi - a.x_lo > 1e-6)) a.x_hi = a.x_lo + 1.0;
  const auto [lo, hi] = data_range(chart, t_now_s, a.x_lo);
  const int rows = std::max(2, (plot_top - r.bottom - ch - 6) / (ch + 6));
  a.y = value_axis(lo, hi, chart.min_span(), std::min(5, rows));
  int label_w = 0;
  for (double v : a.y.ticks.values) label_w = std::max(label_w, text_width_px(fmt::format("{:.{}f}", v, a.y.ticks.decimals), con));
  a.px = {r.left + pad + label_w + 4, r.bottom + ch + 4, 0, 0};
  a.px.width = r.left + r.width - pad - a.px.left;
  a.px.height = plot_top - a.px.bottom;
  if (a.px.width < 10 || a.px.height < 10) return;
  const Ticks xt = time_ticks(a, con);
  draw_axes(a, xt, con, w, h);
  draw_lines(chart, a, t_now_s);
}

void draw_text_rows(const std::vector<TextRow>& rows, const PixelRect& r, const mjrContext& con, int w, int h) {
  const int ch = con.charHeight, pad = 6, gap = 8;
  int title_w = 0;
  for (const auto& row : rows) title_w = std::max(title_w, text_width_px(row.title, con));
  int y = r.bottom + r.height - pad - ch;
  for (const auto& row : rows) {
    if (y < r.bottom) break;
    const int vx = row.title.empty() ? r.left + pad : r.left + pad + title_w + gap;
    if (!row.title.empty()) text_at(row.title, r.left + pad, y + ch / 4, kDim, con, w, h);
    text_at(fit_text(row.value, r.left + r.width - pad - vx, con), vx, y + ch / 4, kText, con, w, h);
    y -= ch + 3;
  }
}

}  // namespace driftless::render
