// Line charts as SVG (src/eval/line_chart.h): lines, dots with tooltips, rings, margins.
#include "src/eval/line_chart.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountOccurrences;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(LineChartTest, ScatterSeriesDrawDotsWithTooltips) {
  LineChart chart;
  chart.title = "t";
  LineSeries dots{"cells", {1, 2, 3}, {4, 5, 6}};
  dots.line = false;
  dots.marker_radius = 3;
  dots.tips = {"a<1>", "b", "c"};
  LineSeries ring{"default", {2}, {5}};
  ring.line = false;
  ring.marker_radius = 7;
  ring.hollow_markers = true;
  ring.color = "#d62728";
  chart.series = {dots, ring};
  const std::string svg = LineChartSvg(chart);
  EXPECT_EQ(CountOccurrences(svg, "<polyline"), 0);
  EXPECT_EQ(CountOccurrences(svg, "<circle"), 3 + 1 + 2);  // dots, ring, two legend marks.
  EXPECT_THAT(svg, HasSubstr("<title>a&lt;1&gt;</title>"));
  EXPECT_THAT(svg, HasSubstr("r=\"7.0\" fill=\"none\" stroke=\"#d62728\""));
  // A plain line chart keeps its polyline and draws no dots.
  LineChart plain;
  plain.series = {LineSeries{"cost", {1, 2}, {3, 4}}};
  const std::string line_svg = LineChartSvg(plain);
  EXPECT_EQ(CountOccurrences(line_svg, "<polyline"), 1);
  EXPECT_THAT(line_svg, Not(HasSubstr("<circle")));
}

// A break starts a new polyline at its point: the points before and after it are not joined. A
// break at the first point, or one whose point is not drawn, adds no empty line.
TEST(LineChartTest, BreaksStartNewLines) {
  LineChart chart;
  LineSeries phase{"texture", {1, 2, 5, 6, 9}, {1, 2, 3, 4, 5}};
  phase.breaks = {0, 2, 4};
  chart.series = {phase};
  const std::string svg = LineChartSvg(chart);
  EXPECT_EQ(CountOccurrences(svg, "<polyline"), 3);
  // Two points, two points, one point: each line's points are its own.
  std::vector<int> sizes;
  for (size_t at = svg.find("points=\""); at != std::string::npos;
       at = svg.find("points=\"", at + 1)) {
    const size_t end = svg.find('"', at + 8);
    sizes.push_back(CountOccurrences(svg.substr(at + 8, end - at - 8), ","));
  }
  EXPECT_EQ(sizes, (std::vector<int>{2, 2, 1}));
  LineChart joined = chart;
  joined.series[0].breaks.clear();
  const std::string one = LineChartSvg(joined);
  EXPECT_EQ(CountOccurrences(one, "<polyline"), 1);
  LineChart skipped = chart;
  skipped.series[0].y[2] = std::nan("");  // the break's own point is not drawn.
  EXPECT_EQ(CountOccurrences(LineChartSvg(skipped), "<polyline"), 3);
}

// With a margin, the extreme points sit inside the frame instead of on it.
TEST(LineChartTest, MarginKeepsPointsOffTheFrame) {
  LineChart chart;
  chart.width = 400;
  chart.height = 300;
  LineSeries s{"s", {-2, 10}, {0, 10}};
  s.line = false;
  s.marker_radius = 2;
  chart.series = {s};
  // Frame: x from 70 to 400 - 150 = 250, y from 30 to 300 - 42 = 258.
  EXPECT_THAT(LineChartSvg(chart), HasSubstr("cx=\"70.0\" cy=\"258.0\""));
  chart.margin = 0.1;
  const std::string svg = LineChartSvg(chart);
  EXPECT_THAT(svg, Not(HasSubstr("cx=\"70.0\"")));
  // x: [-2, 10] widens to [-3.2, 11.2]: 70 + 180 · 1.2/14.4 = 85. y: [0, 10] stays at 0 below
  // (non-negative) and widens to 11 above: the lowest point sits on the frame's bottom, 258.
  EXPECT_THAT(svg, HasSubstr("cx=\"85.0\" cy=\"258.0\""));
}

// Tick labels: 3 significant digits on a wide range, enough to tell neighbours apart on a narrow
// one far from zero (equal-budget sweep cells end within a second of 300 s).
TEST(LineChartTest, TickLabelsTellNeighboursApart) {
  LineChart chart;
  chart.series = {LineSeries{"s", {300, 301}, {0, 100}}};
  const std::string svg = LineChartSvg(chart);
  for (const char* tick : {">300<", ">300.25<", ">300.5<", ">300.75<", ">301<"}) {
    EXPECT_THAT(svg, HasSubstr(tick)) << tick;
  }
  EXPECT_THAT(svg, HasSubstr(">25<"));  // the y axis, 0–100: no extra digits.
  EXPECT_THAT(svg, HasSubstr(">75<"));
}

}  // namespace
}  // namespace sft
