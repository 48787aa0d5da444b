// Strip charts drawn into the video frame: a sliding time window of a few named lines, with
// round tick values, a legend for the line colours, dashed reference (truth) lines and text
// that always fits its box (docs/render.md, "Overlay").
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <mujoco/mujoco.h>

namespace driftless::render {

/// One line of a chart.
struct ChartLine {
  std::string name;
  float rgb[3];
  bool dashed = false;  // reference lines (truth) are dashed in their axis' colour
};

/// One legend entry: a short line sample and its text.
struct LegendEntry {
  std::string text;
  float rgb[3];
  bool dashed = false;
};

/// A chart's data over a sliding window of data time.
class StripChart {
 public:
  /// title: with units; window_s: width of the time axis (s of data time); min_span: the y axis
  /// spans at least this much (units of the values), so a flat line is not blown up to noise.
  StripChart(std::string title, std::vector<ChartLine> lines, std::vector<LegendEntry> legend,
             double window_s, double min_span);
  /// Appends one point per line (NaN leaves a line untouched at that time).
  void push(double t_s, const std::vector<double>& values);
  void clear();
  bool empty() const { return points_ == 0; }
  const std::string& title() const { return title_; }
  const std::vector<ChartLine>& lines() const { return lines_; }
  const std::vector<LegendEntry>& legend() const { return legend_; }
  double window_s() const { return window_s_; }
  double min_span() const { return min_span_; }
  /// What an empty chart says instead of an axis ("waiting for the first update").
  std::string empty_text = "no data yet";
  /// Points of line i as (t, value) pairs inside the window ending at t_now_s.
  std::vector<std::pair<double, double>> points(std::size_t i, double t_now_s) const;
  /// Time of the first point ever pushed (NaN before any): the time axis starts there.
  double first_t_s() const { return first_t_s_; }

 private:
  std::string title_;
  std::vector<ChartLine> lines_;
  std::vector<LegendEntry> legend_;
  double window_s_;
  double min_span_;
  std::vector<std::vector<std::pair<double, double>>> data_;  // per line, time-ordered
  std::size_t points_ = 0;
  double first_t_s_;
};

/// Round tick values covering [lo, hi]: steps of 1, 2 or 5 x 10^k, at most `max_ticks` of them
/// inside the range (the first and last may lie on the ends).
struct Ticks {
  double step = 1.0;
  std::vector<double> values;
  int decimals = 0;  // digits after the point that show every value exactly
};
Ticks round_ticks(double lo, double hi, int max_ticks);

/// The y range a chart shows: the data's extent padded by 8 %, at least `min_span` wide,
/// widened to whole tick steps. Returns {lo, hi, ticks}.
struct AxisRange {
  double lo = 0.0, hi = 1.0;
  Ticks ticks;
};
AxisRange value_axis(double data_lo, double data_hi, double min_span, int max_ticks);

/// A pixel rectangle, origin at the bottom left (OpenGL's convention).
struct PixelRect {
  int left = 0, bottom = 0, width = 0, height = 0;
};

/// Width in pixels of `text` in `con`'s normal font.
int text_width_px(const std::string& text, const mjrContext& con);
/// `text` cut (with "..") to fit `width_px`.
std::string fit_text(const std::string& text, int width_px, const mjrContext& con);

/// Draws `chart` into `rect` of a frame of frame_w x frame_h pixels at data time t_now_s. Needs
/// the GL context current and the frame's framebuffer bound.
void draw_chart(const StripChart& chart, const PixelRect& rect, double t_now_s, const mjrContext& con,
                int frame_w, int frame_h);

/// Fills `rect` with a colour (alpha blended).
void fill_rect(const PixelRect& rect, float r, float g, float b, float a, int frame_w, int frame_h);

/// One line of the overlay text: a title (grey) and its value (white).
struct TextRow {
  std::string title, value;
};
/// Draws rows top-down from the top left of `rect`: titles in one column, values in the next,
/// each value cut to the rect's width.
void draw_text_rows(const std::vector<TextRow>& rows, const PixelRect& rect, const mjrContext& con, int frame_w,
                    int frame_h);

}  // namespace driftless::render
