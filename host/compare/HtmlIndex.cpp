#include "compare/HtmlIndex.h"

#include <fmt/format.h>

#include "compare/EnvmapPdfComparison.h"
#include "compare/SummaryTables.h"
#include "report/PreviewPng.h"

namespace misalloc {
namespace {

const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 2em; max-width: 1400px; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
th:first-child, td:first-child { text-align: left; }
img.px { image-rendering: pixelated; width: 128px; }
.note { color: #555; max-width: 60em; }
</style>
)";

std::string image(const std::string& path, const std::string& title) {
  return fmt::format(R"(<img class="px" src="{}" title="{}" alt="{}">)", path, title, title);
}

// Rows = methods, columns = budgets: each repeat-0 preview, then the α map at the
// table budget (blue = envmap sampling, red = BRDF sampling, as [HS14] Fig. 5.5; green
// = the product technique).
std::string imageGrid(const Summary& s, const CaseSummary& c) {
  std::string out = "<table>\n<tr><th>method</th>";
  for (int b : s.budgets) out += fmt::format("<th>{} spp</th>", b);
  out += fmt::format("<th>α at {} spp</th></tr>\n", s.tableBudget);
  for (const MethodSummary& m : c.methods) {
    out += "<tr><td>" + methodName(m.method) + "</td>";
    for (int b : s.budgets) {
      const BudgetStats* stats = m.at(b);
      std::string path = previewPath(imagePath(c.info.label, m.method, b));
      out += stats ? "<td>" +
                         image(path,
                               fmt::format("{} {} spp: RMSE×1000 {:.2f}", methodName(m.method), b, stats->rmseX1000)) +
                         fmt::format("<br>{:.2f}</td>", stats->rmseX1000)
                   : "<td>–</td>";
    }
    bool hasAlpha = isAdaptive(m.method) && m.at(s.tableBudget);
    out += hasAlpha ? "<td>" + image(previewPath(alphaMapPath(c.info.label, m.method, s.tableBudget)), "α") + "</td>"
                    : "<td>fixed</td>";
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

}  // namespace

std::string plotFileName(const std::string& sceneLabel) { return "plot_" + sceneLabel + ".svg"; }

std::string indexHtml(const Summary& s) {
  std::string out =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<title>misalloc compare</title>\n" +
      std::string(kStyle) + "</head>\n<body>\n<h1>misalloc compare</h1>\n";
  if (s.interrupted) out += "<p><b>Interrupted: only the budgets that every repeat finished are shown.</b></p>\n";
  if (!s.cases.empty())
    out += fmt::format(
        "<p class=\"note\">Device: {}. Budgets (spp): {}. Times are wall-clock seconds per render "
        "(sampling kernels, allocation and host work), the median over repeats. Errors are against each "
        "scene's reference, corrected for its own variance (the mean of (x − r)² minus Var(r)); "
        "the spread is the standard deviation over repeats with independent seeds.</p>\n",
        s.cases.front().info.device, fmt::join(s.budgets, ", "));
  out += fmt::format("<h2>RMSE×1000 at {} spp ([HS14] Table 5.2 layout)</h2>\n", s.tableBudget) + html(rmseTable(s));
  for (int budget : speedUpBudgets(s))
    out += fmt::format("<h2>Speed-up over equal at equal error, {} spp</h2>\n", budget) + html(speedUpTable(s, budget));
  out += fmt::format("<h2>Seconds per render at {} spp: wall (kernel + allocation)</h2>\n", s.tableBudget) +
         html(timeTable(s));
  for (const SceneGroup& scene : groupByScene(s)) {
    const CaseInfo& first = scene.cases.front()->info;
    out += fmt::format("<h2 id=\"{0}\">{0}</h2>\n", scene.label);
    out += fmt::format("<p class=\"note\">Costs per sample: {}. Reference: {}.</p>\n",
                       first.costs.empty() ? "calibrated once per device, kernel build and scene, and cached "
                                             "(runs.json: costs_source)"
                                           : fmt::format("{:.3g} s (--cost)", fmt::join(first.costs, ", ")),
                       first.referenceSource);
    out +=
        fmt::format("<img src=\"{}\" alt=\"error against time, every method and pdf\">\n", plotFileName(scene.label));
    for (const CaseSummary* c : scene.cases) {
      // The scene's heading holds the id of the case that shares its label.
      if (scene.cases.size() > 1)
        out += c->info.label == scene.label ? fmt::format("<h3>{}</h3>\n", c->info.label)
                                            : fmt::format("<h3 id=\"{0}\">{0}</h3>\n", c->info.label);
      for (const LeftOutMethod& l : c->info.leftOut)
        out += fmt::format("<p class=\"note\">Not run: {} ({}).</p>\n", methodName(l.method), escapeHtml(l.why));
      out +=
          "<h4>Equal-time RMSE×1000</h4>\n<p class=\"note\">At equal's median render times; ~: continued past the "
          "measured times with MSE ∝ 1/t.</p>\n" +
          html(equalTimeTable(*c));
      out += "<h4>Images (repeat 0)</h4>\n<p>Reference: " + image(c->info.label + "/reference.png", "reference") +
             "</p>\n" + imageGrid(s, *c);
    }
  }
  return out + "</body>\n</html>\n";
}

}  // namespace misalloc
