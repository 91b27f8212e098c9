#include "src/eval/report.h"

#include <glog/logging.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "src/core/file_util.h"
#include "src/image/image_io.h"

namespace sft {
namespace {

constexpr char kStyle[] = R"(body{font-family:sans-serif;margin:1.5em;color:#222;background:#fff}
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.5em}
table{border-collapse:collapse;margin:0.5em 0}
td,th{border:1px solid #ccc;padding:0.2em 0.6em;text-align:left;vertical-align:top}
th{background:#f0f0f0}
table.summary td:first-child{font-weight:bold}
div.row{display:flex;flex-wrap:wrap;align-items:flex-start;gap:0.8em;margin:0.6em 0;
padding:0.4em 0;border-top:1px solid #ddd}
div.label{font-weight:bold;width:100%}
figure{margin:0}figcaption{font-size:0.85em;text-align:center}
img{image-rendering:pixelated;background:#000;display:block}
div.missing{background:#eee;color:#888;display:flex;align-items:center;justify-content:center}
table.notes{font-size:0.9em}
svg{display:block;margin:0.5em 0}
)";

// Percent-encodes everything but unreserved URL characters and '/', for src attributes.
std::string UrlPathEscape(const std::string& path) {
  static const char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : path) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~' || c == '/') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

// A number for SVG coordinates.
std::string Coord(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f", v);
  return buffer;
}

// 1, 2 or 5 times a power of ten, at least `raw` (> 0).
double NiceStep(double raw) {
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= raw * (1.0 - 1e-9)) return m * power;
  }
  return 10.0 * power;
}

Status CheckImageFile(const std::string& file) {
  if (file.empty()) return Status::Error("report image: empty file name");
  if (file[0] == '/') return Status::Error("report image " + file + ": must be relative");
  if (file.find("..") != std::string::npos) {
    return Status::Error("report image " + file + ": must not contain '..'");
  }
  if (FileExtension(file) != "png") return Status::Error("report image " + file + ": not .png");
  return Status::Ok();
}

}  // namespace

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string FormatNumber(double value, int significant) {
  if (!std::isfinite(value)) return "n/a";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", significant, value);
  return buffer;
}

HtmlReport::HtmlReport(std::string dir, std::string title, HtmlReportOptions options)
    : dir_(std::move(dir)), title_(std::move(title)), options_(options) {}

void HtmlReport::AddHeading(const std::string& text) {
  body_ += "<h2>" + HtmlEscape(text) + "</h2>\n";
}

void HtmlReport::AddParagraph(const std::string& text) {
  body_ += "<p>" + HtmlEscape(text) + "</p>\n";
}

void HtmlReport::AddSummaryTable(const std::vector<std::pair<std::string, std::string>>& rows) {
  body_ += "<table class=\"summary\">\n";
  for (const auto& [key, value] : rows) {
    body_ += "<tr><td>" + HtmlEscape(key) + "</td><td>" + HtmlEscape(value) + "</td></tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::AddTable(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows) {
  body_ += "<table>\n<tr>";
  for (const std::string& h : header) body_ += "<th>" + HtmlEscape(h) + "</th>";
  body_ += "</tr>\n";
  for (const std::vector<std::string>& row : rows) {
    body_ += "<tr>";
    const size_t cells = std::max(row.size(), header.size());
    for (size_t i = 0; i < cells; ++i) {
      body_ += "<td>" + (i < row.size() ? HtmlEscape(row[i]) : std::string()) + "</td>";
    }
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::AddBarChart(const BarChart& chart) { body_ += BarChartSvg(chart); }

void HtmlReport::AddSvg(const std::string& svg) { body_ += svg; }

void HtmlReport::AddHtml(const std::string& markup) { body_ += markup + "\n"; }

Status HtmlReport::WriteImage(const std::string& file, const Image& image) {
  SFT_RETURN_IF_ERROR(CheckImageFile(file));
  CHECK(!image.empty()) << file;
  SFT_RETURN_IF_ERROR(WritePng(JoinPath(dir_, file), ScaledRgb(image, 1.0)));
  sizes_[file] = {image.width, image.height};
  return Status::Ok();
}

Status HtmlReport::AddImageRow(const ImageRow& row) {
  for (const ReportImage& cell : row.images) {
    if (cell.image != nullptr) {
      SFT_RETURN_IF_ERROR(WriteImage(cell.file, *cell.image));
    } else if (!cell.file.empty()) {
      SFT_RETURN_IF_ERROR(CheckImageFile(cell.file));
      if (!FileExists(JoinPath(dir_, cell.file))) {
        return Status::Error("report image " + JoinPath(dir_, cell.file) + ": not written");
      }
    }
  }
  // Display size: thumbnail_width wide, the aspect of the row's first image of known size
  // (placeholders too); square when none is known.
  double aspect = 1.0;
  for (const ReportImage& cell : row.images) {
    const auto it = sizes_.find(cell.file);
    if (!cell.file.empty() && it != sizes_.end() && it->second.first > 0) {
      aspect = static_cast<double>(it->second.second) / it->second.first;
      break;
    }
  }
  const int width = options_.thumbnail_width;
  const int height = std::max(1, static_cast<int>(std::lround(width * aspect)));
  std::string html = "<div class=\"row\">\n";
  if (!row.label.empty()) html += "<div class=\"label\">" + HtmlEscape(row.label) + "</div>\n";
  for (const ReportImage& cell : row.images) {
    html += "<figure>";
    if (!cell.file.empty()) {
      html += "<img src=\"" + HtmlEscape(UrlPathEscape(cell.file)) + "\" width=\"" +
              std::to_string(width) + "\" alt=\"" + HtmlEscape(cell.caption) + "\">";
    } else {
      html += "<div class=\"missing\" style=\"width:" + std::to_string(width) +
              "px;height:" + std::to_string(height) + "px\">n/a</div>";
    }
    html += "<figcaption>" + HtmlEscape(cell.caption) + "</figcaption></figure>\n";
  }
  if (!row.notes.empty()) {
    html += "<table class=\"notes\">\n";
    for (const auto& [key, value] : row.notes) {
      html += "<tr><td>" + HtmlEscape(key) + "</td><td>" + HtmlEscape(value) + "</td></tr>\n";
    }
    html += "</table>\n";
  }
  html += "</div>\n";
  body_ += html;
  return Status::Ok();
}

std::string HtmlReport::Html() const {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         HtmlEscape(title_) + "</title>\n<style>\n" + kStyle + "</style>\n</head>\n<body>\n<h1>" +
         HtmlEscape(title_) + "</h1>\n" + body_ + "</body>\n</html>\n";
}

Status HtmlReport::Write(const std::string& file_name) const {
  return WriteTextFile(JoinPath(dir_, file_name), Html());
}

std::string BarChartSvg(const BarChart& chart) {
  CHECK_EQ(chart.labels.size(), chart.values.size());
  const double width = std::max(chart.width, 160), height = std::max(chart.height, 120);
  const double left = 64, right = 16, top = 30, bottom = 40;
  const double plot_w = width - left - right, plot_h = height - top - bottom;
  const size_t n = chart.values.size();
  const bool has_reference = std::isfinite(chart.reference_value);
  double lo = 0.0, hi = 0.0;
  bool any = false;
  for (double v : chart.values) {
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    any = true;
  }
  if (has_reference) {
    lo = std::min(lo, chart.reference_value);
    hi = std::max(hi, chart.reference_value);
  }
  if (!(hi > lo)) hi = lo + 1.0;
  const double step = NiceStep((hi - lo) / 5.0);
  const double axis_lo = std::floor(lo / step + 1e-9) * step;
  const double axis_hi = std::ceil(hi / step - 1e-9) * step;
  auto y_of = [&](double v) { return top + plot_h * (axis_hi - v) / (axis_hi - axis_lo); };

  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + Coord(width) +
                    "\" height=\"" + Coord(height) + "\" viewBox=\"0 0 " + Coord(width) + " " +
                    Coord(height) + "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  svg += "<title>" + HtmlEscape(chart.title) + "</title>\n";
  svg += "<text x=\"" + Coord(width / 2) + "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\" " +
         "font-weight=\"bold\">" + HtmlEscape(chart.title) + "</text>\n";
  // Value axis: grid lines and tick labels.
  for (int i = 0;; ++i) {
    double tick = axis_lo + i * step;
    if (tick > axis_hi + 0.5 * step) break;
    if (std::abs(tick) < 1e-9 * step) tick = 0.0;
    const std::string y = Coord(y_of(tick));
    svg += "<line x1=\"" + Coord(left) + "\" y1=\"" + y + "\" x2=\"" + Coord(left + plot_w) +
           "\" y2=\"" + y + "\" stroke=\"#e4e4e4\"/>\n";
    svg += "<text x=\"" + Coord(left - 4) + "\" y=\"" + y +
           "\" text-anchor=\"end\" dominant-baseline=\"middle\">" + FormatNumber(tick, 3) +
           "</text>\n";
  }
  svg += "<text transform=\"translate(12 " + Coord(top + plot_h / 2) +
         ") rotate(-90)\" text-anchor=\"middle\">" + HtmlEscape(chart.y_label) + "</text>\n";
  // Bars, with the value in a tooltip; labels thinned to one per ~28 px.
  const double slot = n > 0 ? plot_w / n : plot_w;
  const size_t label_every =
      std::max<size_t>(1, static_cast<size_t>(std::ceil(28.0 * n / std::max(plot_w, 1.0))));
  const double zero_y = y_of(0.0);
  for (size_t i = 0; i < n; ++i) {
    const double v = chart.values[i];
    const double x = left + i * slot;
    if (std::isfinite(v)) {
      const double y = y_of(v);
      svg += "<rect x=\"" + Coord(x + 0.15 * slot) + "\" y=\"" + Coord(std::min(y, zero_y)) +
             "\" width=\"" + Coord(std::max(0.7 * slot, 0.5)) + "\" height=\"" +
             Coord(std::abs(zero_y - y)) + "\" fill=\"#4a7ab5\"><title>" +
             HtmlEscape(chart.labels[i]) + ": " + FormatNumber(v) + "</title></rect>\n";
    } else {
      svg += "<text x=\"" + Coord(x + 0.5 * slot) + "\" y=\"" + Coord(zero_y - 3) +
             "\" text-anchor=\"middle\" fill=\"#999\" font-size=\"9\">n/a</text>\n";
    }
    if (i % label_every == 0) {
      svg += "<text x=\"" + Coord(x + 0.5 * slot) + "\" y=\"" + Coord(top + plot_h + 14) +
             "\" text-anchor=\"middle\">" + HtmlEscape(chart.labels[i]) + "</text>\n";
    }
  }
  if (!chart.x_label.empty()) {
    svg += "<text x=\"" + Coord(left + plot_w / 2) + "\" y=\"" + Coord(height - 6) +
           "\" text-anchor=\"middle\">" + HtmlEscape(chart.x_label) + "</text>\n";
  }
  if (!any) {
    svg += "<text x=\"" + Coord(left + plot_w / 2) + "\" y=\"" + Coord(top + plot_h / 2) +
           "\" text-anchor=\"middle\" fill=\"#999\">no data</text>\n";
  }
  // Axes.
  svg += "<line x1=\"" + Coord(left) + "\" y1=\"" + Coord(top) + "\" x2=\"" + Coord(left) +
         "\" y2=\"" + Coord(top + plot_h) + "\" stroke=\"#444\"/>\n";
  svg += "<line x1=\"" + Coord(left) + "\" y1=\"" + Coord(zero_y) + "\" x2=\"" +
         Coord(left + plot_w) + "\" y2=\"" + Coord(zero_y) + "\" stroke=\"#444\"/>\n";
  if (has_reference) {
    const std::string y = Coord(y_of(chart.reference_value));
    svg += "<line x1=\"" + Coord(left) + "\" y1=\"" + y + "\" x2=\"" + Coord(left + plot_w) +
           "\" y2=\"" + y + "\" stroke=\"#c0392b\" stroke-dasharray=\"5 3\"/>\n";
    svg += "<text x=\"" + Coord(left + plot_w - 2) + "\" y=\"" +
           Coord(y_of(chart.reference_value) - 4) + "\" text-anchor=\"end\" fill=\"#c0392b\">" +
           HtmlEscape(chart.reference_label) + " " + FormatNumber(chart.reference_value) +
           "</text>\n";
  }
  svg += "</svg>\n";
  return svg;
}

double ExposureScale(const Image& image, const Image* mask, double percentile) {
  CHECK_GE(percentile, 0.0);
  CHECK_LE(percentile, 1.0);
  const bool use_mask = mask != nullptr && !mask->empty();
  if (use_mask) {
    CHECK_EQ(mask->width, image.width);
    CHECK_EQ(mask->height, image.height);
  }
  const int colour = std::min(image.channels, 3);
  std::vector<float> values;
  values.reserve(static_cast<size_t>(image.width) * image.height * colour);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (use_mask && mask->at(x, y) <= 0.5f) continue;
      for (int c = 0; c < colour; ++c) {
        const float v = image.at(x, y, c);
        if (std::isfinite(v)) values.push_back(v);
      }
    }
  }
  if (values.empty()) return 1.0;
  const size_t k = static_cast<size_t>(std::floor(percentile * (values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  double level = values[k];
  if (!(level > 0.0)) level = *std::max_element(values.begin() + k, values.end());
  return level > 0.0 ? 1.0 / level : 1.0;
}

Image ScaledRgb(const Image& image, double scale) {
  CHECK(image.channels == 1 || image.channels >= 3) << image.channels << " channels";
  Image out(image.width, image.height, 3);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        out.at(x, y, c) = static_cast<float>(scale * image.at(x, y, image.channels == 1 ? 0 : c));
      }
    }
  }
  return out;
}

Image AbsDifferenceRgb(const Image& a, const Image& b, double scale) {
  CHECK_EQ(a.width, b.width);
  CHECK_EQ(a.height, b.height);
  const Image ra = ScaledRgb(a, 1.0), rb = ScaledRgb(b, 1.0);
  Image out(a.width, a.height, 3);
  for (size_t i = 0; i < out.data.size(); ++i) {
    out.data[i] = static_cast<float>(scale * std::abs(ra.data[i] - rb.data[i]));
  }
  return out;
}

}  // namespace sft
