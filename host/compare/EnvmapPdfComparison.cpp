#include "compare/EnvmapPdfComparison.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <optional>
#include <sstream>

#include "Error.h"
#include "compare/Suite.h"
#include "render/RunChecks.h"

namespace misalloc {
namespace {

// The scene a case renders, whatever its pdf and weights: its scene JSON without the pdf,
// and without how long the product technique's tables took to build (a time, which
// differs from case to case).
std::string sceneWithoutPdf(const CaseInfo& info) {
  nlohmann::json scene = info.scene;
  scene.erase("envmap_pdf");
  if (scene.contains("product")) scene["product"].erase("build_seconds");
  return scene.dump();
}

// Every pdf and weights run, in the order of the first scene that ran it.
std::vector<std::string> pdfNames(const Summary& s) {
  std::vector<std::string> names;
  for (const CaseSummary& c : s.cases)
    if (std::find(names.begin(), names.end(), caseVariant(c.info)) == names.end()) names.push_back(caseVariant(c.info));
  return names;
}

bool usable(const MethodSummary* m) {
  if (!m || m->budgets.empty()) return false;
  for (const BudgetStats& b : m->budgets)
    if (!(b.mse > 0 && std::isfinite(b.mse) && b.wallSeconds > 0)) return false;
  return true;
}

}  // namespace

std::string requestedPdf(const CaseInfo& info) { return info.scene["envmap_pdf"]["requested"]; }

std::string caseVariant(const CaseInfo& info) {
  return info.weights == MisWeights::Balance ? requestedPdf(info) : requestedPdf(info) + " + optimal weights";
}

std::vector<SceneGroup> groupByScene(const Summary& s) {
  std::vector<SceneGroup> groups;
  std::map<std::string, size_t> index;
  for (const CaseSummary& c : s.cases) {
    auto [it, inserted] = index.emplace(sceneWithoutPdf(c.info), groups.size());
    if (inserted) groups.push_back({c.info.label, {}, {}});
    groups[it->second].byPdf[caseVariant(c.info)] = &c;
    groups[it->second].cases.push_back(&c);
  }
  return groups;
}

void leaveOutBiasedMethods(std::vector<CompareCase>& cases, const std::vector<Method>& methods,
                           const std::vector<int>& budgets, const AdaptiveOptions& adaptive) {
  auto refusal = [&](const SceneOptions& scene, Method m) -> std::optional<std::string> {
    try {
      for (int budget : budgets) requireValidRun(scene, m, Estimator::MultiSample, budget, adaptive);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::nullopt;
  };
  for (CompareCase& c : cases) {
    if (c.scene.envmapPdf.plain()) continue;
    SceneOptions plain = c.scene;
    plain.envmapPdf = EnvmapPdf{};
    for (Method m : methods)
      if (auto why = refusal(c.scene, m); why && !refusal(plain, m)) c.leftOut.push_back({m, *why});
  }
}

std::vector<EnvmapPdf> parseEnvmapPdfList(const std::string& list) {
  std::vector<EnvmapPdf> pdfs;
  std::vector<std::string> names;
  std::stringstream items(list);
  for (std::string item; std::getline(items, item, ',');) {
    EnvmapPdf pdf = parseEnvmapPdf(item, "--envmap-pdfs");
    if (std::find(names.begin(), names.end(), envmapPdfName(pdf)) != names.end())
      throw InputError(fmt::format("--envmap-pdfs {}: {} is listed twice", list, item));
    names.push_back(envmapPdfName(pdf));
    pdfs.push_back(pdf);
  }
  if (pdfs.empty()) throw InputError("--envmap-pdfs: no pdf");
  return pdfs;
}

std::vector<CompareCase> casesPerEnvmapPdf(const std::vector<CompareCase>& cases, const std::vector<EnvmapPdf>& pdfs) {
  std::vector<CompareCase> out;
  for (const CompareCase& c : cases)
    for (const EnvmapPdf& pdf : pdfs) {
      CompareCase withPdf = c;
      withPdf.scene.envmapPdf = pdf;
      withPdf.label = caseLabel(withPdf.scene);
      out.push_back(withPdf);
    }
  return out;
}

TextTable envmapPdfSpeedUpTable(const Summary& s, int budget) {
  const std::vector<SceneGroup> groups = groupByScene(s);
  TextTable table;
  table.header = {"method", "pdf"};
  for (const SceneGroup& g : groups) table.header.push_back(g.label);
  table.header.push_back("geometric mean");
  for (Method method : s.methods)
    for (const std::string& pdf : pdfNames(s)) {
      std::vector<TableCell> row{{methodName(method), false}, {pdf, false}};
      double logSum = 0;
      int n = 0;
      for (const SceneGroup& g : groups) {
        auto base = g.byPdf.find("plain"), with = g.byPdf.find(pdf);
        const MethodSummary* equal = base == g.byPdf.end() ? nullptr : base->second->find(Method::Equal);
        const MethodSummary* m = with == g.byPdf.end() ? nullptr : with->second->find(method);
        const BudgetStats* b = usable(m) ? m->at(budget) : nullptr;
        if (!usable(equal) || !b) {
          row.push_back({"—", false});
          continue;
        }
        CurveValue v = speedUpOver(equal->curve(), {b->wallSeconds, b->mse});
        row.push_back({formatCurveValue(v, 2), false});
        logSum += std::log(v.value);
        ++n;
      }
      row.push_back({n > 0 ? fmt::format("{:.2f}", std::exp(logSum / n)) : "—", false});
      table.rows.push_back(row);
    }
  return table;
}

std::string envmapPdfMarkdown(const Summary& s) {
  if (pdfNames(s).size() < 2) return "";
  std::string out;
  for (int budget : speedUpBudgets(s))
    out += fmt::format(
        "\n## Envmap pdfs ([Kar19]): speed-up over equal with the plain pdf at equal error, {} spp\n\nHow many "
        "times longer `equal` with `--envmap-pdf plain` needs to reach the error each method reaches with each pdf "
        "at {} spp (`~`: read past equal's measured times).\n\n{}",
        budget, budget, markdown(envmapPdfSpeedUpTable(s, budget)));
  return out;
}

}  // namespace misalloc
