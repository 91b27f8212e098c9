#include "src/eval/line_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "src/eval/report.h"

namespace sft {
namespace {

const char* const kColors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                               "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f", v);
  return buffer;
}

// Enough significant digits that neighbouring ticks (a quarter of [lo, hi] apart) read
// differently: a narrow range far from zero, such as 300–301 s, needs more than 3.
int TickDigits(double lo, double hi) {
  const double step = (hi - lo) / 4.0, size = std::max(std::abs(lo), std::abs(hi));
  if (!(step > 0.0) || !(size > 0.0)) return 3;
  return std::clamp(static_cast<int>(std::ceil(std::log10(size / step))) + 1, 3, 10);
}

// The legend's mark (a line and/or a dot) and name for `series`, starting at x, centred on y.
std::string LegendEntry(const LineSeries& series, const std::string& color, const std::string& fill,
                        double x, double y) {
  std::string svg;
  if (series.line) {
    svg += "<line x1=\"" + Num(x) + "\" y1=\"" + Num(y) + "\" x2=\"" + Num(x + 18) + "\" y2=\"" +
           Num(y) + "\" stroke=\"" + color + "\" stroke-width=\"2\"/>";
  }
  if (series.marker_radius > 0.0) {
    svg += "<circle cx=\"" + Num(x + 9) + "\" cy=\"" + Num(y) + "\" r=\"" +
           Num(std::min(series.marker_radius, 5.0)) + "\" fill=\"" + fill + "\" stroke=\"" + color +
           "\" stroke-width=\"" + (series.hollow_markers ? "2" : "1") + "\"/>";
  }
  return svg + "<text x=\"" + Num(x + 22) + "\" y=\"" + Num(y + 4) + "\">" +
         HtmlEscape(series.name) + "</text>\n";
}

}  // namespace

std::string LineChartSvg(const LineChart& chart) {
  const double width = std::max(chart.width, 200), height = std::max(chart.height, 150);
  const double left = 70, right = 150, top = 30, bottom = 42;
  const double plot_w = width - left - right, plot_h = height - top - bottom;
  auto usable = [&](double x, double y) {
    return std::isfinite(x) && std::isfinite(y) && (!chart.log_y || y > 0);
  };
  auto ty = [&](double y) { return chart.log_y ? std::log10(y) : y; };
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo, y_lo = x_lo, y_hi = -x_lo;
  for (const LineSeries& s : chart.series) {
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!usable(s.x[i], s.y[i])) continue;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, ty(s.y[i]));
      y_hi = std::max(y_hi, ty(s.y[i]));
    }
  }
  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + Num(width) +
                    "\" height=\"" + Num(height) +
                    "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  svg += "<text x=\"" + Num(left) + "\" y=\"18\" font-size=\"13\">" + HtmlEscape(chart.title) +
         "</text>\n";
  if (!(x_hi >= x_lo) || !(y_hi >= y_lo))
    return svg + "<text x=\"80\" y=\"60\">no data</text></svg>\n";
  if (x_hi == x_lo) x_hi = x_lo + 1;
  if (y_hi == y_lo) {
    y_hi += 0.5;
    y_lo -= 0.5;
  }
  const double margin = std::clamp(chart.margin, 0.0, 1.0);
  const double x_pad = margin * (x_hi - x_lo), y_pad = margin * (y_hi - y_lo);
  // The margin never takes a non-negative axis below zero (times, counts).
  x_lo = x_lo >= 0.0 ? std::max(0.0, x_lo - x_pad) : x_lo - x_pad;
  x_hi += x_pad;
  y_lo = (y_lo >= 0.0 && !chart.log_y) ? std::max(0.0, y_lo - y_pad) : y_lo - y_pad;
  y_hi += y_pad;
  auto px = [&](double x) { return left + (x - x_lo) / (x_hi - x_lo) * plot_w; };
  auto py = [&](double y) { return top + (1.0 - (ty(y) - y_lo) / (y_hi - y_lo)) * plot_h; };
  svg += "<rect x=\"" + Num(left) + "\" y=\"" + Num(top) + "\" width=\"" + Num(plot_w) +
         "\" height=\"" + Num(plot_h) + "\" fill=\"none\" stroke=\"#888\"/>\n";
  const int x_digits = TickDigits(x_lo, x_hi);
  const int y_digits = chart.log_y ? 3 : TickDigits(y_lo, y_hi);
  for (int k = 0; k <= 4; ++k) {
    const double fx = x_lo + (x_hi - x_lo) * k / 4.0;
    const double fy = y_lo + (y_hi - y_lo) * k / 4.0;
    const double y_value = chart.log_y ? std::pow(10.0, fy) : fy;
    svg += "<text x=\"" + Num(px(fx)) + "\" y=\"" + Num(top + plot_h + 14) +
           "\" text-anchor=\"middle\">" + FormatNumber(fx, x_digits) + "</text>\n";
    svg += "<text x=\"" + Num(left - 4) + "\" y=\"" + Num(py(y_value) + 4) +
           "\" text-anchor=\"end\">" + FormatNumber(y_value, y_digits) + "</text>\n";
  }
  svg += "<text x=\"" + Num(left + plot_w / 2) + "\" y=\"" + Num(height - 6) +
         "\" text-anchor=\"middle\">" + HtmlEscape(chart.x_label) + "</text>\n";
  svg += "<text x=\"12\" y=\"" + Num(top + plot_h / 2) + "\" transform=\"rotate(-90 12 " +
         Num(top + plot_h / 2) + ")\" text-anchor=\"middle\">" + HtmlEscape(chart.y_label) +
         (chart.log_y ? " (log)" : "") + "</text>\n";
  for (size_t s = 0; s < chart.series.size(); ++s) {
    const LineSeries& series = chart.series[s];
    const std::string color = !series.color.empty()
                                  ? HtmlEscape(series.color)
                                  : kColors[s % (sizeof(kColors) / sizeof(kColors[0]))];
    const std::string fill = series.hollow_markers ? "none" : color;
    std::vector<std::string> lines(1);  // each a polyline's points.
    std::string dots;
    for (size_t i = 0; i < std::min(series.x.size(), series.y.size()); ++i) {
      const bool breaks =
          std::find(series.breaks.begin(), series.breaks.end(), i) != series.breaks.end();
      if (breaks && !lines.back().empty()) lines.emplace_back();
      if (!usable(series.x[i], series.y[i])) continue;
      lines.back() += Num(px(series.x[i])) + "," + Num(py(series.y[i])) + " ";
      if (series.marker_radius <= 0.0) continue;
      dots += "<circle cx=\"" + Num(px(series.x[i])) + "\" cy=\"" + Num(py(series.y[i])) +
              "\" r=\"" + Num(series.marker_radius) + "\" fill=\"" + fill + "\" stroke=\"" + color +
              "\" stroke-width=\"" + (series.hollow_markers ? "2" : "1") + "\">";
      if (i < series.tips.size()) dots += "<title>" + HtmlEscape(series.tips[i]) + "</title>";
      dots += "</circle>\n";
    }
    for (const std::string& points : lines) {
      if (!series.line || points.empty()) continue;
      svg += "<polyline fill=\"none\" stroke=\"" + color + "\" stroke-width=\"1.5\" points=\"" +
             points + "\"/>\n";
    }
    svg += dots;
    svg += LegendEntry(series, color, fill, left + plot_w + 10, top + 14 * s + 8);
  }
  return svg + "</svg>\n";
}

}  // namespace sft
