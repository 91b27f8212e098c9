// Line charts as SVG (src/eval/line_chart.h): lines, dots with tooltips, rings, margins.
#include "src/eval/line_chart.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace sft {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (size_t p = text.find(needle); p != std::string::npos; p = text.find(needle, p + 1)) ++n;
  return n;
}

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
  EXPECT_EQ(Count(svg, "<polyline"), 0);
  EXPECT_EQ(Count(svg, "<circle"), 3 + 1 + 2);  // dots, ring, two legend marks.
  EXPECT_THAT(svg, HasSubstr("<title>a&lt;1&gt;</title>"));
  EXPECT_THAT(svg, HasSubstr("r=\"7.0\" fill=\"none\" stroke=\"#d62728\""));
  // A plain line chart keeps its polyline and draws no dots.
  LineChart plain;
  plain.series = {LineSeries{"cost", {1, 2}, {3, 4}}};
  const std::string line_svg = LineChartSvg(plain);
  EXPECT_EQ(Count(line_svg, "<polyline"), 1);
  EXPECT_THAT(line_svg, Not(HasSubstr("<circle")));
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
