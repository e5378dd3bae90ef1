// Compiles the variants of the two OpenCL programs that the host can build to NVIDIA PTX
// with clang, so that a kernel edit that only a GPU compiler would reject fails here, on
// a machine without a GPU. The variants come from the host's own option builders
// (sampleKernelOptions, gridSearchKernelOptions) over the scenes, methods, estimators and
// work-group sizes it uses. By default a pairwise covering set of them compiles
// (tests/Covering.h: every pair of -D settings that some variant holds); with
// MISALLOC_TEST_SIZE=exhaustive (scripts/exhaustive-tests) every one.
//
// Usage: ptx_kernel_variants CLANG KERNEL_DIR RANDOM123_INCLUDE_DIR
// Exit 0: every chosen variant compiled; 1: at least one did not (each is printed with
// its options and clang's messages); 77: clang or its nvptx64 target is missing (a skip).
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "../Covering.h"
#include "../TestSize.h"
#include "Error.h"
#include "alloc/GridSearch.h"
#include "render/Method.h"
#include "render/Render.h"
#include "render/RunChecks.h"
#include "sampling/Sampler.h"
#include "scene/Scene.h"

extern char** environ;

using namespace misalloc;

namespace {

constexpr int kSkip = 77;

struct Variant {
  std::string file;     // in the kernel folder
  std::string options;  // as the host passes them to clBuildProgram

  bool operator<(const Variant& other) const { return std::tie(file, options) < std::tie(other.file, other.options); }
};

Scene scene(const std::string& envmap, bool split, bool product, EnvmapSampler sampler, const std::string& pdf) {
  SceneOptions o;
  o.envmapPdf = parseEnvmapPdf(pdf);
  o.envmap = envmap;
  o.grid = "uniform:0.5,0.5,10";
  o.width = o.height = 4;
  o.splitBrdf = split;
  o.product = product;
  o.sampler = sampler;
  o.proceduralWidth = 64;
  return makeScene(o);
}

// Every program a Sampler can build: per scene, each method's config (the fixed splits
// with every estimator) and its plainConfig, with either MIS weights where the run
// takes them (render/RunChecks.h), at each work-group size, and the grid search where
// the config asks for one (Sampler's constructor); not those of runs that
// requireValidRun refuses (ris with the optimal pdf). The optimal pdf's bank and the
// optimal pdf per pixel on one map: the map changes MA_ANALYTIC_RADIANCE alone. Work-groups of the CPU's
// size and the largest GPU's: the size changes the local arrays' lengths alone, which `clang -S` does not hold against
// a device's limits. The product technique (M = 3 as with split lobes, its tables' count compiled in, or from the
// optimal pdf per pixel's cells) on one map. A
// CPU's samplePixelStage (alias sampler, no resampling) at 8 and 16 lanes.
std::set<Variant> hostVariants() {
  std::set<Variant> variants;
  for (const std::string pdf : {"plain", "optimal", "optimal-pixel"})
    for (int techniques : {0, 1, 2})  // the BRDF as one technique, split, or with the product
      for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf})
        for (const std::string envmap : {"constant", "cosk:3"}) {
          const bool split = techniques == 1, product = techniques == 2;
          if (pdf != "plain" && (split || envmap != "constant")) continue;
          if (pdf == "optimal-pixel" && sampler == EnvmapSampler::Cdf) continue;  // its own sampler either way
          if (product && envmap != "constant") continue;
          Scene s = scene(envmap, split, product, sampler, pdf);
          for (Method method : allMethods())
            for (Estimator estimator : {Estimator::MultiSample, Estimator::OneSample, Estimator::CountIndependent})
              for (MisWeights weights : {MisWeights::Balance, MisWeights::Optimal}) {
                AdaptiveOptions options;
                options.weights = weights;
                if (weights == MisWeights::Optimal && !takesOptimalWeights(method, estimator)) continue;
                try {
                  requireValidRun(s.options, method, estimator, 64, options);
                } catch (const InputError&) {
                  continue;
                }
                SamplerConfig config = samplerConfigFor(method, estimator, 64, options, s.techniqueCount());
                for (int localSize : {8, 256}) {
                  variants.insert({"sample.cl", sampleKernelOptions(s, config, localSize)});
                  variants.insert({"sample.cl", sampleKernelOptions(s, plainConfig(config), localSize)});
                }
                // A CPU's plain program with samplePixelStage (Sampler), at AVX2's and
                // AVX-512's float widths, with PoCL's 512 KiB of local memory.
                for (int deviceLanes : {8, 16})
                  if (const int lanes = samplePixelLanes(s, config, deviceLanes); lanes > 0)
                    if (const int pixels = pixelStageGroupPixels(s, config, lanes, 512 * 1024); pixels > 0)
                      variants.insert({"sample.cl", sampleKernelOptions(s, plainConfig(config), 8, lanes, pixels)});
                if (config.gridSize > 0)
                  variants.insert(
                      {"gridsearch.cl", gridSearchKernelOptions(sampleColumns(s, config), config.optimalWeights)});
              }
        }
  return variants;
}

