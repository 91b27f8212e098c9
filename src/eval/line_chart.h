// Line charts as inline SVG for the HTML reports: several series of (x, y) points, optionally
// with a logarithmic y axis (cost curves span decades).
#ifndef SFT_EVAL_LINE_CHART_H_
#define SFT_EVAL_LINE_CHART_H_

#include <string>
#include <vector>

namespace sft {

struct LineSeries {
  std::string name;       // legend entry.
  std::vector<double> x;  // same length as y; non-finite points are skipped.
  std::vector<double> y;
};

struct LineChart {
  std::string title;    // above the plot.
  std::string x_label;  // under the x axis.
  std::string y_label;  // beside the y axis.
  bool log_y = false;   // logarithmic y axis (non-positive values are skipped).
  int width = 640;      // pixels.
  int height = 320;     // pixels.
  std::vector<LineSeries> series;
};

// The chart as an <svg> element (with a legend and axis ticks).
std::string LineChartSvg(const LineChart& chart);

}  // namespace sft

#endif  // SFT_EVAL_LINE_CHART_H_
