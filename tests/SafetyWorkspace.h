#pragma once
// What the safety tests share: a workspace of inputs and earlier outputs, and the
// fingerprint of a folder that a failed or interrupted run must leave as it was.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "CliRunner.h"
#include "scene/ExrIO.h"

namespace misalloc::test {

namespace fs = std::filesystem;

// Every file and link under `dir` with its sha256 (or its link's target), one a line:
// what a failed run must leave exactly as it was.
inline std::string fingerprint(const fs::path& dir) {
  const std::string command = fmt::format(
      "cd '{}' && find . -type l -printf '%p -> %l\\n' | sort && find . -type f -print0 | sort -z | xargs -0 -r sha256sum",
      dir.string());
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string listing;
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof buffer, pipe)) listing.append(buffer, n);
  REQUIRE(pclose(pipe) == 0);
  return listing;
}

inline bool holdsTemporaries(const fs::path& dir) {
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp") != std::string::npos) return true;
  return false;
}

inline void writeText(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

inline std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A run that must be refused with exit 2 and a message holding `expected`.
struct Refusal {
  std::string args, expected;
};

// Runs each refusal and checks that it leaves every file under `dir` as it was and,
// when `untouched` is given, that this path was never created.
inline void checkRefusals(const fs::path& dir, const std::vector<Refusal>& refusals, const fs::path& untouched = {}) {
  const std::string before = fingerprint(dir);
  for (const Refusal& c : refusals) {
    auto r = runMisalloc(c.args);
    INFO(c.args << "\n" << r.output);
    CHECK(r.exitCode == 2);
    CHECK(r.output.find(c.expected) != std::string::npos);
    if (!untouched.empty()) CHECK_FALSE(fs::exists(untouched));
    CHECK(fingerprint(dir) == before);
  }
}

// A small valid envmap, its links, and earlier outputs that a failed run must keep.
struct Workspace {
  TempDir dir{"safety"};
  std::string path(const std::string& name) const { return (dir.path / name).string(); }

  Workspace() {
    misalloc::writeExr(path("env.exr"), misalloc::RgbImage{8, 4, std::vector<float>(96, 0.5f)});
    misalloc::writeExr(path("ref.exr"), misalloc::RgbImage{4, 4, std::vector<float>(48, 0.25f)});
    fs::create_symlink("env.exr", dir.path / "link.exr");
    fs::create_hard_link(dir.path / "env.exr", dir.path / "hard.exr");
    fs::create_directory(dir.path / "sub");
    for (const char* earlier : {"render.exr", "render.png", "render.json", "alpha.exr", "alpha.png", "ref_out.exr"})
      writeText(dir.path / earlier, std::string("earlier ") + earlier);
  }

  // A fast run: a 4×4 image of the small map, no reference unless asked.
  std::string render(const std::string& args) const {
    return fmt::format("render --envmap {} --size 4x4 --spp 8 --device cpu --reference none --out {} --report {} {}",
                       path("env.exr"), path("render.exr"), path("render.json"), args);
  }
};

}  // namespace misalloc::test
