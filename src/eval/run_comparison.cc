#include "src/eval/run_comparison.h"

#include <cstdio>
#include <nlohmann/json.hpp>

#include "src/core/file_util.h"
#include "src/eval/line_chart.h"
#include "src/eval/report.h"

namespace sft {

using json = nlohmann::json;

Status CompareRuns(const std::vector<std::string>& runs, const std::vector<std::string>& labels,
                   const std::string& out) {
  if (runs.empty() || runs.size() != labels.size()) {
    return Status::Error("--runs/--labels: need one label per run and at least one run");
  }
  LineChart cost{"objective against wall time", "seconds", "cost ½Σr²", true, 640, 320, {}};
  LineChart chamfer{"Chamfer distance against wall time (after each outer iteration)",
                    "seconds",
                    "Chamfer / diagonal",
                    true,
                    640,
                    320,
                    {}};
  LineChart f1{"F1 against wall time", "seconds", "F1", false, 640, 320, {}};
  std::string csv = "run,kind,outer,seconds,cost,chamfer,f1\n";
  std::vector<std::vector<std::string>> table;
  char line[256];
  for (size_t r = 0; r < runs.size(); ++r) {
    const std::string path = JoinPath(runs[r], "metrics.json");
    std::string text;
    SFT_RETURN_IF_ERROR(ReadTextFile(path, &text));
    const json metrics = json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (metrics.is_discarded() || !metrics.is_object() || !metrics.contains("iterations")) {
      return Status::Error(path + ": not the metrics.json of sft reconstruct");
    }
    LineSeries c{labels[r], {}, {}}, ch{labels[r], {}, {}}, f{labels[r], {}, {}};
    for (const json& it : metrics["iterations"]) {
      if (!it.value("accepted", false)) continue;
      c.x.push_back(it.value("seconds", 0.0));
      c.y.push_back(it.value("cost", 0.0));
      std::snprintf(line, sizeof(line), "%s,iteration,%d,%.3f,%.9g,,\n", labels[r].c_str(),
                    it.value("outer", 0), c.x.back(), c.y.back());
      csv += line;
    }
    double last_chamfer = -1, last_f1 = -1, last_seconds = 0, last_cost = 0;
    if (metrics.contains("outer") && metrics["outer"].is_array()) {
      for (const json& o : metrics["outer"]) {
        last_seconds = o.value("seconds", 0.0);
        last_cost = o.value("cost", 0.0);
        last_chamfer = o.value("chamfer", -1.0);
        last_f1 = o.value("f1", -1.0);
        if (last_chamfer >= 0) {
          ch.x.push_back(last_seconds);
          ch.y.push_back(last_chamfer);
          f.x.push_back(last_seconds);
          f.y.push_back(last_f1);
        }
        std::snprintf(line, sizeof(line), "%s,outer,%d,%.3f,%.9g,", labels[r].c_str(),
                      o.value("outer", 0), last_seconds, last_cost);
        csv += line;
        // Without --reference the run has no Chamfer or F1: empty fields, not a sentinel value
        // that a plot or spreadsheet would take for a measurement.
        if (last_chamfer >= 0) {
          std::snprintf(line, sizeof(line), "%.6g,%.6g", last_chamfer, last_f1);
          csv += line;
        } else {
          csv += ",";
        }
        csv += "\n";
      }
    }
    cost.series.push_back(c);
    chamfer.series.push_back(ch);
    f1.series.push_back(f);
    table.push_back({labels[r], FormatNumber(last_seconds), FormatNumber(last_cost),
                     last_chamfer >= 0 ? FormatNumber(last_chamfer) : "n/a",
                     last_f1 >= 0 ? FormatNumber(last_f1) : "n/a"});
  }
  SFT_RETURN_IF_ERROR(MakeDirectories(out));
  SFT_RETURN_IF_ERROR(WriteTextFile(JoinPath(out, "comparison.csv"), csv));
  HtmlReport html(out, "sft compare: " + std::to_string(runs.size()) + " runs");
  html.AddTable({"run", "wall time (s)", "final cost", "final Chamfer", "final F1"}, table);
  html.AddSvg(LineChartSvg(cost));
  html.AddSvg(LineChartSvg(chamfer));
  html.AddSvg(LineChartSvg(f1));
  return html.Write("report.html");
}

}  // namespace sft