std::vector<std::string> words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string word; in >> word;) out.push_back(word);
  return out;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Starts argv[0] found on PATH with stdout and stderr into the given files; -1 if it
// could not be started.
pid_t spawn(const std::vector<std::string>& args, const std::string& stdoutPath, const std::string& stderrPath) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdoutPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderrPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  pid_t pid = -1;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return rc == 0 ? pid : -1;
}

// The exit status, or -1 if it did not exit normally.
int waitFor(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string commandLine(const std::vector<std::string>& args) {
  std::string line;
  for (const std::string& a : args) line += (line.empty() ? "'" : " '") + a + "'";
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: " << argv[0] << " CLANG KERNEL_DIR RANDOM123_INCLUDE_DIR\n";
    return 2;
  }
  const std::string clang = argv[1], kernelDir = argv[2], random123Dir = argv[3];
  char tmpl[] = "/tmp/misalloc-ptx-XXXXXX";
  if (!mkdtemp(tmpl)) {
    std::perror("mkdtemp");
    return 2;
  }
  const std::string tmp = tmpl;

  const std::string targetsPath = tmp + "/targets";
  pid_t probe = spawn({clang, "-print-targets"}, targetsPath, tmp + "/targets.err");
  if (probe < 0 || waitFor(probe) != 0) {
    std::cout << "SKIP: " << clang << " cannot be run; install Debian's clang (.ci/setup lists it)\n";
    std::filesystem::remove_all(tmp);
    return kSkip;
  }
  if (readFile(targetsPath).find("nvptx64") == std::string::npos) {
    std::cout << "SKIP: " << clang << " has no nvptx64 target (clang -print-targets)\n";
    std::filesystem::remove_all(tmp);
    return kSkip;
  }

  const std::set<Variant> variantSet = hostVariants();
  const std::vector<Variant> every(variantSet.begin(), variantSet.end());
  std::vector<Variant> variants = every;
  if (!test::exhaustiveTestSize()) {
    std::vector<test::Configuration> settings;
    for (const Variant& v : every) {
      settings.push_back(words(v.options));
      settings.back().push_back("file=" + v.file);
    }
    variants.clear();
    for (size_t i : test::pairwiseCovering(settings)) variants.push_back(every[i]);
  }
  auto argsOf = [&](const Variant& v) {
    std::vector<std::string> args{clang,
                                  "-x",
                                  "cl",
                                  "-cl-std=CL1.2",
                                  "-D__OPENCL_VERSION__=120",
                                  "-target",
                                  "nvptx64-nvidia-nvcl",
                                  "-Xclang",
                                  "-finclude-default-header",
                                  "-I" + kernelDir,
                                  "-I" + random123Dir};
    for (std::string& w : words(v.options)) args.push_back(std::move(w));
    for (const char* a : {"-S", "-o", "/dev/null"}) args.emplace_back(a);
    args.push_back(kernelDir + "/" + v.file);
    return args;
  };

  const auto start = std::chrono::steady_clock::now();
  // As many as ctest reserves for it (PROCESSORS in tests/CMakeLists.txt).
  const size_t jobs = std::clamp<size_t>(std::thread::hardware_concurrency(), 1, 2);
  std::vector<std::pair<pid_t, size_t>> running;  // (process, variant)
  std::vector<size_t> failed;
  auto reap = [&]() {
    int status = 0;
    pid_t pid = wait(&status);
    auto it = std::find_if(running.begin(), running.end(), [&](const auto& r) { return r.first == pid; });
    if (it == running.end()) return;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) failed.push_back(it->second);
    running.erase(it);
  };
  for (size_t i = 0; i < variants.size(); ++i) {
    while (running.size() >= jobs) reap();
    pid_t pid = spawn(argsOf(variants[i]), "/dev/null", tmp + "/" + std::to_string(i) + ".err");
    if (pid < 0) {
      std::ofstream(tmp + "/" + std::to_string(i) + ".err") << "could not start " << clang << "\n";
      failed.push_back(i);
      continue;
    }
    running.emplace_back(pid, i);
  }
  while (!running.empty()) reap();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::sort(failed.begin(), failed.end());
  for (size_t i : failed) {
    const Variant& v = variants[i];
    std::cout << "FAILED: " << v.file << " with " << v.options << "\n  " << commandLine(argsOf(v)) << "\n"
              << readFile(tmp + "/" + std::to_string(i) + ".err") << "\n";
  }
  const auto count = [&](const char* file) {
    return std::count_if(variants.begin(), variants.end(), [&](const Variant& v) { return v.file == file; });
  };
  std::cout << variants.size() - failed.size() << " of " << variants.size() << " kernel variants ("
            << count("sample.cl") << " of sample.cl, " << count("gridsearch.cl") << " of gridsearch.cl; "
            << every.size() << " host variants, "
            << (variants.size() < every.size() ? "a pairwise covering set" : "all of them")
            << ") compiled to PTX (nvptx64-nvidia-nvcl) in " << seconds << " s, " << jobs << " at a time\n";
  std::filesystem::remove_all(tmp);
  return failed.empty() ? 0 : 1;
}
