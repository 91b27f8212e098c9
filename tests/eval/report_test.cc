// The HTML report library, and the report `sft render` writes (comparison with the Cycles images).
#include "src/eval/report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"
#include "src/image/image_io.h"
#include "tests/testing/temp_dir.h"

namespace sft {
namespace {

using testing::CountLines;
using testing::RunSft;

using ::testing::HasSubstr;
using ::testing::Not;

int CountOccurrences(const std::string& text, const std::string& needle) {
  int count = 0;
  for (size_t pos = text.find(needle); pos != std::string::npos;
       pos = text.find(needle, pos + needle.size())) {
    ++count;
  }
  return count;
}

std::vector<std::string> ListFiles(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) {
      files.push_back(std::filesystem::relative(entry.path(), dir).string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(ReportTest, HtmlEscapeAndFormat) {
  EXPECT_EQ(HtmlEscape("a<b>&\"c\"'d'"), "a&lt;b&gt;&amp;&quot;c&quot;&#39;d&#39;");
  EXPECT_EQ(HtmlEscape("plain"), "plain");
  EXPECT_EQ(FormatNumber(0.0123456), "0.01235");
  EXPECT_EQ(FormatNumber(std::nan("")), "n/a");
  EXPECT_EQ(FormatNumber(12, 3), "12");
}

TEST(ReportTest, PageWithTableRowsAndChart) {
  testing::TempDir tmp;
  const std::string dir = tmp.Join("out");
  HtmlReport report(dir, "Title <with> & markup");
  report.AddSummaryTable({{"views", "2"}, {"mesh", "<script>alert(1)</script>"}});
  report.AddTable({"a", "b"}, {{"1", "2"}, {"only"}});
  BarChart chart;
  chart.title = "error & bias";
  chart.x_label = "view";
  chart.y_label = "relative";
  chart.labels = {"0", "1", "2"};
  chart.values = {0.01, std::nan(""), 0.03};
  chart.reference_value = 0.02;
  chart.reference_label = "mean";
  report.AddBarChart(chart);

  Image red(4, 2, 3), grey(4, 2, 1, 0.5f);
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) red.at(x, y, 0) = 1.0f;
  }
  ImageRow row0;
  row0.label = "view 0 <a>";
  row0.images = {{"files/v0_red.png", "red", &red}, {"files/v0_grey.png", "grey", &grey}};
  row0.notes = {{"error", "0.01"}};
  ASSERT_TRUE(report.AddImageRow(row0).ok());
  // A row referring to an image written earlier, and a placeholder.
  ASSERT_TRUE(report.WriteImage("files/v1 pre.png", grey).ok());
  ImageRow row1;
  row1.label = "view 1";
  row1.images = {{"files/v1 pre.png", "pre-written", nullptr}, {"", "target: missing", nullptr}};
  ASSERT_TRUE(report.AddImageRow(row1).ok());
  ASSERT_TRUE(report.Write().ok());

  std::string html;
  ASSERT_TRUE(ReadTextFile(dir + "/report.html", &html).ok());
  EXPECT_EQ(html, report.Html());
  EXPECT_THAT(html, HasSubstr("<!DOCTYPE html>"));
  EXPECT_THAT(html, HasSubstr("<title>Title &lt;with&gt; &amp; markup</title>"));
  EXPECT_THAT(html, HasSubstr("&lt;script&gt;alert(1)&lt;/script&gt;"));
  EXPECT_THAT(html, Not(HasSubstr("<script")));
  EXPECT_THAT(html, HasSubstr("view 0 &lt;a&gt;"));
  EXPECT_THAT(html, HasSubstr("<td>only</td><td></td>"));
  // Images referenced relatively (URL-escaped), two rows, one placeholder.
  EXPECT_THAT(html, HasSubstr("src=\"files/v0_red.png\""));
  EXPECT_THAT(html, HasSubstr("src=\"files/v0_grey.png\""));
  EXPECT_THAT(html, HasSubstr("src=\"files/v1%20pre.png\""));
  EXPECT_EQ(CountOccurrences(html, "<img "), 3);
  EXPECT_EQ(CountOccurrences(html, "<div class=\"row\">"), 2);
  EXPECT_EQ(CountOccurrences(html, "class=\"missing\""), 1);
  EXPECT_THAT(html, HasSubstr("target: missing"));
  // The chart: inline SVG, two bars (the NaN is n/a), the reference line, escaped title.
  EXPECT_EQ(CountOccurrences(html, "<svg "), 1);
  EXPECT_EQ(CountOccurrences(html, "<rect "), 2);
  EXPECT_THAT(html, HasSubstr("error &amp; bias"));
  EXPECT_THAT(html, HasSubstr("stroke-dasharray"));
  EXPECT_THAT(html, HasSubstr("mean 0.02"));
  // Self-contained: no scripts, no remote resources.
  EXPECT_THAT(html, Not(HasSubstr("src=\"http")));
  EXPECT_THAT(html, Not(HasSubstr("href=")));
  EXPECT_THAT(html, Not(HasSubstr("<link")));

  // The files exist, and atomic writes left no temporary files behind.
  EXPECT_EQ(ListFiles(dir), (std::vector<std::string>{"files/v0_grey.png", "files/v0_red.png",
                                                      "files/v1 pre.png", "report.html"}));
  Image read;
  ASSERT_TRUE(ReadImage(dir + "/files/v0_red.png", &read).ok());
  EXPECT_EQ(read.width, 4);
  EXPECT_EQ(read.height, 2);
  ASSERT_EQ(read.channels, 3);
  EXPECT_NEAR(read.at(1, 1, 0), 1.0f, 1e-3);
  EXPECT_NEAR(read.at(1, 1, 1), 0.0f, 1e-3);
  ASSERT_TRUE(ReadImage(dir + "/files/v0_grey.png", &read).ok());
  EXPECT_NEAR(read.at(0, 0, 2), 0.5f, 0.01);  // sRGB-encoded on write, decoded on read.
}

TEST(ReportTest, BadImageNamesAreErrors) {
  testing::TempDir tmp;
  HtmlReport report(tmp.path(), "t");
  const Image image(2, 2, 3);
  EXPECT_FALSE(report.WriteImage("", image).ok());
  EXPECT_FALSE(report.WriteImage("/abs.png", image).ok());
  EXPECT_FALSE(report.WriteImage("../up.png", image).ok());
  EXPECT_FALSE(report.WriteImage("x.jpg", image).ok());
  ImageRow row;
  row.images = {{"never_written.png", "x", nullptr}};
  const Status status = report.AddImageRow(row);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("never_written.png"));
  EXPECT_TRUE(ListFiles(tmp.path()).empty());
}

TEST(ReportTest, EmptyChartSaysNoData) {
  BarChart chart;
  chart.title = "nothing";
  const std::string svg = BarChartSvg(chart);
  EXPECT_THAT(svg, HasSubstr("no data"));
  EXPECT_EQ(CountOccurrences(svg, "<rect "), 0);
}

TEST(ReportTest, ExposureAndDifference) {
  Image image(10, 10, 4, 0.0f), mask(10, 10, 1, 0.0f);
  // Object: the left half, values 1..50 per pixel (all three channels); background is 0.
  int k = 0;
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 5; ++x) {
      ++k;
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(k);
      mask.at(x, y) = 1.0f;
    }
  }
  // 150 object values; the 99th percentile (index floor(0.99 * 149) = 147) is 50.
  EXPECT_NEAR(ExposureScale(image, &mask), 1.0 / 50.0, 1e-12);
  EXPECT_NEAR(ExposureScale(image, &mask, 0.0), 1.0, 1e-12);
  // Over all pixels half the values are 0: the 40th percentile is 0, so the fallback (max) applies.
  EXPECT_NEAR(ExposureScale(image, nullptr, 0.4), 1.0 / 50.0, 1e-12);
  EXPECT_EQ(ExposureScale(Image(3, 3, 3, 0.0f), nullptr), 1.0);

  const Image scaled = ScaledRgb(image, 0.5);
  EXPECT_EQ(scaled.channels, 3);
  EXPECT_FLOAT_EQ(scaled.at(0, 0, 1), 0.5f);
  Image other = image;
  other.at(0, 0, 2) += 2.0f;
  const Image diff = AbsDifferenceRgb(other, image, 4.0);
  EXPECT_FLOAT_EQ(diff.at(0, 0, 2), 8.0f);
  EXPECT_FLOAT_EQ(diff.at(0, 0, 0), 0.0f);
}

