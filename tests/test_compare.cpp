// misalloc compare: the equal-time arithmetic on curves with known answers, the
// reductions over repeats, and the command end to end: its files (the pictures decoded,
// the page parsed), its bad input and its interruption.
#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <thread>

#include "CliRunner.h"
#include "PictureChecks.h"
#include "RunRecords.h"
#include "compare/Comparison.h"
#include "compare/ErrorCurve.h"
#include "compare/ErrorTimePlot.h"
#include "compare/Summary.h"
#include "compare/SummaryTables.h"
#include "report/AlphaMap.h"
#include "report/PreviewPng.h"
#include "scene/ExrIO.h"

using namespace misalloc;
using namespace misalloc::test;
namespace fs = std::filesystem;

namespace {

// MSE = a/t: a method at constant efficiency 1/a.
ErrorCurve monteCarloCurve(double a, std::vector<double> times) {
  std::vector<CurvePoint> points;
  for (double t : times) points.push_back({t, a / t});
  return ErrorCurve(points);
}

// A case's repeat-0 pictures against its EXRs and runs.json: every preview drawn from its
// image at one exposure (the reference's), every α map holding its run's mean α and drawn
// from its envmap plane. Returns the α maps seen.
int checkCasePictures(const fs::path& out, const nlohmann::json& info, const nlohmann::json& runs, int size) {
  const std::string label = info["label"];
  const auto techniques = info["techniques"].get<std::vector<std::string>>();
  INFO(label);
  const Picture reference = readPng(out / label / "reference.png");
  CHECK(reference.width == size);
  CHECK(reference.height == size);
  ExposureRange exposure;
  int alphaMaps = 0;
  for (const auto& run : runs) {
    if (run["case"] != label || run["repeat"] != 0) continue;
    const Method method = parseMethod(run["method"]);
    const int spp = run["spp"];
    INFO(methodName(method) << " " << spp << " spp");
    const std::string exr = (out / imagePath(label, method, spp)).string();
    const RgbImage image = readExr(exr);
    REQUIRE(image.width == size);
    REQUIRE(image.height == size);
    narrowExposure(exposure, readPng(previewPath(exr)), image);
    const std::string alphaMap = (out / alphaMapPath(label, method, spp)).string();
    CHECK(fs::exists(alphaMap) == isAdaptive(method));
    if (!isAdaptive(method)) continue;
    ++alphaMaps;
    const auto planes = readAlphaMap(alphaMap, techniques, size, size);
    const AlphaSummary alpha = summarizeAlpha(planes, image);
    CHECK(alpha.offSimplex == 0);
    for (size_t k = 0; k < techniques.size(); ++k)
      CHECK(alpha.coveredMean[k] == Approx(run["mean_alpha"][k].get<double>()).margin(1e-6));
    CHECK(alphaPictureMismatches(readPng(alphaPngPath(alphaMap)), planes.front(), image) == 0);
  }
  INFO("exposures " << exposure.lo << " to " << exposure.hi);
  CHECK_FALSE(exposure.empty());
  return alphaMaps;
}

// The cells' text of the first table after `heading` in a page of html(TextTable) tables,
// row by row, the header first, bold dropped.
std::vector<std::vector<std::string>> tableAfter(const std::string& page, const std::string& heading) {
  const size_t at = page.find(heading);
  INFO(heading);
  REQUIRE(at != std::string::npos);
  const size_t begin = page.find("<table>", at), end = page.find("</table>", begin);
  REQUIRE(end != std::string::npos);
  const std::string table = page.substr(begin, end - begin);
  static const std::regex row("<tr>(.*)</tr>"), cell("<t[hd]>(?:<b>)?(.*?)(?:</b>)?</t[hd]>");
  std::vector<std::vector<std::string>> rows;
  for (auto r = std::sregex_iterator(table.begin(), table.end(), row); r != std::sregex_iterator(); ++r) {
    const std::string cells = (*r)[1];
    rows.emplace_back();
    for (auto c = std::sregex_iterator(cells.begin(), cells.end(), cell); c != std::sregex_iterator(); ++c)
      rows.back().push_back((*c)[1]);
  }
  return rows;
}

std::vector<double> numbersIn(const std::string& text) {
  static const std::regex number("[0-9]+(\\.[0-9]+)?");
  std::vector<double> out;
  for (auto n = std::sregex_iterator(text.begin(), text.end(), number); n != std::sregex_iterator(); ++n)
    out.push_back(std::stod((*n)[0]));
  return out;
}

// A table of rows = methods and columns = cases (SummaryTables.h) against summary.json:
// each cell holds `fields` of its method's entry at the table budget, rounded to `step`,
// or "–" where there is none.
template <typename Fields>  // std::vector<double>(const nlohmann::json& budgetEntry)
void checkMethodTable(const std::vector<std::vector<std::string>>& table, const nlohmann::json& summary, double step,
                      Fields fields) {
  REQUIRE(table.size() == 1 + summary["methods"].size());
  REQUIRE(table[0].size() == 1 + summary["cases"].size());
  for (size_t c = 0; c < summary["cases"].size(); ++c) {
    const nlohmann::json& scene = summary["cases"][c];
    CHECK(table[0][1 + c] == scene["label"]);
    for (size_t m = 0; m < summary["methods"].size(); ++m) {
      const std::string& text = table[1 + m][1 + c];
      INFO(scene["label"] << " " << summary["methods"][m] << ": " << text);
      CHECK(table[1 + m][0] == summary["methods"][m]);
      std::vector<double> expected;
      for (const auto& method : scene["methods"])
        if (method["method"] == summary["methods"][m])
          for (const auto& budget : method["budgets"])
            if (budget["spp"] == summary["table_spp"]) expected = fields(budget);
      const std::vector<double> shown = numbersIn(text);
      REQUIRE(shown.size() == expected.size());
      for (size_t i = 0; i < shown.size(); ++i) CHECK(std::abs(shown[i] - expected[i]) <= 0.5 * step + 1e-12);
      if (expected.empty()) CHECK(text == "–");
    }
  }
}

}  // namespace

