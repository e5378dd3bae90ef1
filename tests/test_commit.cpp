// All of a run's outputs or none, even under signals: SIGINT and SIGTERM wait for the
// renames of a commit, what SIGKILL leaves behind is removed by the next run that writes
// there, compare's folder is exchanged whole, temporary names fit the file system, and
// outputs that are not regular files are refused before any work.
#include <fmt/format.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>

#include "AtomicFile.h"
#include "CliRunner.h"
#include "SafetyWorkspace.h"
#include "Spawn.h"

using namespace misalloc::test;

namespace {

// A PID that no process has: one that just ended.
long deadPid() {
  pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitStatus(pid);
  return long(pid);
}

const char* const kOutputs[] = {"render.exr", "render.png", "render.json", "alpha.exr", "alpha.png"};

// How many of the render's outputs still hold what the workspace put there.
int earlierOutputs(const Workspace& w) {
  int earlier = 0;
  for (const char* name : kOutputs) earlier += readText(w.path(name)).rfind("earlier ", 0) == 0;
  return earlier;
}

std::string renderWithAlpha(const Workspace& w) {
  return w.render(fmt::format("--method heuristic --spp 40 --alpha-map {}", w.path("alpha.exr")));
}

}  // namespace

TEST_CASE("SIGINT and SIGTERM during the commit wait for it: every output new, no temporary left",
          "[cli][safety][signals]") {
  for (int signal : {SIGINT, SIGTERM}) {
    Workspace w;
    // The commit pauses after each rename: the signal arrives between two of them.
    pid_t pid = spawnMisalloc(renderWithAlpha(w), "MISALLOC_TEST_COMMIT_PAUSE_MS=200");
    REQUIRE(waitFor([&] { return earlierOutputs(w) < 5; }));
    REQUIRE(kill(pid, signal) == 0);
    const int status = waitStatus(pid);
    INFO("signal " << signal);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 128 + signal);
    CHECK(earlierOutputs(w) == 0);
    CHECK_FALSE(holdsTemporaries(w.dir.path));
  }
}

TEST_CASE("a signal before the commit leaves every output as it was", "[cli][safety][signals]") {
  Workspace w;
  const std::string before = fingerprint(w.dir.path);
  // A reference of many samples keeps the run busy long before it commits.
  pid_t pid =
      spawnMisalloc(renderWithAlpha(w) + " --reference auto --reference-spp 100000000 --cache-dir " + w.path("cache"));
  REQUIRE(waitFor([&] { return fs::exists(w.dir.path / "cache" / "references"); }));
  REQUIRE(kill(pid, SIGTERM) == 0);
  const int status = waitStatus(pid);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 128 + SIGTERM);
  fs::remove_all(w.dir.path / "cache");
  CHECK(fingerprint(w.dir.path) == before);
}

