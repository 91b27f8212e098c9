// Line charts as inline SVG for the HTML reports: several series of (x, y) points, optionally
// with a logarithmic y axis (cost curves span decades). A series may be drawn as a line, as dots
// (a scatter plot, with a tooltip per dot), or both.
#ifndef SFT_EVAL_LINE_CHART_H_
#define SFT_EVAL_LINE_CHART_H_

#include <string>
#include <vector>

namespace sft {

struct LineSeries {
  std::string name;       // legend entry.
  std::vector<double> x;  // same length as y; non-finite points are skipped.
  std::vector<double> y;
  bool line = true;             // join the points in order.
  double marker_radius = 0.0;   // a dot at every point, in pixels; 0 = none.
  bool hollow_markers = false;  // rings instead of filled dots (to mark points over others).
  std::string color{};          // CSS colour; "" = the palette's colour of the series' position.
  std::vector<std::string> tips{};  // optional tooltip per point (on its dot).
  // Indices of points that start a new line: the point is not joined to the one before it (a
  // series interrupted by another, e.g. one phase's records between the other phase's stages).
  std::vector<size_t> breaks{};
};

struct LineChart {
  std::string title;    // above the plot.
  std::string x_label;  // under the x axis.
  std::string y_label;  // beside the y axis.
  bool log_y = false;   // logarithmic y axis (non-positive values are skipped).
  int width = 640;      // pixels.
  int height = 320;     // pixels.
  std::vector<LineSeries> series;
  // Free space beyond the data on each side, fraction of its range, [0, 1]; it does not take a
  // non-negative linear axis below 0.
  double margin = 0.0;
};

// The chart as an <svg> element (with a legend and axis ticks).
std::string LineChartSvg(const LineChart& chart);

}  // namespace sft

#endif  // SFT_EVAL_LINE_CHART_H_