TEST_CASE("error curves interpolate in log-log and continue with the Monte Carlo law", "[compare]") {
  ErrorCurve curve = monteCarloCurve(2.0, {0.4, 0.1, 0.2});  // unsorted on purpose
  for (double t : {0.1, 0.13, 0.2, 0.31, 0.4}) {
    CurveValue v = curve.mseAt(t);
    CHECK(v.value == Approx(2.0 / t).epsilon(1e-12));
    CHECK_FALSE(v.extrapolated);
  }
  for (double t : {0.05, 1.0}) {
    CurveValue v = curve.mseAt(t);
    CHECK(v.value == Approx(2.0 / t).epsilon(1e-12));
    CHECK(v.extrapolated);
  }
  for (double mse : {5.0, 12.0, 20.0, 40.0}) CHECK(curve.secondsFor(mse).value == Approx(2.0 / mse).epsilon(1e-12));
  CHECK_FALSE(curve.secondsFor(12.0).extrapolated);
  CHECK(curve.secondsFor(40.0).extrapolated);
  CHECK(*curve.logLogSlope() == Approx(-1).epsilon(1e-12));
  ErrorCurve slower({{1, 1}, {4, 0.5}});  // MSE ∝ t^(−1/2)
  CHECK(*slower.logLogSlope() == Approx(-0.5).epsilon(1e-12));
  CHECK_FALSE(ErrorCurve({{1, 1}}).logLogSlope());
  CHECK_THROWS_AS(ErrorCurve({{1, 0}}), std::invalid_argument);
  CHECK_THROWS_AS(ErrorCurve({}), std::invalid_argument);
}

TEST_CASE("the speed-up over equal at equal error is the ratio of efficiencies under the Monte Carlo law",
          "[compare]") {
  ErrorCurve equal = monteCarloCurve(2.0, {0.1, 0.2, 0.4, 0.8});
  // Half equal's error at each time: equal needs twice as long for the same error.
  for (double t : {0.1, 0.3, 0.8}) {
    CurveValue s = speedUpOver(equal, {t, 1.0 / t});
    CHECK(s.value == Approx(2.0).epsilon(1e-12));
  }
  // A noisy curve that rises between budgets is read at its first crossing.
  ErrorCurve noisy({{1, 4}, {2, 1}, {3, 2}, {4, 0.5}});
  CHECK(noisy.secondsFor(1.5).value < 2);
}