const char kBunnyMaterial[] =
    "'{\"albedo\": [0.7, 0.5, 0.3], \"roughness\": 0.5, \"specular\": 0}'";

// `sft render` on a Cycles reference dataset compares each render with the Cycles image (the
// Cycles agreement, measured by the CLI) and writes report.html with the thumbnails.
TEST(RenderReportTest, ComparesWithCyclesAndWritesReport) {
  testing::TempDir tmp;
  const std::string ds = testing::DataDir() + "/cycles/bunny_point_diffuse";
  const std::string out_dir = tmp.Join("r");
  std::string out;
  ASSERT_EQ(RunSft("render --quiet --dataset " + ds + " --mesh " + ds + "/gt/mesh.ply --material " +
                       kBunnyMaterial + " --spp 16 --bounces 1 --views 0,1 --out " + out_dir,
                   &out),
            0)
      << out;
  std::string text;
  ASSERT_TRUE(ReadTextFile(out_dir + "/render.json", &text).ok());
  const nlohmann::json json = nlohmann::json::parse(text);
  ASSERT_EQ(json["views"].size(), 2u);
  for (const nlohmann::json& view : json["views"]) {
    ASSERT_TRUE(view["comparison"].is_object()) << view.dump();
    const nlohmann::json& c = view["comparison"];
    std::printf("view %d: relative mean |d| %.4f, bias %+.4f, max block %.4f, %d pixels\n",
                view["view"].get<int>(), c["relative_mean_abs_difference"].get<double>(),
                c["relative_mean_difference"].get<double>(),
                c["max_block_relative_difference"].get<double>(), c["object_pixels"].get<int>());
    EXPECT_LT(c["relative_mean_abs_difference"].get<double>(), 0.02) << view.dump();
    EXPECT_LT(std::abs(c["relative_mean_difference"].get<double>()), 0.02) << view.dump();
    EXPECT_GT(c["object_pixels"].get<int>(), 500);
    EXPECT_TRUE(c.contains("max_block_relative_difference"));
    EXPECT_EQ(c["mask"], "masks/00" + std::to_string(view["view"].get<int>()) + ".png");
  }
  ASSERT_TRUE(json["comparison"].is_object());
  EXPECT_EQ(json["comparison"]["views_compared"], 2);
  EXPECT_LT(json["comparison"]["mean_relative_mean_abs_difference"].get<double>(), 0.02);

  std::string html;
  ASSERT_TRUE(ReadTextFile(out_dir + "/report.html", &html).ok());
  EXPECT_EQ(CountOccurrences(html, "<div class=\"row\">"), 2);
  EXPECT_EQ(CountOccurrences(html, "<svg "), 1);
  for (const char* name : {"target", "render", "difference"}) {
    for (int v = 0; v < 2; ++v) {
      const std::string file = "report_files/view_00" + std::to_string(v) + "_" + name + ".png";
      EXPECT_THAT(html, HasSubstr("src=\"" + file + "\""));
      Image png;
      ASSERT_TRUE(ReadImage(out_dir + "/" + file, &png).ok()) << file;
      EXPECT_EQ(png.width, 128);
      EXPECT_EQ(png.channels, 3);
    }
  }
  for (const std::string& file : ListFiles(out_dir)) {
    EXPECT_THAT(file, Not(HasSubstr(".tmp"))) << "left-over temporary file";
  }
}

