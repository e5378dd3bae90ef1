// Nothing lost, ever: an output never replaces an input or another output, a failed
// run leaves every earlier file as it was, exit codes mean one thing, every numeric
// option is checked in full range, and a written image is always finite.
#include <fmt/format.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "CliRunner.h"
#include "JsonText.h"
#include "RawExr.h"
#include "SafetyWorkspace.h"
#include "TestSize.h"
#include "paper/PaperReport.h"
#include "scene/ExrIO.h"

namespace fs = std::filesystem;

using misalloc::test::runMisalloc;
using misalloc::test::TempDir;
using namespace misalloc::test;

TEST_CASE("an output that is an input, or another output, is refused and nothing is written", "[cli][safety]") {
  Workspace w;
  const std::string env = w.path("env.exr");
  fs::copy_file(env, w.path("map.png"));  // an envmap that an α map's PNG would replace
  const std::vector<Refusal> cases = {
      {w.render("--out " + env), "--out " + env + " is the same file as --envmap"},
      {w.render(fmt::format("--out {}/./env.exr", w.dir.path.string())), "is the same file as --envmap"},
      {w.render(fmt::format("--out {}/sub/../env.exr", w.dir.path.string())), "is the same file as --envmap"},
      {w.render("--out " + w.path("link.exr")), "is the same file as --envmap"},
      {w.render("--out " + w.path("hard.exr")), "is the same file as --envmap"},
      {w.render("--report " + env), "--report " + env + " is the same file as --envmap"},
      {w.render("--report " + w.path("hard.exr")), "is the same file as --envmap"},
      {w.render("--alpha-map " + env + " --method heuristic --spp 40"), "--alpha-map " + env + " is the same file"},
      {fmt::format("render --envmap {} --size 4x4 --spp 40 --method heuristic --reference none --out {} --report {} "
                   "--alpha-map {}",
                   w.path("map.png"), w.path("render.exr"), w.path("render.json"), w.path("map.exr")),
       "--alpha-map " + w.path("map.png") + " is the same file as --envmap"},
      {w.render(fmt::format("--reference {} --out {}", w.path("ref.exr"), w.path("ref.exr"))),
       "is the same file as --reference"},
      {w.render("--report " + w.path("render.exr")), "are the same file"},
      {w.render(fmt::format("--out {} --alpha-map {} --method heuristic --spp 40", w.path("alpha.png"),
                            w.path("alpha.exr"))),
       "are the same file"},
      {w.render(fmt::format("--alpha-map {} --method heuristic --spp 40", w.path("render.exr"))), "are the same file"},
      {fmt::format("reference --envmap {} --size 4x4 --spp 8 --device cpu --cache-dir {} --out {}", env,
                   w.path("cache"), w.path("link.exr")),
       "is the same file as --envmap"},
  };
  checkRefusals(w.dir.path, cases);
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("a run that fails leaves every earlier file as it was", "[cli][safety]") {
  Workspace w;
  const std::string before = fingerprint(w.dir.path);
  // /sys refuses new files even to root: the run does all its work, then cannot write.
  const std::string unwritable[] = {
      w.render("--report /sys/render.json"),
      w.render("--alpha-map /sys/alpha.exr --method heuristic --spp 40"),
      w.render("--spp 0"),
      w.render("--cache-dir /proc/no/cache --reference auto"),
      fmt::format("reference --envmap {} --size 4x4 --spp 8 --device cpu --cache-dir {} --out /sys/ref.exr",
                  w.path("env.exr"), w.path("cache")),
  };
  for (const std::string& args : unwritable) {
    auto r = runMisalloc(args);
    INFO(args << "\n" << r.output);
    CHECK(r.exitCode == 2);
    // The cache may gain a reference; nothing that was there before changes.
    fs::remove_all(w.dir.path / "cache");
    CHECK(fingerprint(w.dir.path) == before);
  }
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("compare's folder is replaced all or nothing", "[cli][safety][compare]") {
  Workspace w;
  const fs::path out = w.dir.path / "cmp";
  const std::string compare = fmt::format(
      "compare --envmap {} --size 4x4 --methods equal --budgets 4 --repeats 1 --device cpu --cache-dir {} --out-dir {}",
      w.path("env.exr"), w.path("cache"), out.string());
  // A folder of the user's, not an earlier comparison: refused, untouched.
  fs::create_directories(out);
  writeText(out / "notes.txt", "mine");
  const std::string before = fingerprint(w.dir.path);
  auto r = runMisalloc(compare);
  INFO(r.output);
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("holds files that no earlier run of this command wrote (no runs.json)") != std::string::npos);
  CHECK(fingerprint(w.dir.path) == before);

  // An earlier comparison, even one with a folder where a file now goes, is replaced
  // as a whole: nothing of it stays beside the new files.
  writeText(out / "runs.json", "earlier runs");
  fs::create_directory(out / "summary.md");
  writeText(out / "summary.md" / "keep", "earlier");
  r = runMisalloc(compare);
  INFO(r.output);
  CHECK(r.exitCode == 0);
  CHECK(readText(out / "runs.json") != "earlier runs");
  CHECK(fs::is_regular_file(out / "summary.md"));
  CHECK_FALSE(fs::exists(out / "notes.txt"));
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("a report holds any file name, valid UTF-8 or not", "[cli][safety]") {
  CHECK(misalloc::validUtf8("plain é ✓ 𝄞") == "plain é ✓ 𝄞");
  CHECK(misalloc::validUtf8("a\xff"
                            "b") == "a\\xFFb");
  CHECK(misalloc::validUtf8("\xc3") == "\\xC3");                    // truncated sequence
  CHECK(misalloc::validUtf8("\xc0\xaf") == "\\xC0\\xAF");           // overlong '/'
  CHECK(misalloc::validUtf8("\xed\xa0\x80") == "\\xED\\xA0\\x80");  // a surrogate
  Workspace w;
  const std::string odd = w.path("map\xff\xfe.exr");
  fs::copy_file(w.path("env.exr"), odd);
  auto r =
      runMisalloc(fmt::format("render --envmap '{}' --size 4x4 --spp 8 --device cpu --reference none --out {} "
                              "--report {}",
                              odd, w.path("odd.exr"), w.path("odd.json")));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  nlohmann::json report = nlohmann::json::parse(readText(w.path("odd.json")));
  CHECK(report["scene"]["envmap_file"].get<std::string>().find("map\\xFF\\xFE.exr") != std::string::npos);
}

namespace {

bool allFinite(const misalloc::RgbImage& image) {
  for (float v : image.rgb)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace

TEST_CASE("radiance near the float maximum is refused, naming the input, and written images are finite",
          "[cli][safety][finite]") {
  Workspace w;
  misalloc::writeExr(w.path("huge.exr"), misalloc::RgbImage{8, 4, std::vector<float>(96, 1e38f)});
  const std::string huge[] = {"constant:1e38",      "constant:1e31", "sun:40,90,0.5,1e38",
                              "sun:40,90,0.5,1e30", "cosk:1e38",     w.path("huge.exr")};
  for (const std::string& envmap : huge) {
    for (const std::string& command :
         {fmt::format("render --envmap {} --size 4x4 --spp 8 --device cpu --cache-dir {} --out {} --report {}", envmap,
                      w.path("cache"), w.path("h.exr"), w.path("h.json")),
          fmt::format("reference --envmap {} --size 4x4 --spp 8 --device cpu --cache-dir {}", envmap,
                      w.path("cache"))}) {
      auto r = runMisalloc(command);
      INFO(command << "\n" << r.output);
      if (r.exitCode == 0) {
        if (command.rfind("render", 0) == 0) CHECK(allFinite(misalloc::readExr(w.path("h.exr"))));
        fs::remove(w.path("h.exr"));
      } else {
        CHECK(r.exitCode == 2);
        CHECK(r.output.find(envmap) != std::string::npos);
        CHECK_FALSE(fs::exists(w.path("h.exr")));
      }
    }
  }
  // Whatever was cached is finite (readExr refuses NaN and Inf); the locks beside the
  // entries are empty files.
  if (fs::exists(w.dir.path / "cache"))
    for (const auto& entry : fs::recursive_directory_iterator(w.dir.path / "cache"))
      if (entry.is_regular_file() && entry.path().extension() == ".exr")
        CHECK_NOTHROW(misalloc::readExr(entry.path().string()));
  // The brightest map accepted renders finite pixels at the most extreme lobes.
  auto r = runMisalloc(fmt::format(
      "render --envmap constant:1e30 --grid general:0,0,1e5,1e5 --size 4x4 --spp 64 --device cpu --reference none "
      "--method heuristic --out {} --report {}",
      w.path("h.exr"), w.path("h.json")));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK(allFinite(misalloc::readExr(w.path("h.exr"))));
  // compare tabulates no NaN or Inf.
  r = runMisalloc(fmt::format(
      "compare --envmap constant:1e38 --size 4x4 --methods equal --budgets 4 --repeats 1 --device cpu --cache-dir {} "
      "--out-dir {}",
      w.path("cache"), w.path("cmp")));
  INFO(r.output);
  CHECK(r.exitCode == 2);
  CHECK_FALSE(fs::exists(w.dir.path / "cmp"));
}

TEST_CASE("exit codes: 2 for bad input, 3 for OpenCL errors, 0 for help", "[cli][safety][exit-codes]") {
  Workspace w;
  struct Case {
    std::string args;
    int code;
    std::string expected;
  };
  const std::string cache = "--cache-dir " + w.path("cache");
  const Case cases[] = {
      {"--help", 0, "render"},
      {"render --help", 0, "--spp"},
      {"", 2, "subcommand"},
      {"bogus", 2, "unknown subcommand 'bogus'"},
      {"render --bogus", 2, "--bogus"},
      {"render --spp 1e3", 2, "--spp"},
      {"render --spp", 2, "--spp"},
      {"compare --envmap constant", 2, "--out-dir"},
      {"paper nosuch", 2, "unknown example"},
      {"render --size 100000x100000", 2, "--size 100000x100000"},
      {"render --size 40000x40000 --reference none", 2, "--size 40000x40000"},
      {w.render("--cache-dir /proc/no/cache --reference auto"), 2, "--cache-dir /proc/no/cache"},
      {fmt::format("compare --envmap constant --size 4x4 --methods equal --budgets 4 --out-dir /proc/no/out {}", cache),
       2, "--out-dir /proc/no/out"},
      {w.render("--method linear --size 64x64 --spp 1000000000"), 2, "--spp 1000000000 with --method linear"},
      {fmt::format("compare --envmap constant --size 64x64 --methods linear --budgets 100,1000000 --out-dir {} {}",
                   w.path("cmp"), cache),
       2, "--budgets 1000000 with --method linear"},
      {w.render("--method oracle --size 64x64 --spp 40 --oracle-spp 1000000000"), 2, "--oracle-spp 1000000000"},
      {w.render("--method exact --grid-u 16777217"), 2, "--grid-u"},
      {w.render("--local-size 100000"), 3, "--local-size 100000"},
      {w.render("--method exact --grid-u 1000000 --size 64x64 --spp 40"), 3, "--grid-u 1000000"},
  };
  for (const Case& c : cases) {
    auto r = runMisalloc(c.args);
    INFO(c.args << "\n" << r.output);
    CHECK(r.exitCode == c.code);
    CHECK(r.output.find(c.expected) != std::string::npos);
  }
  CHECK_FALSE(fs::exists(w.path("cmp")));
}

namespace {

// An option's bad values: each must be refused with exit 2 and the option's name.
struct NumericOption {
  std::string option;
  std::vector<std::string> bad;
};

const std::vector<std::string> kNotNumbers = {"nan", "inf", "-inf", "''", "junk", "1x", "0x10", "1,2"};

std::vector<std::string> withNotNumbers(std::vector<std::string> values) {
  values.insert(values.end(), kNotNumbers.begin(), kNotNumbers.end());
  return values;
}

// A whole number option in [lo, ...]: too small, too large or wrapped, fractional.
NumericOption count(const std::string& option, long long lo, const std::string& tooLarge = "2147483648") {
  return {option,
          withNotNumbers({std::to_string(lo - 1), "-1", tooLarge, "4294967297", "18446744073709551617", "1.5", "1e3"})};
}

}  // namespace

TEST_CASE("every numeric option of every subcommand is checked in full range", "[cli][safety][options]") {
  Workspace w;
  const std::string cache = "--cache-dir " + w.path("cache");
  // Fast, harmless runs, so that a value that slipped through costs little and shows.
  const std::vector<std::pair<std::string, std::string>> subcommands = {
      {"render", w.render("")},
      {"reference", fmt::format("reference --envmap constant --size 2x2 --spp 2 --device cpu {}", cache)},
      {"compare", fmt::format("compare --envmap constant --size 2x2 --methods equal --budgets 4 --repeats 1 "
                              "--device cpu --out-dir {} {}",
                              w.path("cmp"), cache)},
  };
  const std::vector<NumericOption> scene = {
      {"--size",
       {"0x4", "4x0", "-1x4", "4294967297x1", "1x4294967297", "65536x65536", "4", "4x", "x4", "nanx4", "4x4x4", "''",
        "1.5x4", "'4 x4'", "+4x4"}},
      {"--view", {"-1", "90", "1e309", "nan", "inf", "''", "junk", "10,nan", "10,inf", "10,", ",10", "1,2,3"}},
      {"--grid",
       {"general:0,1,nan,1", "general:0,1,1,inf", "general:0,1,0,1", "general:0,2,1,1", "uniform:0.5,0.5",
        "uniform:0.5,0.5,1e6", "uniform:nan,0.5,1", "uniform:0.5,0.5,1,", "general:"}},
      {"--envmap",
       {"constant:nan", "constant:-1", "constant:inf", "constant:", "constant:1e39", "cosk:-1", "cosk:nan", "cosk:1e39",
        "sun:40,90,0.5", "sun:181,90,0.5,1e5", "sun:40,nan,0.5,1e5", "sun:40,90,0,1e5", "sun:40,90,91,1e5",
        "sun:40,90,0.5,0", "sun:40,90,0.5,-1", "sun:40,90,0.5,1e39", "sun:40,90,0.5,1e5,1"}},
      count("--procedural-width", 2, "16385"),
  };
  const std::vector<NumericOption> adaptive = {
      {"--pilot", withNotNumbers({"0", "1", "-0.1", "1.5", "1e309"})},
      count("--stages", 1),
      count("--grid-u", 2, "16777217"),
      count("--oracle-spp", 2),
      count("--ris-candidates", 1, "17"),
      count("--pool", 0, "4097"),
      {"--skip-below", withNotNumbers({"-0.1", "1", "1.5", "1e309"})},
      {"--cost", {"1,nan", "1,inf", "1,0", "1,-1", "1", "1,2,3", "1,,2", "''", "junk,1", "1e309,1"}},
  };
  std::vector<std::pair<std::string, NumericOption>> table;
  for (const auto& [name, base] : subcommands)
    for (const NumericOption& o : scene) table.push_back({base, o});
  for (const std::string& base : {subcommands[0].second + " --method heuristic --spp 40",
                                  subcommands[2].second + " --methods heuristic --budgets 40"})
    for (const NumericOption& o : adaptive) table.push_back({base, o});
  for (const std::string& base : {subcommands[0].second, subcommands[1].second})
    table.push_back({base, count("--spp", 1)});
  table.push_back({subcommands[0].second, count("--reference-spp", 1)});
  table.push_back({subcommands[2].second, count("--reference-spp", 1)});
  for (const std::string& base : {subcommands[0].second, subcommands[2].second}) {
    table.push_back({base, count("--local-size", 1)});
    table.push_back({base, {"--seed", withNotNumbers({"-1", "18446744073709551616", "1.5", "1e3"})}});
  }
  table.push_back({subcommands[2].second, count("--repeats", 1)});
  table.push_back({subcommands[2].second, count("--table-spp", 1)});
  table.push_back({subcommands[2].second,
                   {"--budgets",
                    {"0", "-4", "4.5", "10000001", "4,nan", "8,4", "4,4", "4,,8", "4,", "nan", "inf", "''", "junk",
                     "1x", "0x10"}}});
  // Small test size (the sanitizers): each option's first and last bad value, through
  // the same parser and checks.
  for (auto& [base, o] : table)
    if (smallTestSize() && o.bad.size() > 2) o.bad = {o.bad.front(), o.bad.back()};
  for (const auto& [base, o] : table)
    for (const std::string& value : o.bad) {
      const std::string args = fmt::format("{} {} {}", base, o.option, value);
      auto r = runMisalloc(args);
      INFO(args << "\n" << r.output);
      CHECK(r.exitCode == 2);
      CHECK(r.output.find(o.option) != std::string::npos);
    }
  CHECK_FALSE(fs::exists(w.path("cmp")));
}

TEST_CASE("the reference cache cannot lie: a clash is refused, a damaged entry is computed again",
          "[cli][safety][cache]") {
  Workspace w;
  const std::string cache = w.path("cache");
  const std::string run = w.render("--reference auto --reference-spp 16 --cache-dir " + cache);
  auto first = runMisalloc(run);
  INFO(first.output);
  REQUIRE(first.exitCode == 0);
  const fs::path references = w.dir.path / "cache" / "references";
  REQUIRE(std::distance(fs::directory_iterator(references), fs::directory_iterator()) == 1);
  const fs::path entry = fs::directory_iterator(references)->path();
  const std::string trusted = readText(entry);
  CHECK(runMisalloc(run).output.find("16 spp (cached)") != std::string::npos);

  // An output over the cached reference, which is an input of the run.
  const std::string before = fingerprint(w.dir.path);
  for (const std::string& args :
       {fmt::format("render --envmap {} --size 4x4 --spp 8 --device cpu --reference-spp 16 --cache-dir {} --out {} "
                    "--report {}",
                    w.path("env.exr"), cache, entry.string(), w.path("render.json")),
        fmt::format("reference --envmap {} --size 4x4 --spp 16 --device cpu --cache-dir {} --out {}", w.path("env.exr"),
                    cache, entry.string())}) {
    auto r = runMisalloc(args);
    INFO(args << "\n" << r.output);
    CHECK(r.exitCode == 2);
    CHECK(r.output.find("is the same file as the cached reference") != std::string::npos);
    CHECK(fingerprint(w.dir.path) == before);
  }

  // Each damage is reported, the entry computed again and trusted from then on.
  struct Damage {
    const char* what;
    std::function<void()> apply;
    const char* reported;
  };
  const Damage damages[] = {
      {"a flipped bit",
       [&] {
         std::string bytes = trusted;
         bytes[bytes.size() / 2] ^= 0x10;
         writeText(entry, bytes);
       },
       "not trusted"},
      {"truncated", [&] { writeText(entry, trusted.substr(0, trusted.size() / 2)); }, "truncated or corrupt"},
      {"text", [&] { writeText(entry, "not an image"); }, "not an OpenEXR file"},
      {"another size",
       [&] {
         misalloc::writeExr(entry.string(), misalloc::RgbImage{2, 2, std::vector<float>(12, 1.0f)});
       },
       "has no"},
      {"NaN",
       [&] {
         misalloc::RgbImage nan{4, 4, std::vector<float>(48, 0.5f)};
         nan.rgb[5] = std::nanf("");
         misalloc::test::writeRawExr(entry.string(), nan);
       },
       "NaN"},
  };
  for (const Damage& d : damages) {
    d.apply();
    auto r = runMisalloc(run);
    INFO(d.what << "\n" << r.output);
    CHECK(r.exitCode == 0);
    CHECK(r.output.find("the cached reference") != std::string::npos);
    CHECK(r.output.find(d.reported) != std::string::npos);
    CHECK(r.output.find("computed again") != std::string::npos);
    CHECK(readText(entry) == trusted);  // the same seed: the same reference, bit for bit
    CHECK(runMisalloc(run).output.find("16 spp (cached)") != std::string::npos);
  }
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("refusals that the options alone decide come before any work", "[cli][safety][bad-input]") {
  Workspace w;
  const fs::path od = w.dir.path / "od", mine = w.dir.path / "mine";
  fs::create_directories(od);
  writeText(od / "runs.json", "an earlier comparison");
  misalloc::writeExr((od / "map.exr").string(), misalloc::RgbImage{8, 4, std::vector<float>(96, 0.5f)});
  fs::create_directories(mine);
  writeText(mine / "notes.txt", "mine");
  const std::string cache = w.path("cache");
  const std::string compare = fmt::format(
      "compare --size 4x4 --methods equal --budgets 4 --repeats 1 --device cpu --reference-spp 20000 --cache-dir {}",
      cache);
  const std::vector<Refusal> cases = {
      {fmt::format("{} --envmap {} --out-dir {}", compare, (od / "map.exr").string(), od.string()),
       "lies inside --out-dir"},
      {fmt::format("{} --envmap {} --out-dir {} --cache-dir {}", compare, w.path("env.exr"), w.path("od2"),
                   w.path("od2/cache")),
       "--cache-dir"},
      {fmt::format("{} --envmap {} --out-dir {}", compare, w.path("env.exr"), mine.string()),
       "holds files that no earlier run of this command wrote"},
      {fmt::format("{} --envmap {} --out-dir ''", compare, w.path("env.exr")), "--out-dir: an empty value"},
      {w.render("--out '' --reference auto --cache-dir " + cache), "--out: an empty value"},
      {w.render("--report '' --reference auto --cache-dir " + cache), "--report: an empty value"},
      {w.render("--cache-dir '' --reference auto"), "--cache-dir: an empty value"},
      {w.render("--device :2 --reference auto --cache-dir " + cache), "--device :2: expected DEVICE:N"},
      {w.render("--method sigma-sqrt-c --spp 16 --stages 12 --reference auto --cache-dir " + cache),
       "a stage of 1 sample(s)"},
      {w.render("--method exact --grid-rule entropy --spp 40 --reference auto --cache-dir " + cache), "give --pool 0"},
  };
  checkRefusals(w.dir.path, cases, cache);  // no reference computed, no cache entry written
}

TEST_CASE("every example that `misalloc paper` lists runs", "[cli][paper]") {
  auto list = runMisalloc("paper");
  REQUIRE(list.exitCode == 0);
  std::istringstream lines(list.output);
  int listed = 0;
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string id;
    words >> id;
    auto r = runMisalloc("paper " + id);
    INFO(id << "\n" << r.output);
    CHECK(r.exitCode == 0);
    ++listed;
  }
  CHECK(listed == int(misalloc::paperIds().size()));
  CHECK(list.output.find("001-6.3") != std::string::npos);
}