TEST_CASE("repeats reduce to means and spreads, and unfinished budgets are left out", "[compare]") {
  Comparison c;
  c.cases.push_back({"a", {}, {"envmap", "brdf"}, {1, 1}, "--cost", "analytic", 0, "test"});
  for (int budget : {10, 20}) {
    for (int r = 0; r < 2; ++r) {
      // RMSE×1000 = 100 ± 10 (budget 10) and an exact 1/t law for equal.
      double rmse = (budget == 10 ? 90 + 20 * r : 70) / 1000.0;
      c.runs.push_back(record("a", Method::Equal, budget, r, 0.01 * budget, 1e-4 * 10 / budget));
      c.runs.push_back(record("a", Method::Heuristic, budget, r, 0.01 * budget, rmse * rmse));
    }
  }
  c.runs.push_back(record("a", Method::Exact, 10, 0, 0.1, 1e-4));  // one repeat of two
  CompareOptions o;
  o.methods = {Method::Equal, Method::Heuristic, Method::Exact};
  o.budgets = {10, 20};
  o.repeats = 2;
  o.tableBudget = 12;
  Summary s = summarize(c, o);
  CHECK(s.tableBudget == 10);
  const CaseSummary& a = s.cases.at(0);
  const MethodSummary* h = a.find(Method::Heuristic);
  REQUIRE(h);
  REQUIRE(h->budgets.size() == 2);
  CHECK(h->budgets[0].rmseX1000 == Approx(1000 * std::sqrt((0.09 * 0.09 + 0.11 * 0.11) / 2)));
  CHECK(h->budgets[0].rmseSpreadX1000 == Approx(std::sqrt(200.0)));  // sample sd of 90 and 110
  CHECK(h->budgets[1].rmseSpreadX1000 == Approx(0).margin(1e-9));
  CHECK(a.find(Method::Exact)->budgets.empty());
  CHECK(a.find(Method::Equal)->budgets[1].speedUp->value == Approx(1));
  CHECK(speedUpBudgets(s) == std::vector<int>{10, 20});
  CHECK(a.commonSeconds == std::vector<double>{0.1, 0.2});

  std::string md = summaryMarkdown(s);
  CHECK(md.find("| exact | – |") != std::string::npos);
  CHECK(md.find("## RMSE×1000 at 10 spp") != std::string::npos);
  CHECK(summaryCsv(s) == fmt::format("method,a\nequal,10.0000\nheuristic,{:.4f}\nexact,\n", h->budgets[0].rmseX1000));
  std::string svg = errorTimePlotSvg(SceneGroup{a.info.label, {}, {&a}});
  CHECK(svg.rfind("<svg", 0) == 0);
  CHECK(svg.find("</svg>") != std::string::npos);
  CHECK(std::count(svg.begin(), svg.end(), '\n') > 3);
  size_t lines = 0;
  for (size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) ++lines;
  CHECK(lines == 2);  // equal and heuristic; exact has no finished budget
}

TEST_CASE("compare writes its tables, plots, images and index.html", "[cli][compare]") {
  TempDir dir("compare");
  const fs::path out = dir.path / "out";
  // By default each scene runs with the plain and the optimal pdf.
  auto r =
      runMisalloc(fmt::format("compare --envmap cosk:2 --size 8x8 --budgets 10,20 --repeats 2 "
                              "--methods equal,heuristic,exact,brdf --device cpu --out-dir {} --cache-dir {}",
                              out.string(), (dir.path / "cache").string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  for (const char* file : {"index.html", "summary.md", "summary.csv", "summary.json", "budgets.csv", "runs.json",
                           "runs.csv", "plot_cosk_2.svg", "cosk_2/reference.png", "cosk_2/exact_20spp.exr",
                           "cosk_2/exact_20spp.png", "cosk_2/exact_20spp_alpha.exr", "cosk_2/exact_20spp_alpha.png",
                           "cosk_2-optimal/exact_20spp.exr", "cosk_2-optimal/reference.png"})
    CHECK(fs::exists(out / file));
  // One plot per scene, with every method and pdf: equal/plain and exact/optimal meet.
  CHECK_FALSE(fs::exists(out / "plot_cosk_2-optimal.svg"));
  std::ifstream plot(out / "plot_cosk_2.svg");
  const std::string svg((std::istreambuf_iterator<char>(plot)), std::istreambuf_iterator<char>());
  for (const char* line : {"equal / plain", "exact / optimal", "brdf / optimal"})
    CHECK(svg.find(line) != std::string::npos);
  size_t lines = 0;
  for (size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) ++lines;
  CHECK(lines == 4 * 2);
  nlohmann::json runs = nlohmann::json::parse(std::ifstream(out / "runs.json"));
  CHECK(runs["interrupted"] == false);
  CHECK(runs["runs"].size() == 4 * 2 * 2 * 2);
  // The adaptive renders' stages carry the cost model's prediction; the fixed splits' do not.
  for (const auto& run : runs["runs"]) {
    REQUIRE(!run["stages"].empty());
    const bool adaptive = run["method"] == "heuristic" || run["method"] == "exact";
    CHECK(run["stages"][0].contains("predicted_kernel_s") == adaptive);
  }
  CHECK(runs["cases"][0]["reference"] == "analytic ([HS14] eq. 6.17)");
  nlohmann::json summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  CHECK(summary["table_spp"] == 20);
  CHECK(summary["cost_model"]["stages"] == 2 * 2 * 2 * 2 * 2);  // heuristic and exact: pilot and a stage each
  for (const auto& m : summary["cases"][0]["methods"]) {
    CHECK(m["budgets"].size() == 2);
    CHECK(m["equal_time_rmse_x1000"].size() == 2);
  }
  // The pictures show what the EXRs and runs.json hold: two adaptive methods × two budgets per pdf.
  for (const auto& info : runs["cases"]) CHECK(checkCasePictures(out, info, runs["runs"], 8) == 2 * 2);
  // Every file the page shows or links is in the folder, by a relative path.
  std::ifstream in(out / "index.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::regex link("(src|href)=\"([^\"]+)\"");
  int images = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), link); it != std::sregex_iterator(); ++it) {
    const std::string path = (*it)[2];
    INFO(path);
    CHECK(fs::exists(out / path));
    CHECK(fs::path(path).is_relative());
    CHECK(path.find("..") == std::string::npos);
    images += (*it)[1] == "src";
  }
  CHECK(images == 1 + 2 * (1 + 4 * 2 + 2));  // plot; per pdf: reference, each method × budget, two α maps
  // It names every case and method, and its tables' numbers are summary.json's.
  for (const auto& info : runs["cases"])
    CHECK(html.find(fmt::format("id=\"{}\"", info["label"].get<std::string>())) != std::string::npos);
  // Each anchor once.
  const std::regex anchor("id=\"([^\"]+)\"");
  std::set<std::string> ids;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), anchor); it != std::sregex_iterator(); ++it)
    CHECK(ids.insert((*it)[1]).second);
  checkMethodTable(tableAfter(html, "<h2>RMSE×1000 at 20 spp"), summary, 0.01, [](const nlohmann::json& b) {
    return std::vector<double>{b["rmse_x1000"], b["rmse_spread_x1000"]};
  });
  checkMethodTable(tableAfter(html, "<h2>Seconds per render at 20 spp"), summary, 0.001, [](const nlohmann::json& b) {
    return std::vector<double>{b["time_s"]["wall"], b["time_s"]["kernel"], b["time_s"]["allocation"]};
  });
}