TEST_CASE("what SIGKILL leaves behind is removed by the next run that writes there", "[cli][safety][signals]") {
  Workspace w;
  pid_t pid = spawnMisalloc(renderWithAlpha(w), "MISALLOC_TEST_COMMIT_PAUSE_MS=200");
  REQUIRE(waitFor([&] { return earlierOutputs(w) < 5; }));
  REQUIRE(kill(pid, SIGKILL) == 0);
  waitStatus(pid);
  CHECK(holdsTemporaries(w.dir.path));  // the temporaries not yet renamed
  // A temporary of a process that still runs (this one) is left alone.
  const std::string live = fmt::format(".x.exr.tmp-{}-{}-0", misalloc::hostTag(), ::getpid());
  writeText(w.dir.path / live, "live");
  auto r = runMisalloc(renderWithAlpha(w));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK(earlierOutputs(w) == 0);
  CHECK(fs::exists(w.dir.path / live));
  fs::remove(w.dir.path / live);
  CHECK_FALSE(holdsTemporaries(w.dir.path));

  // The reference cache's folder likewise.
  const fs::path references = w.dir.path / "cache" / "references";
  fs::create_directories(references);
  const std::string stale = fmt::format(".0123456789abcdef.exr.tmp-{}-{}-0", misalloc::hostTag(), deadPid());
  writeText(references / stale, "left by a killed run");
  r = runMisalloc(w.render("--reference auto --reference-spp 16 --cache-dir " + w.path("cache")));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK_FALSE(fs::exists(references / stale));
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("a writer's temporaries are its host's: another PID namespace's live ones are left alone",
          "[cli][safety][signals]") {
  // A second writer in a PID namespace of its own (a container, or another machine on a
  // shared file system) whose PID runs nowhere here: its temporaries, in the folder
  // while its commit pauses, must survive a run here that clears dead runs' leftovers.
  if (::geteuid() != 0 || std::system("unshare -p -f --mount-proc true >/dev/null 2>&1") != 0) {
    WARN("skipped: a PID namespace needs root and unshare");
    return;
  }
  Workspace w;
  const long pid = deadPid();
  const std::string inner = fmt::format(
      "unshare -p -f --mount-proc sh -c 'echo {} >/proc/sys/kernel/ns_last_pid; "
      "MISALLOC_TEST_COMMIT_PAUSE_MS=1000 {} {} & wait $!' >/dev/null 2>&1",
      pid - 1, misallocBinary(), renderWithAlpha(w));
  const pid_t writer = fork();
  REQUIRE(writer >= 0);
  if (writer == 0) {
    execl("/bin/sh", "sh", "-c", inner.c_str(), (char*)nullptr);
    _exit(127);
  }
  REQUIRE(waitFor([&] { return earlierOutputs(w) < 5; }));  // committing: the others still temporaries
  CHECK(holdsTemporaries(w.dir.path));
  auto here = runMisalloc(fmt::format(
      "render --envmap {} --size 4x4 --spp 8 --device cpu --reference none --no-preview --out {} --report {}",
      w.path("env.exr"), w.path("here.exr"), w.path("here.json")));
  INFO(here.output);
  CHECK(here.exitCode == 0);
  const int status = waitStatus(writer);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(earlierOutputs(w) == 0);  // every output of the other writer renamed into place
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("compare replaces its folder whole, even when killed", "[cli][safety][signals][compare]") {
  Workspace w;
  const fs::path out = w.dir.path / "cmp";
  fs::create_directories(out / "a_case");
  writeText(out / "runs.json", "earlier runs");
  writeText(out / "a_case" / "earlier.png", "earlier");
  const std::string compare = fmt::format(
      "compare --envmap {} --size 4x4 --methods equal --budgets 4 --repeats 1 --device cpu --cache-dir {} --out-dir {}",
      w.path("env.exr"), w.path("cache"), out.string());
  pid_t pid = spawnMisalloc(compare, "MISALLOC_TEST_COMMIT_PAUSE_MS=500");
  REQUIRE(waitFor([&] { return readText(out / "runs.json") != "earlier runs"; }));
  REQUIRE(kill(pid, SIGKILL) == 0);
  waitStatus(pid);
  // The folder is the new one, whole: nothing of the earlier run is in it.
  CHECK_FALSE(fs::exists(out / "a_case" / "earlier.png"));
  CHECK(fs::exists(out / "index.html"));
  CHECK(holdsTemporaries(w.dir.path));  // the earlier folder, under its hidden name
  auto r = runMisalloc(compare);
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("a temporary name fits the file system whatever the output's name", "[cli][safety]") {
  Workspace w;
  const std::string name = std::string(246, 'n') + ".exr";  // 250 bytes: a legal name
  auto r =
      runMisalloc(w.render(fmt::format("--out {} --report {}", w.path(name), w.path(std::string(245, 'r') + ".json"))));
  INFO(r.output);
  CHECK(r.exitCode == 0);
  CHECK(fs::file_size(w.path(name)) > 0);
  CHECK(fs::exists(w.path(std::string(246, 'n') + ".png")));
  CHECK(misalloc::temporaryName(w.path(name), 0).size() - w.dir.path.string().size() - 1 <= 255);
  CHECK(misalloc::temporaryName(w.path(name), 0) != misalloc::temporaryName(w.path(std::string(246, 'm') + ".exr"), 0));
  CHECK_FALSE(holdsTemporaries(w.dir.path));
}

TEST_CASE("an output that is a device, FIFO or socket is refused before any work", "[cli][safety][bad-input]") {
  Workspace w;
  REQUIRE(mkfifo(w.path("fifo").c_str(), 0666) == 0);
  const std::string before = fingerprint(w.dir.path);
  const std::string cache = " --reference auto --reference-spp 16 --cache-dir " + w.path("cache");
  for (const std::string& args : {w.render("--out " + w.path("fifo") + cache), w.render("--report /dev/null" + cache),
                                  w.render("--alpha-map /dev/zero --method heuristic --spp 40" + cache)}) {
    auto r = runMisalloc(args);
    INFO(args << "\n" << r.output);
    CHECK(r.exitCode == 2);
    CHECK(r.output.find("is not a regular file") != std::string::npos);
    CHECK_FALSE(fs::exists(w.dir.path / "cache"));  // refused before the reference
  }
  CHECK(fs::is_fifo(w.path("fifo")));
  CHECK(fs::is_character_file("/dev/null"));
  CHECK(fingerprint(w.dir.path) == before);
}