// A missing target never fails the render: that view gets "comparison": null and the reason;
// --no-report writes neither comparison nor report.
TEST(RenderReportTest, MissingTargetAndNoReport) {
  testing::TempDir tmp;
  const std::string src = testing::DataDir() + "/cycles/bunny_point_diffuse";
  const std::string ds = tmp.Join("ds");
  std::filesystem::create_directories(ds + "/images");
  std::filesystem::create_directories(ds + "/masks");
  std::filesystem::copy_file(src + "/scene.json", ds + "/scene.json");
  std::filesystem::copy_file(src + "/images/000.exr", ds + "/images/000.exr");
  std::filesystem::copy_file(src + "/masks/000.png", ds + "/masks/000.png");
  testing::WriteTestFile(ds + "/images/001.exr", "not an exr");
  const std::string common = "render --quiet --dataset " + ds + " --mesh " + src +
                             "/gt/mesh.ply --material " + kBunnyMaterial +
                             " --spp 4 --bounces 1 --views 0,1,2 --out ";
  std::string out;
  ASSERT_EQ(RunSft(common + tmp.Join("r"), &out), 0) << out;
  std::string text;
  ASSERT_TRUE(ReadTextFile(tmp.Join("r/render.json"), &text).ok());
  const nlohmann::json json = nlohmann::json::parse(text);
  ASSERT_EQ(json["views"].size(), 3u);
  EXPECT_TRUE(json["views"][0]["comparison"].is_object());
  for (int v : {1, 2}) {
    const nlohmann::json& view = json["views"][v];
    EXPECT_TRUE(view["comparison"].is_null()) << view.dump();
    EXPECT_THAT(view["comparison_skipped"].get<std::string>(),
                HasSubstr("00" + std::to_string(v) + ".exr"));
  }
  EXPECT_EQ(json["comparison"]["views_compared"], 1);
  std::string html;
  ASSERT_TRUE(ReadTextFile(tmp.Join("r/report.html"), &html).ok());
  EXPECT_EQ(CountOccurrences(html, "<div class=\"row\">"), 3);
  EXPECT_EQ(CountOccurrences(html, "class=\"missing\""), 2);
  EXPECT_TRUE(FileExists(tmp.Join("r/report_files/view_002_render.png")));

  ASSERT_EQ(RunSft(common + tmp.Join("n") + " --no-report", &out), 0) << out;
  ASSERT_TRUE(ReadTextFile(tmp.Join("n/render.json"), &text).ok());
  const nlohmann::json plain = nlohmann::json::parse(text);
  EXPECT_FALSE(plain.contains("comparison"));
  EXPECT_FALSE(plain["views"][0].contains("comparison"));
  EXPECT_FALSE(FileExists(tmp.Join("n/report.html")));
  EXPECT_FALSE(FileExists(tmp.Join("n/report_files")));
}

}  // namespace
}  // namespace sft