TEST_CASE("compare rejects bad options before it writes anything", "[cli][compare][bad-input]") {
  TempDir dir("compare_bad");
  const fs::path out = dir.path / "out";
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"--budgets 0,10", "--budgets"},           {"--budgets 20,10", "ascending"},
      {"--budgets 10,x", "'x' is not a number"}, {"--methods equal,magic", "magic"},
      {"--methods equal,equal", "listed twice"}, {"--methods exact --budgets 3", "smaller than the pilot"},
      {"--repeats 0", "--repeats: '0'"},         {"--suite --envmap forest_slope", "drop --envmap"},
      {"--envmap /no/such.exr", "/no/such.exr"}, {"--cost 1", "expected 2 numbers"},
  };
  for (const Case& c : cases) {
    auto r = runMisalloc(
        fmt::format("compare --envmap cosk:2 --size 8x8 --budgets 10 --out-dir {} {}", out.string(), c.args));
    INFO(c.args << "\n" << r.output);
    CHECK(r.exitCode == 2);
    CHECK(r.output.find(c.expected) != std::string::npos);
    CHECK_FALSE(fs::exists(out));
  }
}

TEST_CASE("an interrupted compare stops with every file complete", "[cli][compare]") {
  TempDir dir("compare_interrupt");
  const fs::path out = dir.path / "out", log = dir.path / "log.txt";
  const std::string args = fmt::format(
      "{} compare --envmap cosk:2 --size 16x16 --budgets 8,16,32,64,128 --repeats 8 --device cpu --out-dir {} "
      "--cache-dir {} >{} 2>&1",
      misalloc::test::misallocBinary(), out.string(), (dir.path / "cache").string(), log.string());
  pid_t pid = 0;
  const char* argv[] = {"sh", "-c", args.c_str(), nullptr};
  // exec, not a child shell, so that the signal reaches misalloc itself.
  std::string execArgs = "exec " + args;
  argv[2] = execArgs.c_str();
  REQUIRE(posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ) == 0);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  // The folder fills a staging folder beside it, moved in when compare ends.
  auto started = [&] {
    for (const auto& entry : fs::recursive_directory_iterator(dir.path))
      if (entry.path().filename() == "runs.json") return true;
    return false;
  };
  while (!started() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  REQUIRE(started());
  ::kill(pid, SIGINT);
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  std::ifstream logIn(log);
  std::string output((std::istreambuf_iterator<char>(logIn)), std::istreambuf_iterator<char>());
  INFO(output);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  CHECK(output.find("interrupted after") != std::string::npos);
  nlohmann::json runs = nlohmann::json::parse(std::ifstream(out / "runs.json"));
  CHECK(runs["interrupted"] == true);
  CHECK(runs["runs"].size() < 8 * 5 * 8);
  nlohmann::json summary = nlohmann::json::parse(std::ifstream(out / "summary.json"));
  CHECK(summary["interrupted"] == true);
  for (const auto& entry : fs::recursive_directory_iterator(dir.path))
    CHECK(entry.path().string().find(".tmp") == std::string::npos);
}
