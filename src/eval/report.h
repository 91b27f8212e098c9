// Self-contained HTML reports for long commands (the "human report" of the project standard):
// a title, summary tables, rows of images (PNG files written next to the HTML and referenced by
// relative paths) and simple inline SVG plots. No external resources (the style sheet is inline;
// the one script, the 3D view of model_viewer.h, is copied into the report's folder), so the
// report directory can be copied or archived as is. All text is
// HTML-escaped. The page is written atomically (WriteTextFile), as are the images (WritePng).
//
// Usage:
//   HtmlReport report("out", "sft render");
//   report.AddSummaryTable({{"views", "8"}, {"spp", "64"}});
//   report.AddBarChart(chart);
//   SFT_RETURN_IF_ERROR(report.AddImageRow(row));  // writes the row's PNGs under out/
//   SFT_RETURN_IF_ERROR(report.Write());           // out/report.html
#ifndef SFT_EVAL_REPORT_H_
#define SFT_EVAL_REPORT_H_

#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "src/core/image.h"
#include "src/core/status.h"

namespace sft {

// Escapes & < > " ' for HTML/SVG text and attribute values.
std::string HtmlEscape(const std::string& text);

// A number for humans: `significant` significant digits ("%.*g"); "n/a" when not finite.
std::string FormatNumber(double value, int significant = 4);

// One image of an image row. Three kinds: `image` set: AddImageRow writes it to `file`; `image`
// null and `file` set: a PNG already written (HtmlReport::WriteImage), so that rows can be added
// after the pixels are gone; both empty: a grey "n/a" placeholder with the caption.
struct ReportImage {
  std::string file;              // PNG path relative to the report directory ("x/0_target.png").
  std::string caption;           // shown under the image.
  const Image* image = nullptr;  // not owned; see above.
};

// A labelled row of images, e.g. one view's target, render and difference.
struct ImageRow {
  std::string label;                                       // the row's heading.
  std::vector<ReportImage> images;                         // left to right.
  std::vector<std::pair<std::string, std::string>> notes;  // key/value lines beside the images.
};

// A bar chart of one value per item (e.g. a per-view metric), drawn as inline SVG.
struct BarChart {
  std::string title;                // above the plot.
  std::string x_label;              // the item axis' name (under the labels).
  std::string y_label;              // the value axis' name.
  std::vector<std::string> labels;  // one per bar, under it (thinned out when crowded).
  std::vector<double> values;       // one per bar; non-finite = no bar, "n/a" in its tooltip.
  // A dashed horizontal line (e.g. the mean or a threshold); none when not finite.
  double reference_value = std::numeric_limits<double>::quiet_NaN();
  std::string reference_label;  // the line's label.
  int width = 640;              // SVG size in CSS pixels.
  int height = 260;
};

// Options of an HtmlReport.
struct HtmlReportOptions {
  int thumbnail_width = 256;  // display width of row images in CSS pixels (nearest-neighbour).
};

class HtmlReport {
 public:
  // `dir`: the report's directory (created on demand); `title`: the page title and heading.
  HtmlReport(std::string dir, std::string title, HtmlReportOptions options = HtmlReportOptions());

  const std::string& dir() const { return dir_; }

  void AddHeading(const std::string& text);
  void AddParagraph(const std::string& text);
  // A two-column key/value table.
  void AddSummaryTable(const std::vector<std::pair<std::string, std::string>>& rows);
  // A table with a header row; rows shorter than the header are padded with empty cells.
  void AddTable(const std::vector<std::string>& header,
                const std::vector<std::vector<std::string>>& rows);
  void AddBarChart(const BarChart& chart);
  // Appends an inline <svg> element made by this program (e.g. LineChartSvg); not escaped.
  void AddSvg(const std::string& svg);
  // Appends markup made by this program (e.g. the 3D view of model_viewer.h); not escaped.
  void AddHtml(const std::string& markup);
  // Writes `image` as an 8-bit sRGB-encoded PNG (colour clamped to [0, 1]; alpha dropped, so
  // thumbnails show on black) to dir/file, atomically. Errors: a file that is empty, absolute,
  // contains "..", or does not end in ".png"; a failed write.
  Status WriteImage(const std::string& file, const Image& image);
  // Writes the row's images that have pixels (WriteImage) and adds the row. Errors as WriteImage,
  // and a referenced `file` that does not exist.
  Status AddImageRow(const ImageRow& row);

  // The complete page.
  std::string Html() const;
  // Writes Html() to dir/file_name atomically.
  Status Write(const std::string& file_name = "report.html") const;

 private:
  std::string dir_;
  std::string title_;
  HtmlReportOptions options_;
  std::string body_;
  std::map<std::string, std::pair<int, int>> sizes_;  // width, height of each written image.
};

// The SVG markup of `chart` (what AddBarChart embeds).
std::string BarChartSvg(const BarChart& chart);

// Exposure for thumbnails of linear images: 1 / the `percentile` (in [0, 1]) of the RGB values of
// `image` over the pixels where `mask` (1 channel, same size) is > 0.5, or over all pixels when
// `mask` is null or empty. Falls back to 1 / max when that percentile is 0, and to 1 for a black
// image.
double ExposureScale(const Image& image, const Image* mask, double percentile = 0.99);

// `image`'s RGB times `scale` (a grey image is replicated to RGB; alpha is dropped).
Image ScaledRgb(const Image& image, double scale);

// |a − b| per RGB channel times `scale`; `a` and `b` have equal sizes and ≥ 3 channels (or 1).
Image AbsDifferenceRgb(const Image& a, const Image& b, double scale);

// The reports' |render − target| thumbnails are this much brighter than the images they compare.
constexpr int kDifferenceGain = 4;

}  // namespace sft

#endif  // SFT_EVAL_REPORT_H_
